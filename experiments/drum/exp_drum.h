// SPDX-License-Identifier: MIT
/// @file exp_drum.h
/// The rotating drum of sections 3.2.2–3.2.3: 100 mm across, 44 mm deep,
/// 43 % filled, turning about its axis (z) at a given rpm. Either the full
/// drum with end plates, or a slice with a periodic axis (the paper's
/// assumption iv: end plates negligible) of a given depth.
#ifndef EXP_DRUM_H
#define EXP_DRUM_H

#include <stdint.h>

#include "dem_gsd.h"
#include "dem_world.h"
#include "exp_common.h"
#include "exp_face_measure.h"

/// How exp_drum_fill builds the bed before it is cut to the fill degree.
typedef enum exp_drum_fill_method {
    /// Layers on a lattice one largest diameter apart, above the bed, each
    /// landing before the next (the lab's pour, slowly).
    EXP_FILL_POUR = 0,
    /// Bands of a loose random packing (exp_pack_band) from the bed surface
    /// to a little above the fill height, each settling before the next.
    EXP_FILL_PACK = 1,
} exp_drum_fill_method;

/// "pour" or "pack" into *out; 0, or 1 for another name.
int exp_drum_fill_method_from_name(const char *name, exp_drum_fill_method *out);
const char *exp_drum_fill_method_name(exp_drum_fill_method m);

/// Definition of a drum run. Powder and contacts are given for the REAL
/// powder; the coarse-graining laws (eq. 15–18, engine/dem_scaling.c) are
/// applied with `lambda` when the world is built.
typedef struct exp_drum_def {
    double diameter;        ///< inner diameter, m (0.1)
    double depth;           ///< drum depth, or slice depth when periodic, m (0.044)
    double fill;            ///< fill degree: bed volume over drum volume (0.43)
    int periodic;           ///< 1: periodic slice, no end plates; 0: full drum with end plates
    double lambda;          ///< coarse-graining scale factor λ (eq. 15)
    dem_gsd gsd;            ///< real granule size distribution
    double density;         ///< real granule density, kg/m³ (1800)
    dem_contact_params granule; ///< real granule–granule contact (Table 3)
    dem_contact_params wall;    ///< real granule–drum-wall contact (Table 3)
    dem_contact_params end_plate; ///< real granule–end-plate contact (full drum only)
    double pixel;               ///< raster pixel of the drum face, m; 0 = a quarter of the scaled d50
    int closing_px;             ///< closing radius in pixels (2: half a median diameter)
    uint64_t seed;
    exp_drum_fill_method fill_method; ///< how the bed is built (EXP_FILL_POUR)
} exp_drum_def;

/// Defaults: the paper's drum (100 mm across, 44 mm deep, the whole drum with
/// its end plates, 43 % full) and powder, Table 3's contacts, λ = 64.
exp_drum_def exp_default_drum_def(void);

/// What a drum run is physically, as both configs that describe one give it:
/// the drum YAML (exp_drum_config.c) and the calibration config with a tier
/// and a candidate's parameters (calib/runs/cal_case_runs.c). exp_drum_def_from_physics
/// is the one rule that turns it into an exp_drum_def.
typedef struct exp_drum_physics {
    double diameter;    ///< m
    int periodic;       ///< 1: a periodic slice `slice_depth` deep; 0: the whole drum, `depth` deep
    double depth;       ///< the whole drum's depth, m
    double slice_depth; ///< the periodic slice's depth, m
    double fill;        ///< fill degree
    double lambda;      ///< coarse-graining scale factor
    dem_gsd gsd;        ///< real granule size distribution
    double density;     ///< real granule density, kg/m³
    double k_n, xi;     ///< granule–granule normal stiffness (real, N/m) and damping ratio
    dem_damping_mode damping;
    double mu_s, mu_r;           ///< granule–granule friction
    double wall_mu_s, wall_mu_r; ///< granule–drum friction: the wall and the end plates
    exp_drum_fill_method fill_method;
    uint64_t seed;
} exp_drum_physics;

/// The drum definition of `p`: Table 3's contact pairs (exp_granule_pair; the
/// wall and the end plates exp_boundary_pair of it at the drum's friction),
/// the depth of the slice or of the drum; the rest (pixel, closing) default.
exp_drum_def exp_drum_def_from_physics(const exp_drum_physics *p);

/// Height (from the axis) below which a drum of radius r holds the fraction
/// `fill` of its cross-section: the level of a bed of that fill degree.
double exp_drum_fill_level(double r, double fill);

