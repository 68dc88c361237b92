// SPDX-License-Identifier: MIT
// Contact-law registry (the laws' descriptors, the damping readings) and
// parameter handling; the kernel itself is inline in
// dem_contact.h so each force loop gets its own specialised copy.
#include "dem_contact.h"

#include <stdio.h>
#include <string.h>

// Registry of eq. 4 readings: name → (damped while approaching, damped while
// separating, clamp at zero). A small table, like LAMMPS' sub-model registry,
// so an unknown name in a config is a clean error.
static const struct {
    const char *name;
    double approaching, separating, clamp;
} damping_registry[DEM_DAMPING_MODE_COUNT] = {
    [DEM_DAMPING_APPROACHING] = {"approaching", 1.0, 0.0, 0.0},
    [DEM_DAMPING_ALWAYS] = {"always", 1.0, 1.0, 0.0},
    [DEM_DAMPING_SEPARATING] = {"separating", 0.0, 1.0, 0.0},
    [DEM_DAMPING_NO_TENSION] = {"no_tension", 1.0, 1.0, 1.0},
};

const char *dem_damping_mode_name(dem_damping_mode mode)
{
    if ((unsigned)mode >= DEM_DAMPING_MODE_COUNT) return "unknown";
    return damping_registry[mode].name;
}

int dem_damping_mode_from_name(const char *name)
{
    for (int m = 0; m < DEM_DAMPING_MODE_COUNT; ++m)
        if (name && strcmp(name, damping_registry[m].name) == 0) return m;
    return -1;
}

dem_contact_coeffs dem_contact_coeffs_make(const dem_contact_params *p)
{
    dem_contact_coeffs c = {0};
    c.k_r = p->k_r;
    c.mu_s = p->mu_s;
    c.mu_r = p->mu_r;
    c.inv_k_r = p->k_r > 0 ? 1.0 / p->k_r : 0.0;
    dem_contact_model_of(p->law)->coeffs(p, &c);
    unsigned m = (unsigned)p->damping < DEM_DAMPING_MODE_COUNT ? (unsigned)p->damping : 0u;
    c.damp_approaching = damping_registry[m].approaching;
    c.damp_separating = damping_registry[m].separating;
    c.clamp_tension = damping_registry[m].clamp;
    return c;
}

unsigned dem_contact_features(const dem_contact_params *p)
{
    const dem_contact_model *law = dem_contact_model_of(p->law);
    unsigned f = law->feature;
    if (p->xi > 0) f |= DEM_FEAT_DAMPING;
    if (law->has_tangential(p) && p->mu_s > 0) f |= DEM_FEAT_TANGENTIAL;
    if (p->k_r > 0 && p->mu_r > 0) f |= DEM_FEAT_ROLLING;
    return f;
}

static int check_field(double v, const char *field, int allow_zero, char *msg, unsigned long len)
{
    if (!isfinite(v) || v < 0 || (!allow_zero && v == 0)) {
        snprintf(msg, len, "%s = %g: must be a finite number %s", field, v, allow_zero ? ">= 0" : "> 0");
        return 1;
    }
    return 0;
}

int dem_contact_params_check(const dem_contact_params *p, char *msg, unsigned long len)
{
    if ((unsigned)p->law >= DEM_LAW_COUNT) {
        snprintf(msg, len, "law = %d: unknown contact law", (int)p->law);
        return 1;
    }
    if (dem_contact_model_of(p->law)->check(p, msg, len) || check_field(p->k_r, "k_r", 1, msg, len) ||
        check_field(p->xi, "xi", 1, msg, len) || check_field(p->mu_s, "mu_s", 1, msg, len) ||
        check_field(p->mu_r, "mu_r", 1, msg, len))
        return 1;
    if (p->xi >= 1.0) {
        // ξ ≥ 1 is over-damped: the contact never rebounds and eq. 14's step
        // no longer bounds the dashpot. The paper uses 0.7.
        snprintf(msg, len, "xi = %g: must be below 1 (over-damped contacts are not supported)", p->xi);
        return 1;
    }
    if ((unsigned)p->damping >= DEM_DAMPING_MODE_COUNT) {
        snprintf(msg, len, "damping = %d: unknown reading of eq. 4", (int)p->damping);
        return 1;
    }
    return 0;
}

