// SPDX-License-Identifier: MIT
/// @file dem_contact.h
/// The contact law as one stateless kernel shared by granule–granule and
/// granule–wall contacts (a wall is a granule of infinite mass and radius:
/// the caller passes m* = m_i and R* = R_i, and nothing here branches on it).
/// Two laws, each a set of sub-models named by its descriptor
/// (dem_contact_model, dem_contact_model_of):
///  - DEM_LAW_LINEAR, the default: the linear spring–dashpot (LSD) of Tiscar
///    et al. (2019), section 2.1 (eq. 3–13, docs/model.md);
///  - DEM_LAW_HERTZ_MINDLIN: Hertz normal spring, Tsuji-type dashpot, Mindlin
///    no-slip tangential spring; the same rolling spring (docs/model.md,
///    "Hertz–Mindlin").
///
/// The kernel is `static inline` and takes a feature mask that is a
/// compile-time constant at every call site in the force loops, so the
/// compiler removes every effect a scene does not use (see dem_features).
/// The law is one bit of that mask (DEM_FEAT_HERTZ): the force loops pick
/// their instantiation once per world or wall, and no contact tests the law.
#ifndef DEM_CONTACT_H
#define DEM_CONTACT_H

#include <float.h>

#include "dem_vec.h"

/// Effects a scene can switch on. Unused effects cost nothing: the force
/// loop is instantiated once per mask, and history slots exist only for the
/// springs that are on.
enum dem_feature {
    DEM_FEAT_DAMPING = 1u << 0,    ///< normal dashpot, eq. 3–4
    DEM_FEAT_TANGENTIAL = 1u << 1, ///< tangential spring with history, eq. 6–8
    DEM_FEAT_ROLLING = 1u << 2,    ///< rolling quasi-force spring, eq. 11–13
    DEM_FEAT_HERTZ = 1u << 3,      ///< the Hertz–Mindlin law's normal, dashpot and tangential stages
    DEM_FEAT_KERNEL_MASKS = 1u << 4, ///< masks the kernel reads (the bits above)
    DEM_FEAT_PERIODIC = 1u << 4,   ///< one periodic axis (loop level, not kernel)
    DEM_FEAT_COUNT_MASKS = 1u << 5
};

/// The contact law: which sub-models (normal, damping, tangential, rolling)
/// the kernel runs. Zero, the default, is the paper's law.
typedef enum dem_contact_law {
    /// Tiscar et al. (2019): linear normal spring k_n (eq. 3), dashpot
    /// 2ξ sqrt(m* k_n) (eq. 4), linear tangential spring k_s (eq. 6–8).
    DEM_LAW_LINEAR = 0,
    /// Hertz (1882) normal force (4/3) E* sqrt(R*) h^(3/2); Tsuji et al.
    /// (1992) dashpot 2 sqrt(5/6) ξ sqrt(S_n m*), S_n = 2 E* sqrt(R* h);
    /// Mindlin (1949) no-slip tangential stiffness 8 G* sqrt(R* h).
    DEM_LAW_HERTZ_MINDLIN = 1,
    DEM_LAW_COUNT = 2
} dem_contact_law;

/// Which sign of the normal relative velocity switches the dashpot of eq. 4
/// on. The equation, read literally with the sign conventions of eq. 3 and 5
/// (n_ij points from i to j, v_rel,n·n_ij > 0 while approaching), damps only
/// while the granules separate. At ξ = 0.7 the four readings give very
/// different restitution coefficients (the table in docs/model.md,
/// tests/unit/test_contact.c).
typedef enum dem_damping_mode {
    /// Damped only while approaching: the dashpot never pulls granules
    /// together, consistent with the paper's "adhesive forces are not
    /// considered". Default. e = 0.459 at ξ = 0.7.
    DEM_DAMPING_APPROACHING = 0,
    /// Damped in both phases (the classic damped oscillator). e = 0.046.
    DEM_DAMPING_ALWAYS = 1,
    /// Damped only while separating: eq. 4 read literally. e = 0.100.
    DEM_DAMPING_SEPARATING = 2,
    /// Damped in both phases, total normal force clamped at zero (never
    /// attractive). e = 0.210.
    DEM_DAMPING_NO_TENSION = 3,
    DEM_DAMPING_MODE_COUNT = 4
} dem_damping_mode;

