// SPDX-License-Identifier: MIT
// Truncated log-normal granule size distribution (Tiscar et al. 2019, 3.1).
#include "dem_gsd.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "dem_world.h"

#ifndef DEM_PI
#define DEM_PI 3.14159265358979323846
#endif

// Below half a sigma the distribution is all but monodisperse and rejection
// throws away most draws (acceptance 38% at 0.5); use σ_g = 1 for that.
#define DEM_GSD_MIN_TRUNCATION 0.5

dem_gsd dem_default_gsd(void)
{
    // Why truncate, and at 2σ: the paper's sieve analysis of the spray-dried
    // powder (Fig. 3) spans roughly 100–500 µm, and ±2σ of the fitted
    // log-normal is 98–409 µm, keeping 95.4% of the number distribution.
    // The lightest granule sets the time step (eq. 14, Δt_crit =
    // sqrt(m_min/k_n)), so an untruncated tail would draw ever smaller
    // granules as N grows and make the step arbitrarily small; the largest
    // granule sets the neighbour-cell size.
    return (dem_gsd){.median_diameter = 200e-6, .geometric_sd = 1.43, .truncation_sigmas = 2.0};
}

static int fail(char *msg, size_t len, const char *fmt, ...)
{
    if (msg && len > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, len, fmt, ap);
        va_end(ap);
    }
    return 1;
}

int dem_gsd_check(const dem_gsd *g, char *msg, size_t len)
{
    if (!g) return fail(msg, len, "gsd: NULL");
    if (!isfinite(g->median_diameter) || g->median_diameter <= 0.0)
        return fail(msg, len, "gsd.median_diameter = %g m: must be finite and > 0", g->median_diameter);
    if (!isfinite(g->geometric_sd) || g->geometric_sd < 1.0)
        return fail(msg, len, "gsd.geometric_sd = %g: must be finite and >= 1 (1 = monodisperse)", g->geometric_sd);
    if (!isfinite(g->truncation_sigmas) || g->truncation_sigmas < DEM_GSD_MIN_TRUNCATION)
        return fail(msg, len, "gsd.truncation_sigmas = %g: must be finite and >= %g", g->truncation_sigmas,
                    DEM_GSD_MIN_TRUNCATION);
    double lo = dem_gsd_min_diameter(g), hi = dem_gsd_max_diameter(g);
    if (!(lo > 0.0) || !isfinite(hi))
        return fail(msg, len, "gsd: geometric_sd^truncation_sigmas = %g^%g puts the diameter range [%g, %g] m "
                    "outside the doubles", g->geometric_sd, g->truncation_sigmas, lo, hi);
    if (msg && len > 0) msg[0] = '\0';
    return 0;
}

double dem_gsd_min_diameter(const dem_gsd *g)
{
    return g->median_diameter * pow(g->geometric_sd, -g->truncation_sigmas);
}

double dem_gsd_max_diameter(const dem_gsd *g)
{
    return g->median_diameter * pow(g->geometric_sd, g->truncation_sigmas);
}

// GSL's mt19937 keeps only the low 32 bits of its seed (and maps 0 to 4357),
// so seeds differing only in their high bits would alias. Mixing the whole
// 64-bit seed first (SplitMix64 finaliser) makes every bit count; two seeds
// collide with probability 2^-32.
static unsigned long seed_to_mt(uint64_t seed)
{
    uint64_t z = seed + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (unsigned long)((z ^ (z >> 32)) & 0xffffffffull);
}

static void sample_truncated(const dem_gsd *g, gsl_rng *rng, size_t n, double *d)
{
    const double zeta = log(g->median_diameter), sigma = log(g->geometric_sd);
    // Accept against the very bounds dem_gsd_min/max_diameter report, so a
    // caller checking draws against them never sees one a round-off outside.
    const double lo = dem_gsd_min_diameter(g), hi = dem_gsd_max_diameter(g);
    for (size_t i = 0; i < n; i++) {
        double x;
        do {
            x = gsl_ran_lognormal(rng, zeta, sigma);
        } while (!(x >= lo && x <= hi));
        d[i] = x;
    }
}

int dem_gsd_sample(const dem_gsd *g, uint64_t seed, size_t n, double *diameters)
{
    if (dem_gsd_check(g, NULL, 0) != 0 || (n > 0 && !diameters)) return DEM_ERR_INVALID;
    if (g->geometric_sd == 1.0) {
        // Monodisperse: exp(log(d50)) need not round back to d50, and the
        // bounds are d50 exactly, so rejection could never accept.
        for (size_t i = 0; i < n; i++) diameters[i] = g->median_diameter;
        return DEM_OK;
    }
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) return DEM_ERR_NOMEM;
    gsl_rng_set(rng, seed_to_mt(seed));
    sample_truncated(g, rng, n, diameters);
    gsl_rng_free(rng);
    return DEM_OK;
}

// E[d^k] of the truncated distribution. With d = exp(ζ + s z), z a standard
// normal truncated to [−t, t]: E[e^{ksz}] over the truncated range is
// e^{k²s²/2} [Φ(t − ks) − Φ(−t − ks)] / [Φ(t) − Φ(−t)] (complete the square).
static double truncated_moment(const dem_gsd *g, double k)
{
    const double zeta = log(g->median_diameter), s = log(g->geometric_sd), t = g->truncation_sigmas;
    const double ks = k * s;
    const double kept = gsl_cdf_ugaussian_P(t) - gsl_cdf_ugaussian_P(-t);
    const double shifted = gsl_cdf_ugaussian_P(t - ks) - gsl_cdf_ugaussian_P(-t - ks);
    return exp(k * zeta + 0.5 * ks * ks) * shifted / kept;
}

double dem_gsd_mean_volume(const dem_gsd *g)
{
    if (dem_gsd_check(g, NULL, 0) != 0) return NAN;
    return DEM_PI / 6.0 * truncated_moment(g, 3.0);
}

size_t dem_gsd_count_for_volume(const dem_gsd *g, double solid_volume)
{
    if (!isfinite(solid_volume) || solid_volume <= 0.0) return 0;
    const double mean = dem_gsd_mean_volume(g);
    if (!isfinite(mean)) return 0;
    const double q = solid_volume / mean;
    // An exact multiple of the mean volume must not round up to one extra.
    const double nearest = nearbyint(q);
    double count = fabs(q - nearest) <= 1e-12 * nearest ? nearest : ceil(q);
    if (count < 1.0) count = 1.0; // a positive volume needs a granule, even one that underflows q
    if (!(count < (double)SIZE_MAX)) return SIZE_MAX;
    return (size_t)count;
}
