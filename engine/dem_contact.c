// SPDX-License-Identifier: MIT
// Contact-law registry and parameter handling; the kernel itself is inline in
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
    c.k_n = p->k_n;
    c.k_s = p->k_s;
    c.k_r = p->k_r;
    c.mu_s = p->mu_s;
    c.mu_r = p->mu_r;
    c.inv_k_s = p->k_s > 0 ? 1.0 / p->k_s : 0.0;
    c.inv_k_r = p->k_r > 0 ? 1.0 / p->k_r : 0.0;
    c.two_xi_sqrt_kn = 2.0 * p->xi * sqrt(p->k_n);
    unsigned m = (unsigned)p->damping < DEM_DAMPING_MODE_COUNT ? (unsigned)p->damping : 0u;
    c.damp_approaching = damping_registry[m].approaching;
    c.damp_separating = damping_registry[m].separating;
    c.clamp_tension = damping_registry[m].clamp;
    return c;
}

unsigned dem_contact_features(const dem_contact_params *p)
{
    unsigned f = 0;
    if (p->xi > 0) f |= DEM_FEAT_DAMPING;
    if (p->k_s > 0 && p->mu_s > 0) f |= DEM_FEAT_TANGENTIAL;
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
    if (check_field(p->k_n, "k_n", 0, msg, len) || check_field(p->k_s, "k_s", 1, msg, len) ||
        check_field(p->k_r, "k_r", 1, msg, len) || check_field(p->xi, "xi", 1, msg, len) ||
        check_field(p->mu_s, "mu_s", 1, msg, len) || check_field(p->mu_r, "mu_r", 1, msg, len))
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