/// Check a definition; a message names the field.
int exp_drum_check(const exp_drum_def *d, char *msg, size_t len);


/// The drum of d with no granules: its domain, contact law and walls. A
/// world to read a checkpoint of this drum into (dem_checkpoint_read
/// replaces its whole state), without pouring a bed only to overwrite it.
/// NULL with a message.
dem_world *exp_drum_create_empty(const exp_drum_def *d, char *err, size_t len);

/// Build the drum and fill it as the lab does, by bed volume: granules are
/// poured in layers into the empty upper part of the drum, each layer
/// landing before the next is placed, until the bed's occupied CSA (eq. 20)
/// reaches the fill degree; the granules above the height where it equals
/// the fill degree are removed, and the bed settles until its kinetic energy
/// is below 1e-6 of (its mass)·g·d50. How many granules that takes depends on
/// how loosely the contact parameters let the bed pack. NULL with a message.
dem_world *exp_drum_fill(const exp_drum_def *d, exp_progress_fn progress, void *ctx, char *err, size_t len);

/// What a drum run is expected to cost, before it runs (for refusing a tier
/// that cannot fit the machine or the budget): granules from the bed volume at
/// a poured solid fraction of 0.6; the steps from eq. 14's dt_crit of the
/// lightest scaled granule at the fractions the engine runs
/// (EXP_POUR_STEP_FRACTION filling; 0.30 turning: a settled bed's network, measured
/// 0.29-0.30 at λ 4096 and 1000, results/benchmarks/drum_end_to_end.md); the
/// fill charged 1.25 s of simulated time (measured 1.20-1.25 s there).
typedef struct exp_drum_cost {
    double granules;
    double fill_particle_steps;     ///< pouring and settling one bed
    double turn_particle_steps;     ///< one speed turned for max_time
    double memory_mb;               ///< one simulation's peak resident memory (exp_predicted_peak_memory_mb)
} exp_drum_cost;

/// The expected cost of settling d's bed and turning it for max_time s.
exp_drum_cost exp_drum_predict_cost(const exp_drum_def *d, double max_time);

/// Measure the drum face: angle of the free surface and occupied CSA.
typedef struct exp_drum_measure {
    double angle_deg;        ///< magnitude of the surface angle (the dynamic angle of repose)
    double angle_signed_deg; ///< counter-clockwise positive, seen along +z
    double angle_fit_sd_m, csa_percent;
} exp_drum_measure;

int exp_drum_measure_now(const dem_world *w, const exp_drum_def *d, double pixel, int closing_px,
                         exp_drum_measure *out);

/// Where a rotation run saves its state, so that a killed run resumes
/// instead of starting over (dem_checkpoint.h: bit for bit, same build and
/// thread count).
typedef struct exp_drum_checkpoint {
    const char *path; ///< the run's checkpoint file
    const char *key;  ///< the text that defines the run: another run's checkpoint is not resumed
    double every_s;   ///< wall seconds between saves, each at the end of a sample
    /// 1: save once more when the run ends, so that the file holds the turned
    /// bed itself (a bed other runs start from; resumed, the run is done, and
    /// the file is not written again).
    int at_end;
} exp_drum_checkpoint;

/// How a rotation run decides it is done.
/// exp_drum_run_opts.steady_rule.
enum { EXP_STEADY_WINDOWS = 0, EXP_STEADY_MSER = 1 };

/// "windows" or "mser" to EXP_STEADY_*: 0, or 1 for another name.
int exp_drum_steady_rule_from_name(const char *name, int *out);