/// Parameters of one contact kind (granule–granule, or granule–one wall
/// material), in SI units. Table 3 gives the paper's calibrated values.
/// The linear law reads k_n and k_s, the Hertz–Mindlin law E* and G*
/// instead (the other pair must be 0); both read the rest.
typedef struct dem_contact_params {
    double k_n;  ///< normal stiffness, N/m (eq. 3)
    double k_s;  ///< tangential stiffness, N/m (eq. 6)
    double k_r;  ///< rolling stiffness, N/m (eq. 11)
    /// Damping ratio ξ (eq. 4). For either law, with the dashpot on in both
    /// phases (DEM_DAMPING_ALWAYS), the restitution of a head-on collision
    /// is e = exp(−πξ/sqrt(1−ξ²)) (Hertz: Antypov & Elliott 2011).
    double xi;
    double mu_s; ///< sliding friction coefficient (eq. 8)
    double mu_r; ///< rolling friction coefficient (eq. 13)
    dem_damping_mode damping;
    dem_contact_law law;  ///< default DEM_LAW_LINEAR
    /// Hertz–Mindlin only: effective modulus E*, Pa, with 1/E* = (1−ν_i²)/E_i
    /// + (1−ν_j²)/E_j (a wall: its own E and ν, or E = ∞ for a rigid one).
    double youngs_modulus;
    /// Hertz–Mindlin only: effective shear modulus G*, Pa, with 1/G* =
    /// (2−ν_i)/G_i + (2−ν_j)/G_j; 0 switches the tangential spring off.
    double shear_modulus;
} dem_contact_params;

/// Coefficients the kernel needs, derived once from dem_contact_params so the
/// inner loop has no mode switch: the damping reading becomes two 0/1 factors
/// and a 0/1 clamp.
typedef struct dem_contact_coeffs {
    double k_n, k_s, k_r, mu_s, mu_r;
    double inv_k_s, inv_k_r;  ///< 0 where the stiffness is 0
    double two_xi_sqrt_kn;    ///< γ_n = two_xi_sqrt_kn·sqrt(m*) (eq. 4)
    double damp_approaching;  ///< 1 if the dashpot acts while approaching
    double damp_separating;   ///< 1 if the dashpot acts while separating
    double clamp_tension;     ///< 1 to clamp the normal force at zero
    // Hertz–Mindlin (DEM_FEAT_HERTZ), with a = sqrt(R* h) the contact radius:
    double hertz_kn;   ///< (4/3) E*: F_n = hertz_kn·a·h
    double hertz_kt;   ///< 8 G*: k_t = hertz_kt·a (Mindlin 1949)
    double hertz_damp; ///< 2 sqrt(5/6) ξ sqrt(2 E*): γ_n = hertz_damp·sqrt(a)·sqrt(m*)
} dem_contact_coeffs;

/// Geometry and kinematics of one contact at the current step.
typedef struct dem_contact_state {
    dem_vec3 normal;          ///< n_ij, unit, pointing from i to j
    double overlap;           ///< h_ij = R_i + R_j − |r_j − r_i| > 0
    dem_vec3 vrel;            ///< velocity of i's contact point minus j's (eq. 5, 7)
    dem_vec3 wrel;            ///< ω_i − ω_j (eq. 12); for a wall ω_j is the wall's spin
    double twist;             ///< angle the pair turned about n this step, ½(ω_i+ω_j)·n Δt
    double root_reduced_mass; ///< sqrt(m*), of eq. 4 (m* = m_i for a wall)
    double reduced_radius;    ///< R* (R_i for a wall)
    double dt;
} dem_contact_state;

/// What a contact does to granule i (j receives the opposite force, and the
/// torques of eq. 9–10, which the caller forms from these).
typedef struct dem_contact_out {
    dem_vec3 force;        ///< F_ij,n + F_ij,s on i
    dem_vec3 f_tangential; ///< F_ij,s on i
    dem_vec3 f_rolling;    ///< rolling quasi-force F_ij,r
    double normal_force;   ///< signed magnitude along −n_ij (> 0 repulsive)
    double damping_coeff;  ///< γ_n the dashpot applied this step (0 if off, or clamped away)
    /// Stiffness of the tangential / rolling spring for the implicit spring
    /// solve: k while the spring sticks, 0 while it slides (a Coulomb-limited
    /// force, eq. 8 and 13, has no stiffness) or when the spring is off.
    double k_tangential, k_rolling;
} dem_contact_out;

/// Doubles of history a contact needs for the given feature mask.
static inline int dem_history_len(unsigned features)
{
    return 3 * (((features & DEM_FEAT_TANGENTIAL) != 0) + ((features & DEM_FEAT_ROLLING) != 0));
}

