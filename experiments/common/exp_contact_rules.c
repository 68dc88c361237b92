// SPDX-License-Identifier: MIT
// The paper's contact-pair rules (see exp_contact_rules.h).
#include "exp_contact_rules.h"

#include <string.h>

#include "exp_common.h"

int exp_damping_from_name(const char *name, const char *field, dem_damping_mode *out, char *err, size_t len)
{
    int mode = name ? dem_damping_mode_from_name(name) : EXP_DAMPING_DEFAULT;
    if (mode < 0) return exp_fail(err, len, "%s = '%s': use approaching, always, separating or no_tension", field, name);
    *out = (dem_damping_mode)mode;
    return 0;
}

// A pair with its padding zeroed: definitions are compared and saved byte for byte.
static dem_contact_params pair(double k, double xi, double mu_s, double mu_r, dem_damping_mode damping)
{
    dem_contact_params p;
    memset(&p, 0, sizeof p);
    p.k_n = p.k_s = p.k_r = k;
    p.xi = xi, p.mu_s = mu_s, p.mu_r = mu_r, p.damping = damping;
    return p;
}

dem_contact_params exp_granule_pair(double k_n, double xi, double mu_s, double mu_r, dem_damping_mode damping)
{
    return pair(k_n, xi, mu_s, mu_r, damping);
}

double exp_boundary_stiffness(double granule_k_n) { return 2 * granule_k_n; }

dem_contact_params exp_boundary_pair(const dem_contact_params *granule, double mu_s, double mu_r)
{
    return pair(exp_boundary_stiffness(granule->k_n), granule->xi, mu_s, mu_r, granule->damping);
}