typedef struct exp_drum_run_opts {
    double rpm;
    double max_time;        ///< s of turning at most (the paper: 6 s)
    double sample_interval; ///< s between measurements (0.05)
    double window;          ///< s of the averaging window (1.0)
    double angle_tol_deg;   ///< steady: window means of the angle agree within this (1.0°) + half their mean sd
    double csa_tol_percent; ///< ... and of the CSA within this (0.5 %) + half their mean sd
    int adopt_network_dt;   ///< turn at the settled bed's own network step limit (1)
    /// s of turning between checks of the step against the turning bed's
    /// own network (0: never), counted in samples: the world's own checks
    /// (dem_world_set_network_check). A check reads the bed only, so a run
    /// whose step stays within the limit is the same run.
    double network_check_interval;
    /// The settled bed is first turned rigidly by this angle about the drum
    /// axis, in the drum's sense (20°): as if the drum had already turned it,
    /// which a real drum does before it avalanches. Saves the rigid turn a
    /// level bed needs before its first avalanche (0.8 s of 6 s at 4 rpm).
    double start_tilt_deg;
    /// s of turning averaged on after the steady test first holds (0: none,
    /// the two windows it compared are the result). The angle of a slumping
    /// bed saw-tooths with each avalanche (about one a second at 4 rpm), so a
    /// run's mean over two windows carries a few avalanches' noise; a study
    /// that needs the mean to a given error averages longer.
    double average_time;
    /// How the run decides that its transient is over and its mean known.
    /// EXP_STEADY_WINDOWS (0): the two windows' test above, then average_time.
    /// EXP_STEADY_MSER: after each sample, MSER-5 on the angle series and on
    /// the CSA series (experiments/common/exp_series.h) says where each one's
    /// steady part starts; the run stops once neither start lies at MSER's
    /// limit (half the samples so far: the transient may go on) and the
    /// batch-means standard errors of both means from the later start are
    /// within se_angle_deg and se_csa_percent. The result is the mean from that
    /// start; average_time is not used. Why: the windows' test holds on a 4 rpm
    /// bed that is still compacting, and its mean carries ~1° of the transient
    /// (results/benchmarks/long_turn.md); this rule cuts what the series shows
    /// as transient and stops at a stated precision instead of a fixed time.
    int steady_rule;
    double se_angle_deg, se_csa_percent;
    /// NULL: no checkpoints. Not part of what defines a run: a run resumed
    /// from its checkpoints ends as the same run uninterrupted would.
    const exp_drum_checkpoint *checkpoint;
    /// Called with each measurement of the turn as it is made (index from 0;
    /// NULL: none): a watcher, not part of what defines a run. A run resumed
    /// from a checkpoint calls it from the checkpoint's next sample on.
    void (*on_sample)(int index, const exp_drum_measure *m, void *ctx);
    void *sample_ctx;
} exp_drum_run_opts;

exp_drum_run_opts exp_default_drum_run_opts(void);

/// Turn the bed rigidly by `degrees` about the drum axis in the sense a
/// positive rpm turns the drum (dem_world_rotate: springs turn with it).
dem_status exp_drum_tilt(dem_world *w, double degrees);

/// What a rotation run measured: means and spreads over the two windows the
/// steady test compared and the average_time after them (not steady: the last
/// two windows, or what there is of them).
typedef struct exp_drum_result {
    double angle_deg, angle_sd_deg, csa_percent, csa_sd_percent;
    double fit_sd_m;        ///< mean spread of the surface about its fitted line
    double start_tilt_deg;  ///< the start tilt the bed was turned by (exp_drum_run_opts)
    int steady;             ///< 1 if the window criterion held before max_time
    double simulated_time_s, wall_time_s;
    /// Wall seconds the run had cost before the checkpoint it resumed from
    /// (0: not resumed); a caller timing the run adds them to its own clock.
    double earlier_wall_s;
    double averaged_time_s;      ///< s of turning the means and spreads are over
    double measure_wall_s;       ///< wall seconds of this call spent measuring the drum face
    /// The smallest network limit over the step seen by the run's checks
    /// (NAN: none made; a resumed run counts those before its checkpoint),
    /// how often the step had to be lowered, and the wall seconds the checks
    /// of this call took.
    double dt_margin_min;
    int dt_lowered;
    double network_check_wall_s;
    int resumed;                 ///< 1: resumed from a checkpoint
    char checkpoint_note[512];   ///< why a checkpoint found was not resumed, else ""
    unsigned long long particle_steps;
    size_t granules;
} exp_drum_result;

/// Turn a filled drum at opts->rpm until statistically steady (two
/// consecutive windows agree) or max_time; the world is changed. The contact
/// pairs of @p d are applied first, so a bed settled with other friction
/// turns with these. With opts->checkpoint, the run first resumes from its
/// checkpoint if one is there (the world's whole state is then replaced by
/// the checkpoint's, and the bed given is not used); one that cannot be
/// resumed is said in the result's checkpoint_note and the run starts afresh. The state is saved every checkpoint->every_s of
/// wall time; the file is left in place (the caller removes it once the
/// result is safe). Returns the engine status; a fault is recorded in the
/// result as not steady.
dem_status exp_drum_rotate(dem_world *w, const exp_drum_def *d, const exp_drum_run_opts *o, exp_progress_fn progress,
                           void *ctx, exp_drum_result *out);

#endif