/// Whether two feature masks store the same springs in their history: a
/// tangential-only and a rolling-only contact both hold 3 doubles, and one
/// must not be read as the other.
static inline int dem_same_history_layout(unsigned a, unsigned b)
{
    const unsigned springs = DEM_FEAT_TANGENTIAL | DEM_FEAT_ROLLING;
    return (a & springs) == (b & springs);
}

/// Stiffnesses of a contact at overlap h with effective radius R*, as its
/// linearisation reads them: the normal tangent stiffness dF_n/dh, the
/// tangential and the rolling spring (sticking), and the dashpot γ_n.
typedef struct dem_contact_stiffness {
    double k_n, k_t, k_r, gamma;
} dem_contact_stiffness;

/// The descriptor of a contact law: its sub-models by name, the kernel's
/// mask bit for it, and what the code outside the kernel needs of it — the
/// check, the coefficients, the linearisation (stability limit), the
/// elastic energy (diagnostics) and the coarse-graining rule (dem_scaling.c).
/// One row per dem_contact_law (dem_contact.c); the force loops read only
/// the mask bit.
typedef struct dem_contact_model {
    const char *name;                                  ///< "linear", "hertz_mindlin"
    const char *normal, *damping, *tangential, *rolling; ///< sub-models, for reports
    unsigned feature;                                  ///< kernel bit: 0 or DEM_FEAT_HERTZ
    /// Check the law's own fields; message naming the field, non-zero on error.
    int (*check)(const dem_contact_params *p, char *msg, unsigned long msg_len);
    /// Its coefficients into c (the law-independent ones are set already).
    void (*coeffs)(const dem_contact_params *p, dem_contact_coeffs *c);
    /// Whether the parameters switch the tangential spring on (with μ_s > 0).
    int (*has_tangential)(const dem_contact_params *p);
    /// Stiffnesses at overlap h, R*, m* (see dem_contact_stiffness).
    dem_contact_stiffness (*stiffness_at)(const dem_contact_params *p, double h, double rstar, double mstar);
    /// Elastic energy of the normal spring at overlap h, R*.
    double (*normal_energy)(const dem_contact_params *p, double h, double rstar);
    /// Coarse-grained parameters for λ = N_real/N_scaled (eq. 15–18's
    /// principle: the relative overlap h/R under the same force is kept).
    dem_contact_params (*scale)(const dem_contact_params *p, double length_ratio);
} dem_contact_model;

/// The descriptor of a law; that of DEM_LAW_LINEAR for an unknown value
/// (dem_contact_params_check rejects one).
const dem_contact_model *dem_contact_model_of(dem_contact_law law);

/// Name of a contact law ("linear", "hertz_mindlin") and its inverse; -1 for
/// an unknown name.
const char *dem_contact_law_name(dem_contact_law law);
int dem_contact_law_from_name(const char *name);

/// Derive kernel coefficients from parameters.
dem_contact_coeffs dem_contact_coeffs_make(const dem_contact_params *p);

/// Features a parameter set actually uses (a friction of zero switches the
/// spring off: it could never carry force).
unsigned dem_contact_features(const dem_contact_params *p);

/// Name of a damping reading ("approaching", "always", "separating",
/// "no_tension"), and its inverse; returns -1 for an unknown name.
const char *dem_damping_mode_name(dem_damping_mode mode);
int dem_damping_mode_from_name(const char *name);

/// Check a parameter set; on error writes a message naming the field and
/// returns non-zero.
int dem_contact_params_check(const dem_contact_params *p, char *msg, unsigned long msg_len);

/// Carry a history spring onto the contact's current tangent plane: turn it
/// with the pair about n (twist), project it onto the plane normal to n, and
/// rescale it to its old length (Luding 2008), so rigid motion of the pair
/// neither creates nor destroys spring length.
static DEM_ALWAYS_INLINE dem_vec3 dem_spring_carry(dem_vec3 spring, dem_vec3 n, double twist)
{
    // Branch-free, so that a batch of contacts vectorises (dem_contact_batch_internal.h): a
    // zero spring, or one turned onto n, projects to zero and keeps scale 0;
    // the guard only keeps the unused quotient finite.
    double len2 = dem_v3_norm2(spring);
    dem_vec3 turned = dem_v3_axpy(twist, dem_v3_cross(n, spring), spring);
    dem_vec3 proj = dem_v3_axpy(-dem_v3_dot(turned, n), n, turned);
    double plen2 = dem_v3_norm2(proj);
    double ratio = sqrt(len2 / (plen2 > DBL_MIN ? plen2 : DBL_MIN));
    return dem_v3_scale(proj, plen2 > 0.0 ? ratio : 0.0);
}

