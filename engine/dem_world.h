// SPDX-License-Identifier: MIT
/// @file dem_world.h
/// The DEM world: granules (spheres), walls, one contact law per contact kind,
/// velocity-Verlet time stepping, linked-cell Verlet neighbour lists, and
/// diagnostics. Knows nothing of drums, calibration or files of experiments.
#ifndef DEM_WORLD_H
#define DEM_WORLD_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"
#include "dem_vec.h"

/// Status codes. Recoverable errors return one of these; the message is in
/// dem_world_error().
typedef enum dem_status {
    DEM_OK = 0,
    DEM_ERR_INVALID = 1,   ///< bad definition or argument
    DEM_ERR_NOMEM = 2,     ///< allocation failed
    DEM_ERR_UNSTABLE = 3,  ///< time step above the stability limit
    DEM_ERR_NONFINITE = 4, ///< NaN or infinity in the state
    DEM_ERR_ESCAPED = 5,   ///< a granule left the domain
} dem_status;

/// Lever arm of tangential forces and of the tangential contact velocity.
typedef enum dem_lever_arm {
    /// Distance from the centre to the contact point (R_i − h/2 against a
    /// granule, R_i − h against a wall): a pair turned as a rigid body does
    /// not slide. Default.
    DEM_LEVER_CONTACT_POINT = 0,
    /// R_i, as eq. 7 and 9 are written: a rigidly turning overlapped pair
    /// slides at h·Ω, an O(h/R) error.
    DEM_LEVER_RADIUS = 1,
} dem_lever_arm;

/// Kinds of wall. The engine moves a wall only by its prescribed motion
/// (dem_wall_def.motion); a caller may also place one (dem_world_set_wall_point).
typedef enum dem_wall_kind {
    DEM_WALL_PLANE = 0,    ///< infinite plane; granules on the side `normal` points to
    DEM_WALL_DISC = 1,     ///< flat disc of `radius` (an end plate), one-sided like the plane
    DEM_WALL_CYLINDER = 2, ///< inner surface of a cylinder of `radius` about `axis`
} dem_wall_kind;

/// Prescribed motion of a wall, part of its definition (as MercuryDPM's walls
/// carry theirs): the engine moves the wall itself, before every step.
typedef enum dem_wall_motion {
    DEM_WALL_STANDS = 0,     ///< never moved by the engine; `velocity` is its surface's only (a conveyor)
    DEM_WALL_TRANSLATES = 1, ///< translation at constant `velocity` from where it stands (a piston)
} dem_wall_motion;

/// Definition of a wall. A wall can spin about `axis` through `point` at
/// `spin` rad/s (a rotating drum) and translate at `velocity`: its surface
/// velocity at a contact point c is velocity + Ω × (c − point).
typedef struct dem_wall_def {
    dem_wall_kind kind;
    dem_vec3 point;   ///< plane: a point on it; disc: its centre; cylinder: a point on the axis
    dem_vec3 normal;  ///< plane/disc: unit normal towards the granules
    dem_vec3 axis;    ///< cylinder: unit axis; also the spin axis of any wall
    double radius;    ///< disc and cylinder radius, m
    double spin;      ///< angular velocity about `axis`, rad/s
    /// Translational velocity of the wall's surface, m/s (default 0): it
    /// enters the contacts' relative velocity (dashpot, tangential spring and
    /// friction), not the wall's position: a wall moving other than along
    /// its own surface is given its `motion` (dem_world_set_wall_translation).
    /// With DEM_WALL_STANDS the engine never moves it (a conveyor).
    dem_vec3 velocity;
    /// DEM_WALL_TRANSLATES: before each step (its kick and drift, so that
    /// the step's force evaluation sees the wall there) the engine adds
    /// `step_displacement` to `point`, one addition a step: the point is a
    /// running sum, the arithmetic of a caller who moved the wall by hand
    /// between single steps (y += travel), so that such a run keeps its bits
    /// when the engine takes the motion over. Default DEM_WALL_STANDS.
    dem_wall_motion motion;
    /// m per step, DEM_WALL_TRANSLATES only; (0, 0, 0): velocity × dt of the
    /// step. A caller whose distance per step is its own product (travel =
    /// speed × dt, scaled) gives it here rather than have it recomputed.
    dem_vec3 step_displacement;
    dem_contact_params contact; ///< granule–this-wall contact parameters (Table 3)
    const char *name; ///< for messages, optional
} dem_wall_def;

