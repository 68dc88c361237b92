// SPDX-License-Identifier: MIT
/// @file ref_two_particles.h
/// Independent reference integration of the paper's LSD contact model
/// (Tiscar et al. 2019, section 2.1, eq. 1–14) for its verification scene
/// (Appendix A.1, Table A.1): two granules dropped on the floor y = 0.
///
/// Written from the paper's equations and the project's stated conventions
/// only. It shares no code and no headers with engine/, so that comparing
/// the engine with it can catch mistakes in either. Plain arrays, plain loops,
/// no neighbour lists, no feature masks: clarity over speed.
#ifndef REF_TWO_PARTICLES_H
#define REF_TWO_PARTICLES_H

/// Reading of eq. 4 (which sign of the normal relative velocity is damped).
/// Numbered as the engine numbers its readings; the names are the engine's.
typedef enum ref_damping {
    REF_DAMP_APPROACHING = 0, ///< damped only while approaching (v_n > 0)
    REF_DAMP_ALWAYS = 1,      ///< damped in both phases
    REF_DAMP_SEPARATING = 2,  ///< damped only while separating (v_n < 0), eq. 4 read literally
    REF_DAMP_NO_TENSION = 3,  ///< damped in both phases, normal force clamped at >= 0
} ref_damping;

/// Lever arm of the tangential force and of the tangential contact velocity.
typedef enum ref_lever {
    REF_LEVER_CONTACT_POINT = 0, ///< R_i − h/2 (pair), R_i − h (wall)
    REF_LEVER_RADIUS = 1,        ///< R_i, as eq. 7 and 9 are written
} ref_lever;

/// Options of a reference run.
typedef struct ref_options {
    int damping;     ///< a ref_damping
    int lever;       ///< a ref_lever
    double dt;       ///< time step, s (Table A.1: 1e-4)
    double duration; ///< simulated time, s (Table A.1: 5)
} ref_options;

/// Defaults: approaching-only damping, contact-point lever arm, Table A.1's
/// Δt = 1e-4 s and 5 s.
ref_options ref_default_options(void);

/// One recorded state. Index 0 is particle 1 (Table A.1, the upper one,
/// spinning), index 1 is particle 2.
typedef struct {
    double t;
    double x[2][3], v[2][3], w[2][3];
} ref_frame;

/// Interval between recorded frames, s.
#define REF_FRAME_INTERVAL 0.01

/// Number of frames a run of `duration` seconds records (frame 0 at t = 0):
/// 501 for 5 s.
int ref_frame_count(double duration);

/// Integrates the Table A.1 scene with `opt` (NULL: defaults) and writes a
/// frame every REF_FRAME_INTERVAL seconds, frame 0 at t = 0, at most
/// `max_frames`. Returns the number of frames written, or −1 on bad options
/// (dt <= 0, duration < 0, unknown damping or lever, NULL frames with
/// max_frames > 0).
int ref_two_particles_run(const ref_options *opt, ref_frame *frames, int max_frames);

// ---------------------------------------------------------------------------
// Lower level: the state of the integration, for tests that need single
// steps (energy per step, restitution of one contact).

typedef struct { double x, y, z; } ref_vec3;

/// Parameters of one contact kind (Table A.1 rows).
typedef struct ref_contact {
    double kn, ks, kr; ///< normal, tangential, rolling stiffness, N/m
    double xi;         ///< damping ratio ξ
    double mu_s, mu_r; ///< sliding, rolling friction coefficients
} ref_contact;

/// History and diagnostics of one contact (a pair, or a particle and the floor).
typedef struct ref_contact_state {
    ref_vec3 ds;  ///< tangential spring δ_s (eq. 6)
    ref_vec3 dr;  ///< rolling spring δ_r (eq. 11)
    double h;     ///< overlap at the last force evaluation (<= 0: open)
    double f;     ///< scalar normal force f at the last evaluation
} ref_contact_state;

/// The whole integration state. Fields are public on purpose: tests set up
/// other scenes (one particle, no gravity) by editing them after
/// ref_sim_init_table_a1() and before ref_sim_start().
typedef struct ref_sim {
    int n;                 ///< number of particles, 1 or 2 (pair contact only when 2)
    double R[2], m[2], I[2];
    ref_vec3 x[2], v[2], w[2];
    ref_vec3 F[2], T[2];   ///< force and torque at the current positions
    ref_vec3 g;            ///< gravity, m/s²
    ref_contact pair;      ///< particle 1 – particle 2
    ref_contact wall[2];   ///< particle i – floor
    ref_contact_state cs_pair, cs_wall[2];
    int damping, lever;
    double dt;
    long step;             ///< steps taken; time = step·dt
} ref_sim;

/// Fills `s` with Table A.1 (positions, velocities, radii, densities,
/// contact parameters, gravity) and the options. Does not evaluate forces.
void ref_sim_init_table_a1(ref_sim *s, const ref_options *opt);

/// Evaluates the initial forces (springs at zero, not incremented). Call once
/// after setting up the state, before the first ref_sim_step().
void ref_sim_start(ref_sim *s);

/// One velocity-Verlet step (kick, drift, forces, kick).
void ref_sim_step(ref_sim *s);

/// Total energy: translational and rotational kinetic, gravitational
/// (zero at y = 0), and the energy stored in the normal, tangential and
/// rolling springs of the contacts closed at the last evaluation. Without
/// damping and Coulomb slip this is conserved by eq. 1–14 (up to
/// the integrator's error).
double ref_sim_energy(const ref_sim *s);

/// Copies the state into a frame (t = step·dt).
void ref_sim_frame(const ref_sim *s, ref_frame *fr);

/// Name of a damping reading ("approaching", "always", "separating",
/// "no_tension") and its inverse (also accepts "no-tension"); -1 if unknown.
const char *ref_damping_name(int damping);
int ref_damping_from_name(const char *name);

#endif