// Fields one law reads and the other does not must be 0, so that a value
// set for the other law is an error, not silently ignored.
static int check_unused(double v, const char *field, const char *law, char *msg, unsigned long len)
{
    if (v != 0) {
        snprintf(msg, len, "%s = %g: not read by the %s contact law (must be 0)", field, v, law);
        return 1;
    }
    return 0;
}

// ---- The linear law (Tiscar et al. 2019, eq. 3–8): the paper's, the default.

static int linear_check(const dem_contact_params *p, char *msg, unsigned long len)
{
    return check_field(p->k_n, "k_n", 0, msg, len) || check_field(p->k_s, "k_s", 1, msg, len) ||
           check_unused(p->youngs_modulus, "youngs_modulus", "linear", msg, len) ||
           check_unused(p->shear_modulus, "shear_modulus", "linear", msg, len);
}

static void linear_coeffs(const dem_contact_params *p, dem_contact_coeffs *c)
{
    c->k_n = p->k_n;
    c->k_s = p->k_s;
    c->inv_k_s = p->k_s > 0 ? 1.0 / p->k_s : 0.0;
    c->two_xi_sqrt_kn = 2.0 * p->xi * sqrt(p->k_n); // eq. 4 without sqrt(m*)
}

static int linear_has_tangential(const dem_contact_params *p) { return p->k_s > 0; }

static dem_contact_stiffness linear_stiffness_at(const dem_contact_params *p, double h, double rstar, double mstar)
{
    // The springs do not depend on the overlap; the dashpot is eq. 4's.
    return (dem_contact_stiffness){p->k_n, p->k_s, p->k_r, 2 * p->xi * sqrt(mstar * p->k_n)};
}

static double linear_normal_energy(const dem_contact_params *p, double h, double rstar) { return 0.5 * p->k_n * h * h; }

static dem_contact_params linear_scale(const dem_contact_params *p, double length_ratio)
{
    // Eq. 18: k^s/k^r = R^r/R^s. The overlap under a force F is F/k, so
    // h^s/R^s = h^r/R^r: the relative overlap, and with it the coordination
    // number, is kept (the paper's Fig. 2). The paper takes k_n = k_s = k_r
    // (section 3.2); all three are springs on a length (overlap, tangential
    // and rolling displacement, N/m), so eq. 18 keeps each displacement in
    // proportion to R. μ_s, μ_r and ξ are dimensionless ratios: unchanged.
    dem_contact_params s = *p;
    s.k_n = p->k_n / length_ratio;
    s.k_s = p->k_s / length_ratio;
    s.k_r = p->k_r / length_ratio;
    return s;
}

// ---- Hertz–Mindlin: Hertz (1882) normal spring, Tsuji et al. (1992)
// dashpot, Mindlin (1949) no-slip tangential spring; the rolling spring is
// the linear law's (eq. 11–13). See dem_hertz_normal and docs/model.md.

static int hertz_check(const dem_contact_params *p, char *msg, unsigned long len)
{
    return check_field(p->youngs_modulus, "youngs_modulus", 0, msg, len) ||
           check_field(p->shear_modulus, "shear_modulus", 1, msg, len) ||
           check_unused(p->k_n, "k_n", "hertz_mindlin", msg, len) ||
           check_unused(p->k_s, "k_s", "hertz_mindlin", msg, len);
}

static void hertz_coeffs(const dem_contact_params *p, dem_contact_coeffs *c)
{
    c->hertz_kn = 4.0 / 3.0 * p->youngs_modulus;
    c->hertz_kt = 8.0 * p->shear_modulus;
    c->hertz_damp = 2.0 * sqrt(5.0 / 6.0) * p->xi * sqrt(2.0 * p->youngs_modulus);
}