/// dem_world_def.implicit_springs: decided by dem_world_prepare.
#define DEM_IMPLICIT_AUTO (-1)

/// Definition of a world, with defaults from dem_default_world_def().
typedef struct dem_world_def {
    dem_vec3 gravity;               ///< m/s², default (0, −9.81, 0)
    dem_contact_params granule;     ///< granule–granule contact (Table 3)
    double dt;                      ///< time step, s; 0 = choose the stable step
    double dt_safety;               ///< fraction of the stability limit used when choosing, default 0.9
    dem_vec3 domain_lo, domain_hi;  ///< granules outside are reported escaped
    int periodic_axis;              ///< −1 none, else 0/1/2: periodic between domain_lo and domain_hi
    double skin;                    ///< Verlet skin, m; 0 = 0.4 × the smallest radius (dem_world_prepare)
    dem_lever_arm lever_arm;
    /// OpenMP threads of this world's parallel regions; 0 = OpenMP's default
    /// (omp_get_max_threads() when a region starts). OpenMP's process-wide
    /// setting is never changed.
    int threads;
    /// Integrate the normal dashpots semi-implicitly: each granule's velocity
    /// update sees its own dashpots at the new velocity (backward Euler in
    /// its own velocity, neighbours explicit), i.e. it is divided by the
    /// effective mass m·I + Δt·Σγ n nᵀ instead of m. Removes the dashpot from
    /// the stability limit (left: the spring modes, ω·Δt < 2). Default 0
    /// (explicit, as in LIGGGHTS) while it is being validated.
    int implicit_damping;
    /// Implicit springs (the engine issue's semi-implicit update): the
    /// sticking tangential and rolling springs (eq. 6, 11) are integrated by
    /// Newmark's average-acceleration rule (β = 1/4) and the normal dashpots
    /// (eq. 3–4) by backward Euler, both solved over the whole contact network
    /// each step: (M + Δt·C + Δt²/4·K_t)·a = F + M·g, by conjugate gradients
    /// preconditioned with each granule's own 6×6 block (v, ω) of that
    /// matrix. Normal springs stay explicit (velocity Verlet), so collisions
    /// keep their explicit accuracy. Proven limit (dem_stability.h): the
    /// normal springs' own ω_n·Δt < √3 (2 for a dashpot that never switches);
    /// the spin mode leaves it. 1: on (overrides implicit_damping: its
    /// dashpot is part of this solve); 0: off; DEM_IMPLICIT_AUTO (default):
    /// on for a configured dt above the explicit integration's own limit
    /// (e.g. the paper's 0.6 dt_crit, which is then run instead of refused),
    /// unless implicit_damping is set; otherwise explicit, bit for bit as
    /// before (a step left to the engine, the Table A.1 verification).
    int implicit_springs;
    /// Accept a configured dt above the stability limit. Only for studies of
    /// the limit itself (tests/stability); never set by configs.
    int allow_unstable_dt;
    /// Step safety while running: every this much simulated time (s) the
    /// step is checked against the limit of the contact network as it now is
    /// (dem_world_check_network_dt) and lowered where it is above it; what the
    /// checks found: dem_world_network_checks. 0 (default): never (every
    /// scene that does not ask runs as before). A turning bed's contacts
    /// change; the step chosen from the settled bed must stay within them.
    double network_check_interval;
    /// The chunk of simulated time (s) the interval is counted in; 0: one
    /// step. The interval is round(interval/chunk) chunks of round(chunk/dt)
    /// steps each, counted in steps since the last check (saved in
    /// checkpoints), never by comparing simulated times: the checks fall on
    /// the same steps on every machine and after a resume. A caller stepping
    /// in chunks of round(chunk/dt) steps (the drum: one image sample each)
    /// then has every check at the end of one of its chunks, also after a
    /// lowered step has changed the steps a chunk holds.
    double network_check_chunk;
} dem_world_def;

