// SPDX-License-Identifier: MIT
// Coarse-graining laws, Tiscar et al. (2019) eq. 15–18 (after Hilton et al.).
#include "dem_scaling.h"

#include <math.h>
#include <stdio.h>

int dem_scale_check(double lambda, char *msg, size_t len)
{
    // +∞ passes `lambda >= 1` and would turn every radius infinite; NaN
    // fails both tests.
    int ok = isfinite(lambda) && lambda >= 1.0;
    if (msg && len > 0) {
        if (ok)
            msg[0] = '\0';
        else
            snprintf(msg, len, "scale factor lambda = %g: must be finite and >= 1 (lambda = N_real/N_scaled, eq. 15)",
                     lambda);
    }
    return !ok;
}

// λ^(1/3), the length ratio R^s/R^r of eq. 15; NaN for a λ that fails the
// check so the error travels into every derived quantity.
static double length_ratio(double lambda)
{
    return dem_scale_check(lambda, NULL, 0) == 0 ? cbrt(lambda) : NAN;
}

double dem_scale_radius(double r, double lambda)
{
    return r * length_ratio(lambda); // eq. 15
}

double dem_scale_density(double rho, double lambda)
{
    // Eq. 17: ρ^s/ρ^r = 1/λ, so ρ^s V^s = ρ^r V^r (eq. 16): the mass is kept.
    return dem_scale_check(lambda, NULL, 0) == 0 ? rho / lambda : NAN;
}

double dem_scale_stiffness(double k, double lambda)
{
    // Eq. 18: k^s/k^r = R^r/R^s. The overlap under a force F is F/k, so
    // h^s/R^s = h^r/R^r: the relative overlap, and with it the
    // coordination number, is kept (the paper's Fig. 2).
    return k / length_ratio(lambda);
}

dem_contact_params dem_scale_contact(const dem_contact_params *p, double lambda)
{
    // Each law's own rule (dem_contact_model.scale): the linear law's is eq.
    // 18 on k_n, k_s, k_r; Hertz–Mindlin's keeps eq. 18's relative overlap.
    return dem_contact_model_of(p->law)->scale(p, length_ratio(lambda));
}

dem_gsd dem_scale_gsd(const dem_gsd *g, double lambda)
{
    dem_gsd s = *g;
    // Eq. 15 scales every diameter by the same factor: ln d shifts by
    // ln(λ)/3, so σ_g and the truncation (in σ) are unchanged.
    s.median_diameter = dem_scale_radius(g->median_diameter, lambda);
    // A measured table: each row's diameter by the same factor; the
    // cumulative fractions (numbers of granules) are unchanged.
    for (int i = 0; i < g->table.rows; i++) s.table.diameter[i] = dem_scale_radius(g->table.diameter[i], lambda);
    return s;
}