/// The law in stages, each a function of the last one's results, so that a
/// batch of contacts can run each stage over the whole batch in turn
/// (dem_contact_batch_internal.h): a stage's chain of dependent square roots and divisions
/// is then short, and the processor overlaps it across contacts, where the
/// whole law in one loop left it waiting on each chain in turn.
/// dem_contact_eval runs the same stages one after the other: one
/// arithmetic, bit for bit, for every caller.

/// Advance one history spring: carried onto the current tangent plane, then
/// moved by its relative velocity over dt (eq. 6 for sliding, eq. 11 for
/// rolling); returns it, and its elastic force F = −k·δ in `force`.
static DEM_ALWAYS_INLINE dem_vec3 dem_spring_advance(const double *hist, dem_vec3 n, double twist, dem_vec3 vel,
                                                     double dt, double k, dem_vec3 *force)
{
    dem_vec3 spring = dem_spring_carry(dem_v3(hist[0], hist[1], hist[2]), n, twist);
    spring = dem_v3_axpy(dt, vel, spring);
    *force = dem_v3_scale(spring, -k);
    return spring;
}

/// The Coulomb limit on an advanced spring and its force: |F| ≤ μ|F_n|; on
/// truncation the spring is reset so that k|δ| equals the limit (eq. 8 for
/// sliding, eq. 13 for rolling). Stores the spring in `hist`, returns the
/// force; `*sticking` becomes 1 if the spring stayed below the limit.
static DEM_ALWAYS_INLINE dem_vec3 dem_spring_limit(double *hist, dem_vec3 spring, dem_vec3 force, double inv_k,
                                                   double limit, int *sticking)
{
    // Branch-free as dem_spring_carry: both outcomes computed, one kept.
    double f2 = dem_v3_norm2(force);
    const int slides = f2 > limit * limit;
    *sticking = !slides;
    const dem_vec3 truncated = dem_v3_scale(force, limit / sqrt(f2 > DBL_MIN ? f2 : DBL_MIN));
    const dem_vec3 reset = dem_v3_scale(truncated, -inv_k);
    force = slides ? truncated : force;
    spring = slides ? reset : spring;
    hist[0] = spring.x;
    hist[1] = spring.y;
    hist[2] = spring.z;
    return force;
}

/// What drives the springs, from the normal stage.
typedef struct dem_contact_drive {
    double fn_abs; ///< |F_n|, to which the Coulomb limits are proportional
    dem_vec3 vt;   ///< tangential part of the contact-point velocity (eq. 7)
    dem_vec3 vr;   ///< rolling velocity −R* (ω_i − ω_j) × n (eq. 12)
    /// Hertz–Mindlin: the tangential stiffness at this overlap and its
    /// inverse (0 where it is 0); the linear law uses k_s of the coefficients.
    double k_t, inv_k_t;
} dem_contact_drive;

/// The Hertz–Mindlin normal stage, with a = sqrt(R* h) the contact radius:
/// F_n = (4/3) E* a h (Hertz 1882; Johnson 1985, sec. 4.2), the dashpot
/// γ_n = 2 sqrt(5/6) ξ sqrt(S_n m*) with S_n = 2 E* a (Tsuji et al. 1992, in
/// the form of LIGGGHTS and Antypov & Elliott 2011), and Mindlin's (1949)
/// no-slip tangential stiffness k_t = 8 G* a. Returns the elastic force;
/// *gamma_unit is γ_n for a dashpot that is on.
static DEM_ALWAYS_INLINE double dem_hertz_normal(const dem_contact_coeffs *c, const dem_contact_state *s,
                                                 double *gamma_unit, dem_contact_drive *drive)
{
    const double a = sqrt(s->reduced_radius * s->overlap);
    *gamma_unit = c->hertz_damp * sqrt(a) * s->root_reduced_mass;
    drive->k_t = c->hertz_kt * a;
    drive->inv_k_t = drive->k_t > DBL_MIN ? 1.0 / drive->k_t : 0.0; // a select: the batch stays vectorised
    return c->hertz_kn * a * s->overlap;
}