/// Defaults: gravity −9.81 along y, the paper's Table 3 granule–granule
/// contact, automatic time step, no periodic axis, a 1 m domain.
dem_world_def dem_default_world_def(void);

/// Read-only view of the granules, structure of arrays (hot data).
typedef struct dem_granules_view {
    size_t count;
    const dem_vec3 *position, *velocity, *omega, *force, *torque;
    const double *radius, *mass, *inertia;
    const uint64_t *id; ///< stable id given at creation (order changes on re-sorting)
} dem_granules_view;

/// Diagnostics of the current state.
typedef struct dem_diagnostics {
    double time;
    uint64_t step;
    size_t granules;
    size_t contacts;           ///< granule–granule contacts (overlap > 0)
    size_t list_pairs;         ///< pairs the force loop visits: contacts + near misses within the skin
    uint64_t list_rebuilds;    ///< neighbour-list rebuilds so far
    size_t wall_contacts;      ///< granule–wall contacts
    double coordination;       ///< mean granule–granule contacts per granule, 2·contacts/N
    double coordination_walls; ///< mean (granule + wall) contacts per granule
    double ke_translational;   ///< J
    double ke_rotational;      ///< J
    double mass;               ///< kg, every granule's (fixed ones too), summed in index order
    double max_overlap_ratio;  ///< max h/R_min over contacts
    double potential_elastic;  ///< J, stored in normal, tangential and rolling springs
} dem_diagnostics;

typedef struct dem_world dem_world;

/// Create a world; NULL only on out-of-memory or a bad definition (then
/// `err`, if not NULL, receives the message).
dem_world *dem_world_create(const dem_world_def *def, char *err, size_t err_len);
void dem_world_destroy(dem_world *w);
/// A deep copy (granules, walls, contact history, time): a settled bed is
/// filled once and turned at several speeds. NULL on out-of-memory.
dem_world *dem_world_clone(const dem_world *w);

/// Add a granule; returns its id, or −1 (message in dem_world_error).
int64_t dem_world_add_granule(dem_world *w, dem_vec3 position, dem_vec3 velocity, dem_vec3 omega, double radius,
                              double density);
/// Add a wall; returns its index, or −1.
int dem_world_add_wall(dem_world *w, const dem_wall_def *def);
/// Change a wall's spin (rad/s), e.g. to start a drum turning.
dem_status dem_world_set_wall_spin(dem_world *w, int wall, double spin);
/// Place a wall: move its reference point (a plane's point, a disc's centre,
/// a point on a cylinder's axis) to `point` (a piston set on a bed before it
/// is driven; a wall driven at a set speed is given its prescribed motion,
/// dem_world_set_wall_translation, instead). The step in progress ends with the
/// forces already computed; the next force evaluation sees the wall where it
/// now is, with its surface moving at its spin and its velocity
/// (dem_world_set_wall_velocity) only: the move itself enters no relative
/// velocity, so a driven wall should also be given the velocity it is moved
/// at. The lists are rebuilt once a wall has moved half a skin since they
/// were built.
dem_status dem_world_set_wall_point(dem_world *w, int wall, dem_vec3 point);
/// The wall's translational velocity (m/s), which the contact law sees as the
/// wall surface's velocity (with the spin's); e.g. a conveyor plane moving
/// along itself. The wall is not moved by it unless it translates
/// (dem_wall_def.motion; then the step displacement (0, 0, 0) follows the new
/// velocity). A wall whose velocity is zero
/// adds nothing to the relative velocity, so its results are those of a wall
/// without the field, bit for bit.
dem_status dem_world_set_wall_velocity(dem_world *w, int wall, dem_vec3 velocity);
/// Prescribed wall motion in the engine (dem_wall_def.motion): from now on
/// the wall translates, moved by `step_displacement` before every step
/// ((0, 0, 0): velocity × dt), its surface moving at `velocity` in the
/// contacts; a multi-step call (dem_world_step) drives it on every thread.
/// Set again for a new leg (a piston reversing).
dem_status dem_world_set_wall_translation(dem_world *w, int wall, dem_vec3 velocity, dem_vec3 step_displacement);
/// The wall stands where it is: no prescribed motion, velocity zero.
dem_status dem_world_stop_wall(dem_world *w, int wall);
/// A wall's definition as it now is (point and spin included); NULL for no
/// such wall.
const dem_wall_def *dem_world_wall(const dem_world *w, int wall);
/// The total force the granules exert on a wall (N): minus the sum of the
/// granule–wall contact forces of the last force evaluation, as the contact
/// law computed them (normal spring, dashpot and tangential force; rolling
/// resistance is a torque and is not in it). That evaluation is the one of
/// the state after the last step, the forces each granule's second half kick
/// used. Added in one order, the same bits on any number of threads. With
/// implicit damping or implicit springs the velocity update also solves the
/// dashpots and sticking springs implicitly; this is the explicit evaluation,
/// not that correction. (0, 0, 0) before the first step; NaN for no such wall.
dem_vec3 dem_world_wall_force(const dem_world *w, int wall);
/// Change the granule–granule or a wall's contact parameters (calibration
/// candidates); the feature mask is re-derived.
dem_status dem_world_set_granule_contact(dem_world *w, const dem_contact_params *p);
dem_status dem_world_set_wall_contact(dem_world *w, int wall, const dem_contact_params *p);