static int hertz_has_tangential(const dem_contact_params *p) { return p->shear_modulus > 0; }

static dem_contact_stiffness hertz_stiffness_at(const dem_contact_params *p, double h, double rstar, double mstar)
{
    // Tangent stiffnesses at overlap h: dF_n/dh = 2 E* a (S_n of Tsuji's
    // dashpot), Mindlin's 8 G* a, a = sqrt(R* h).
    const double a = sqrt(rstar * (h > 0 ? h : 0));
    const double s_n = 2.0 * p->youngs_modulus * a;
    return (dem_contact_stiffness){s_n, 8.0 * p->shear_modulus * a, p->k_r,
                                   2.0 * sqrt(5.0 / 6.0) * p->xi * sqrt(s_n * mstar)};
}

static double hertz_normal_energy(const dem_contact_params *p, double h, double rstar)
{
    // ∫ (4/3) E* sqrt(R*) h^(3/2) dh = (8/15) E* sqrt(R*) h^(5/2).
    return h > 0 ? 8.0 / 15.0 * p->youngs_modulus * sqrt(rstar) * h * h * sqrt(h) : 0.0;
}

static dem_contact_params hertz_scale(const dem_contact_params *p, double length_ratio)
{
    // Eq. 18's principle, kept: under the same force (the mass is kept, eq.
    // 16–17) the relative overlap h/R is kept. Hertz: h = (3F/(4E* sqrt R))^(2/3),
    // so h/R ∝ F^(2/3) E*^(−2/3) R^(−4/3), kept for E*^s/E*^r = (R^r/R^s)²;
    // Mindlin's k_t = 8 G* sqrt(R h) ∝ G* R then scales as the linear k_s
    // (∝ 1/R) for G* ∝ 1/R² too. The rolling spring is linear: eq. 18.
    const double inv_area = 1.0 / (length_ratio * length_ratio);
    dem_contact_params s = *p;
    s.youngs_modulus = p->youngs_modulus * inv_area;
    s.shear_modulus = p->shear_modulus * inv_area;
    s.k_r = p->k_r / length_ratio;
    return s;
}

static const dem_contact_model contact_models[DEM_LAW_COUNT] = {
    [DEM_LAW_LINEAR] = {"linear", "linear spring k_n (eq. 3)", "2 xi sqrt(m* k_n) (eq. 4)",
                        "linear spring k_s, Coulomb limit (eq. 6-8)", "linear spring k_r (eq. 11-13)", 0u,
                        linear_check, linear_coeffs, linear_has_tangential, linear_stiffness_at,
                        linear_normal_energy, linear_scale},
    [DEM_LAW_HERTZ_MINDLIN] = {"hertz_mindlin", "Hertz (4/3) E* sqrt(R*) h^1.5",
                               "Tsuji 2 sqrt(5/6) xi sqrt(S_n m*)", "Mindlin 8 G* sqrt(R* h), Coulomb limit",
                               "linear spring k_r (eq. 11-13)", DEM_FEAT_HERTZ, hertz_check, hertz_coeffs,
                               hertz_has_tangential, hertz_stiffness_at, hertz_normal_energy, hertz_scale},
};

const dem_contact_model *dem_contact_model_of(dem_contact_law law)
{
    return &contact_models[(unsigned)law < DEM_LAW_COUNT ? law : DEM_LAW_LINEAR];
}

const char *dem_contact_law_name(dem_contact_law law)
{
    return (unsigned)law < DEM_LAW_COUNT ? contact_models[law].name : "unknown";
}

int dem_contact_law_from_name(const char *name)
{
    for (int m = 0; m < DEM_LAW_COUNT; ++m)
        if (name && strcmp(name, contact_models[m].name) == 0) return m;
    return -1;
}