/// First stage of the law: the normal force of eq. 3–4 into out->force,
/// out->normal_force and out->damping_coeff; the springs' drive.
static DEM_ALWAYS_INLINE dem_contact_drive dem_contact_normal(const dem_contact_coeffs *c,
                                                              const dem_contact_state *s, dem_contact_out *out,
                                                              const unsigned features)
{
    const dem_vec3 n = s->normal;
    const double vn = dem_v3_dot(s->vrel, n); // > 0 approaching (eq. 5)
    dem_contact_drive drive = {0.0, dem_v3(0, 0, 0), dem_v3(0, 0, 0), 0.0, 0.0};
    // Eq. 3: F_n = −k_n h n − γ_n v_rel,n; here fn is its magnitude along −n.
    // Hertz–Mindlin: the same with its own spring and dashpot.
    double hertz_gamma = 0.0;
    double fn = (features & DEM_FEAT_HERTZ) ? dem_hertz_normal(c, s, &hertz_gamma, &drive) : c->k_n * s->overlap;
    out->damping_coeff = 0.0;
    if (features & DEM_FEAT_DAMPING) {
        // Eq. 4: γ_n = 2ξ sqrt(m* k_n), on for the phase(s) the reading selects.
        double on = vn > 0.0 ? c->damp_approaching : c->damp_separating;
        double gamma = (features & DEM_FEAT_HERTZ) ? on * hertz_gamma : on * c->two_xi_sqrt_kn * s->root_reduced_mass;
        fn += gamma * vn;
        int clamped = c->clamp_tension != 0.0 && fn < 0.0;
        fn = clamped ? 0.0 : fn;
        out->damping_coeff = clamped ? 0.0 : gamma;
    }
    out->normal_force = fn;
    out->force = dem_v3_scale(n, -fn);
    drive.fn_abs = fabs(fn);
    // Eq. 7: tangential part of the contact-point relative velocity.
    if (features & DEM_FEAT_TANGENTIAL) drive.vt = dem_v3_axpy(-vn, n, s->vrel);
    // Eq. 12: v_rel,r = −R* (ω_i − ω_j) × n.
    if (features & DEM_FEAT_ROLLING) drive.vr = dem_v3_scale(dem_v3_cross(s->wrel, n), -s->reduced_radius);
    return drive;
}

/// Slot in the history of the rolling spring: after the tangential one.
static inline int dem_rolling_slot(unsigned features) { return (features & DEM_FEAT_TANGENTIAL) ? 3 : 0; }

/// The tangential spring's stiffness and its inverse: k_s (eq. 6), or
/// Mindlin's at this overlap (dem_hertz_normal).
static DEM_ALWAYS_INLINE double dem_tangential_k(const dem_contact_coeffs *c, const dem_contact_drive *d,
                                                 double *inv_k, const unsigned features)
{
    *inv_k = (features & DEM_FEAT_HERTZ) ? d->inv_k_t : c->inv_k_s;
    return (features & DEM_FEAT_HERTZ) ? d->k_t : c->k_s;
}

/// The contact law, eq. 3–8 and 11–13 (or Hertz–Mindlin's normal and
/// tangential stages). `features` must be a constant at
/// the call site. `hist` holds dem_history_len(features) doubles: tangential
/// spring δ_s first (if on), then rolling spring δ_r (if on); zero for a new
/// contact. Springs store displacements; forces are −k·δ.
static DEM_ALWAYS_INLINE void dem_contact_eval(const dem_contact_coeffs *c, const dem_contact_state *s, double *hist,
                                    dem_contact_out *out, const unsigned features)
{
    const dem_contact_drive drive = dem_contact_normal(c, s, out, features);
    int stick = 0;
    out->k_tangential = out->k_rolling = 0.0;
    out->f_tangential = out->f_rolling = dem_v3(0, 0, 0);
    if (features & DEM_FEAT_TANGENTIAL) {
        dem_vec3 f;
        double inv_k;
        const double k = dem_tangential_k(c, &drive, &inv_k, features);
        const dem_vec3 spring = dem_spring_advance(hist, s->normal, s->twist, drive.vt, s->dt, k, &f);
        out->f_tangential = dem_spring_limit(hist, spring, f, inv_k, c->mu_s * drive.fn_abs, &stick);
        out->k_tangential = stick ? k : 0.0;
        out->force = dem_v3_add(out->force, out->f_tangential);
    }
    if (features & DEM_FEAT_ROLLING) {
        double *h = hist + dem_rolling_slot(features);
        dem_vec3 f;
        const dem_vec3 spring = dem_spring_advance(h, s->normal, s->twist, drive.vr, s->dt, c->k_r, &f);
        out->f_rolling = dem_spring_limit(h, spring, f, c->inv_k_r, c->mu_r * drive.fn_abs, &stick);
        out->k_rolling = stick ? c->k_r : 0.0;
    }
}

#endif