/// Fix the time step and check it against the stability limit. Called by
/// the first dem_world_step; call it yourself to see the step chosen.
dem_status dem_world_prepare(dem_world *w);

/// Re-derive the time step from the stability limit of the world's CURRENT
/// contact network (dem_stability_current) instead of the a-priori densest
/// cluster: a settled bed of a wide GSD allows a larger step. The step becomes
/// dt_safety of that limit (or stays as configured, if it is below it);
/// returns DEM_ERR_UNSTABLE if a configured step is above it.
dem_status dem_world_adopt_network_dt(dem_world *w);

/// A network step checked again while the world runs (a turning bed's
/// contacts change): the current network's limit over the step in use
/// (> 1: stable with room to spare; INFINITY without contacts), and whether
/// the step was lowered.
typedef struct dem_network_dt_check {
    double margin;
    int lowered;
} dem_network_dt_check;

/// Check the step against the stability limit of the CURRENT contact network
/// (dem_stability_current). Reads the world only, when the step is within
/// the limit: a run checked is the same run, bit for bit. Above it, a step
/// the engine chose is lowered to dt_safety of the new limit (lowered = 1).
/// (A configured step passed the a-priori bound of the densest cluster, which
/// no network exceeds, unless allow_unstable_dt let it through unchecked.)
/// A world whose neighbour list is not built yet is not checked (margin NAN).
dem_status dem_world_check_network_dt(dem_world *w, dem_network_dt_check *out);

/// What the world's own network checks (dem_world_def.network_check_interval)
/// found since the interval was last set.
typedef struct dem_network_checks {
    uint64_t checks;   ///< checks made
    uint64_t lowered;  ///< of them, those that lowered the step
    double margin_min; ///< the least margin seen (dem_network_dt_check.margin); NAN: none measured
    double wall_s;     ///< wall-clock seconds spent in the checks (timing only)
} dem_network_checks;

/// Set the world's network checks (dem_world_def.network_check_interval and
/// network_check_chunk; 0: off) from now on: the count of steps to the next
/// check and dem_world_network_checks start afresh. DEM_ERR_INVALID for a
/// negative or non-finite value.
dem_status dem_world_set_network_check(dem_world *w, double interval, double chunk);
dem_network_checks dem_world_network_checks(const dem_world *w);

/// Advance `steps` time steps, the walls moved by their prescribed motion and
/// the step checked against the network at the world's interval (which may
/// lower dt within the call). Stops early with a status on a fault (NaN,
/// escaped granule); the state at the fault is kept for inspection.
dem_status dem_world_step(dem_world *w, uint64_t steps);

/// Remove granules for which keep(view index) is 0 (e.g. cutting a bed).
dem_status dem_world_remove_granules(dem_world *w, int (*keep)(const dem_granules_view *g, size_t i, void *ctx),
                                     void *ctx);

/// Re-order the granules along a space-filling (Morton) curve so that granules
/// in contact sit close in memory: the force loop then reads its partners from
/// cache at any N. Contact history, forces and ids are kept; view indices
/// change. Call it once a bed is built (and now and then in a long run whose
/// granules travel), never between reading a view and using its indices.
dem_status dem_world_sort_spatially(dem_world *w);

/// Turn the whole granular state rigidly by `angle` (rad, right-handed) about
/// the line through `point` along `axis`: positions, velocities, spins and
/// every contact spring, so each contact keeps its force, turned. Walls do not
/// move: use it for a bed inside a body of revolution about that line (a drum
/// turned before its clock starts). Refused (DEM_ERR_INVALID, nothing changed)
/// for an axis other than a periodic one, or if a granule would leave the domain.
dem_status dem_world_rotate(dem_world *w, dem_vec3 point, dem_vec3 axis, double angle);

/// Set a granule's velocity and spin (by view index); DEM_ERR_INVALID for no
/// such granule.
dem_status dem_world_set_granule_velocity(dem_world *w, size_t i, dem_vec3 velocity, dem_vec3 omega);
/// Fix a granule (by view index) in place, or free it again: a fixed granule
/// neither moves nor turns (its velocity and spin are zeroed and stay so),
/// whatever its contacts and gravity do; its own mass enters its contacts as
/// any granule's does (as LIGGGHTS' fix freeze). A world with fixed granules
/// steps explicitly or with the implicit dashpot: with implicit springs
/// dem_world_prepare refuses it (DEM_ERR_INVALID).
dem_status dem_world_set_granule_fixed(dem_world *w, size_t i, int fixed);
/// Whether a granule (by view index) is fixed.
int dem_world_granule_fixed(const dem_world *w, size_t i);
/// Zero every velocity and spin (keeps contact history).
dem_status dem_world_freeze(dem_world *w);

dem_granules_view dem_world_granules(const dem_world *w);
dem_diagnostics dem_world_diagnose(const dem_world *w);
/// Granule–granule contacts (overlap > 0) of each granule, by view index,
/// into `counts` (granule count entries); the rule dem_world_diagnose counts by.
void dem_world_contact_counts(const dem_world *w, unsigned *counts);
double dem_world_time(const dem_world *w);
/// Granule-steps taken so far (each step counts the granules it moved), the
/// cost figure benchmarks divide by wall time. A clone carries its source's
/// count; a world read from a checkpoint starts again at 0.
uint64_t dem_world_particle_steps(const dem_world *w);
double dem_world_dt(const dem_world *w);
/// The stability limit found by dem_world_prepare (s); 0 before it.
double dem_world_dt_limit(const dem_world *w);
/// Whether the world steps with implicit springs (decided by dem_world_prepare).
int dem_world_implicit_springs(const dem_world *w);
/// OpenMP threads the world's steps run on (dem_world_def.threads, or
/// OpenMP's default now).
int dem_world_threads(const dem_world *w);
/// Change the world's thread count (0: OpenMP's default); results are
/// bitwise the same for any count. DEM_ERR_INVALID for a negative count.
dem_status dem_world_set_threads(dem_world *w, int threads);
/// Mean conjugate-gradient iterations per step of the implicit spring solve.
double dem_world_implicit_iterations(const dem_world *w);
unsigned dem_world_features(const dem_world *w);
const char *dem_world_error(const dem_world *w);
/// Human-readable line on how the time step was chosen.
const char *dem_world_dt_report(const dem_world *w);
/// Text listing the effects on and off in this world ("rolling on, ...").
void dem_world_describe_features(const dem_world *w, char *buf, size_t len);

/// Lightest granule mass and the smallest radius.
double dem_world_min_mass(const dem_world *w);
double dem_world_min_radius(const dem_world *w);
double dem_world_max_radius(const dem_world *w);

#endif
