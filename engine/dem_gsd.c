// SPDX-License-Identifier: MIT
// Granule size distributions: the truncated log-normal of Tiscar et al. (2019,
// 3.1), and measured tables sampled by their inverse cumulative distribution.
#include "dem_gsd.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "dem_vec.h"
#include "dem_world.h"

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
    return dem_gsd_lognormal(200e-6, 1.43, 2.0);
}

dem_gsd dem_gsd_lognormal(double median_diameter, double geometric_sd, double truncation_sigmas)
{
    return (dem_gsd){.median_diameter = median_diameter, .geometric_sd = geometric_sd,
                     .truncation_sigmas = truncation_sigmas};
}

static int vfail(char *msg, size_t len, const char *fmt, va_list ap)
{
    if (msg && len > 0) vsnprintf(msg, len, fmt, ap);
    return 1;
}

static int fail(char *msg, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vfail(msg, len, fmt, ap);
    va_end(ap);
    return 1;
}

static int check_table(const dem_gsd_table *t, char *msg, size_t len)
{
    if (t->rows < 2 || t->rows > DEM_GSD_TABLE_MAX_ROWS)
        return fail(msg, len, "gsd.table: %d rows: need 2 to %d", t->rows, DEM_GSD_TABLE_MAX_ROWS);
    if (t->cumulative[0] != 0.0 || t->cumulative[t->rows - 1] != 1.0)
        return fail(msg, len, "gsd.table: the cumulative fraction must run from 0 to 1");
    for (int i = 0; i < t->rows; i++) {
        if (!(isfinite(t->diameter[i]) && t->diameter[i] > 0.0) || (i && !(t->diameter[i] > t->diameter[i - 1])))
            return fail(msg, len, "gsd.table: diameter %g m on row %d: must be > 0 and increase", t->diameter[i], i + 1);
        if (!(t->cumulative[i] >= 0.0 && t->cumulative[i] <= 1.0) || (i && t->cumulative[i] < t->cumulative[i - 1]))
            return fail(msg, len, "gsd.table: cumulative %g on row %d: must stay in [0, 1] and never decrease",
                        t->cumulative[i], i + 1);
    }
    return 0;
}

int dem_gsd_check(const dem_gsd *g, char *msg, size_t len)
{
    if (!g) return fail(msg, len, "gsd: NULL");
    if (g->table.rows != 0) {
        if (check_table(&g->table, msg, len)) return 1;
        if (msg && len > 0) msg[0] = '\0';
        return 0;
    }
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
    if (g->table.rows) return g->table.diameter[0];
    return g->median_diameter * pow(g->geometric_sd, -g->truncation_sigmas);
}

double dem_gsd_max_diameter(const dem_gsd *g)
{
    if (g->table.rows) return g->table.diameter[g->table.rows - 1];
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

// The table's diameter at cumulative number fraction u: the row interval
// that holds u (the first row whose fraction exceeds it; an interval of
// zero probability is never chosen), then linear in ln d inside it.
static double table_quantile(const dem_gsd_table *t, double u)
{
    int lo = 0, hi = t->rows - 1; // cumulative[lo] <= u < cumulative[hi] while u < 1
    if (!(u < 1.0)) return t->diameter[hi];
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (t->cumulative[mid] > u) hi = mid;
        else lo = mid;
    }
    const double f = (u - t->cumulative[lo]) / (t->cumulative[hi] - t->cumulative[lo]);
    const double x = log(t->diameter[lo]) + f * (log(t->diameter[hi]) - log(t->diameter[lo]));
    return fmin(fmax(exp(x), t->diameter[lo]), t->diameter[hi]); // exp(log(d)) may round past a row
}

// Inverse-CDF sampling: one uniform draw per diameter, so the first k of n
// draws equal a draw of k, as for the log-normal.
static void sample_table(const dem_gsd_table *t, gsl_rng *rng, size_t n, double *d)
{
    for (size_t i = 0; i < n; i++) d[i] = table_quantile(t, gsl_rng_uniform(rng));
}

int dem_gsd_sample(const dem_gsd *g, uint64_t seed, size_t n, double *diameters)
{
    if (dem_gsd_check(g, NULL, 0) != 0 || (n > 0 && !diameters)) return DEM_ERR_INVALID;
    if (g->table.rows == 0 && g->geometric_sd == 1.0) {
        // Monodisperse: exp(log(d50)) need not round back to d50, and the
        // bounds are d50 exactly, so rejection could never accept.
        for (size_t i = 0; i < n; i++) diameters[i] = g->median_diameter;
        return DEM_OK;
    }
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) return DEM_ERR_NOMEM;
    gsl_rng_set(rng, seed_to_mt(seed));
    if (g->table.rows) sample_table(&g->table, rng, n, diameters);
    else sample_truncated(g, rng, n, diameters);
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

// Mean of d³ over ln d uniform on [ln a, ln b]: ∫ e^{3x} dx / (ln b − ln a)
// = (b³ − a³) / (3 ln(b/a)). The class's representative d³ both for the
// table's mean volume and for the volume-to-number conversion.
static double class_mean_cube(double a, double b)
{
    const double w = log(b / a);
    if (!(w > 1e-12)) return a * a * a;
    return (b * b * b - a * a * a) / (3.0 * w);
}

static double table_moment3(const dem_gsd_table *t)
{
    double sum = 0.0;
    for (int i = 1; i < t->rows; i++)
        sum += (t->cumulative[i] - t->cumulative[i - 1]) * class_mean_cube(t->diameter[i - 1], t->diameter[i]);
    return sum;
}

double dem_gsd_mean_volume(const dem_gsd *g)
{
    if (dem_gsd_check(g, NULL, 0) != 0) return NAN;
    if (g->table.rows) return DEM_PI / 6.0 * table_moment3(&g->table);
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

double dem_gsd_quantile(const dem_gsd *g, double p)
{
    if (dem_gsd_check(g, NULL, 0) != 0 || !(p >= 0.0 && p <= 1.0)) return NAN;
    if (g->table.rows) return table_quantile(&g->table, p);
    if (g->geometric_sd == 1.0) return g->median_diameter;
    const double t = g->truncation_sigmas, lo = gsl_cdf_ugaussian_P(-t), hi = gsl_cdf_ugaussian_P(t);
    const double z = gsl_cdf_ugaussian_Pinv(lo + p * (hi - lo));
    return g->median_diameter * pow(g->geometric_sd, fmin(fmax(z, -t), t));
}

// A table's classes holding granules, merged into at most `max` groups of
// consecutive classes: a group's fraction the sum, its mean d³ the
// fraction-weighted mean of its classes'.
static int table_classes(const dem_gsd_table *t, int max, double *diameter, double *fraction)
{
    int held = 0;
    for (int i = 1; i < t->rows; i++) held += t->cumulative[i] > t->cumulative[i - 1];
    const int groups = held < max ? held : max;
    int k = 0, seen = 0;
    double p = 0.0, cube = 0.0;
    for (int i = 1; i < t->rows; i++) {
        const double share = t->cumulative[i] - t->cumulative[i - 1];
        if (!(share > 0.0)) continue;
        p += share, cube += share * class_mean_cube(t->diameter[i - 1], t->diameter[i]);
        // Group k holds the classes up to the (k+1)/groups share of the held ones.
        if (++seen * groups >= (k + 1) * held) {
            fraction[k] = p, diameter[k] = cbrt(cube / p);
            k++, p = 0.0, cube = 0.0;
        }
    }
    return k;
}

// E[d³ | class] of the truncated log-normal for z in [z0, z1]: complete the
// square as in truncated_moment.
static int lognormal_classes(const dem_gsd *g, int max, double *diameter, double *fraction)
{
    const double s = log(g->geometric_sd), t = g->truncation_sigmas;
    if (!(s > 0.0)) return diameter[0] = g->median_diameter, fraction[0] = 1.0, 1;
    const double kept = gsl_cdf_ugaussian_P(t) - gsl_cdf_ugaussian_P(-t), width = 2.0 * t / max;
    for (int k = 0; k < max; k++) {
        const double z0 = -t + k * width, z1 = z0 + width;
        const double n = gsl_cdf_ugaussian_P(z1) - gsl_cdf_ugaussian_P(z0);
        const double m3 = exp(4.5 * s * s) * (gsl_cdf_ugaussian_P(z1 - 3 * s) - gsl_cdf_ugaussian_P(z0 - 3 * s)) / n;
        diameter[k] = g->median_diameter * cbrt(m3), fraction[k] = n / kept;
    }
    return max;
}

int dem_gsd_classes(const dem_gsd *g, int max, double *diameter, double *fraction)
{
    if (dem_gsd_check(g, NULL, 0) != 0 || max < 1 || !diameter || !fraction) return 0;
    if (g->table.rows) return table_classes(&g->table, max, diameter, fraction);
    return lognormal_classes(g, max, diameter, fraction);
}

uint64_t dem_gsd_table_fingerprint(const dem_gsd *g)
{
    // FNV-1a over the rows' bytes: the same table, bit for bit, the same key.
    uint64_t h = 0;
    if (!g->table.rows) return h;
    h = 0xcbf29ce484222325ull;
    const dem_gsd_table *t = &g->table;
    for (int i = 0; i < t->rows; i++) {
        unsigned char bytes[2 * sizeof(double)];
        memcpy(bytes, &t->diameter[i], sizeof(double));
        memcpy(bytes + sizeof(double), &t->cumulative[i], sizeof(double));
        for (size_t k = 0; k < sizeof bytes; k++) h = (h ^ bytes[k]) * 0x100000001b3ull;
    }
    return h;
}

// ---------------------------------------------------------------- tables

static int table_fail(int *bad_row, int row, char *msg, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static int table_fail(int *bad_row, int row, char *msg, size_t len, const char *fmt, ...)
{
    if (bad_row) *bad_row = row;
    va_list ap;
    va_start(ap, fmt);
    vfail(msg, len, fmt, ap);
    va_end(ap);
    return 1;
}

// The measured rows as given: sizes positive and increasing, percentages
// in [0, 100] and never decreasing, 0 first and 100 last.
static int check_measured(const double *d, const double *c, int rows, int *bad_row, char *msg, size_t len)
{
    if (rows < 2 || rows > DEM_GSD_TABLE_MAX_ROWS)
        return table_fail(bad_row, -1, msg, len, "rows: %d given: a table needs 2 to %d rows", rows,
                          DEM_GSD_TABLE_MAX_ROWS);
    for (int i = 0; i < rows; i++) {
        if (!(isfinite(d[i]) && d[i] > 0))
            return table_fail(bad_row, i, msg, len, "size: %g m (%g um) must be a finite size > 0", d[i], 1e6 * d[i]);
        if (i && !(d[i] > d[i - 1]))
            return table_fail(bad_row, i, msg, len, "size: %g um must be larger than the row above (%g um)", 1e6 * d[i],
                              1e6 * d[i - 1]);
        if (!(c[i] >= 0 && c[i] <= 100))
            return table_fail(bad_row, i, msg, len, "cumulative_percent: %g must be in [0, 100]", c[i]);
        if (i && c[i] < c[i - 1])
            return table_fail(bad_row, i, msg, len,
                              "cumulative_percent: %g is below the row above (%g): a cumulative distribution never "
                              "decreases", c[i], c[i - 1]);
    }
    if (c[0] != 0)
        return table_fail(bad_row, 0, msg, len,
                          "cumulative_percent: %g: the first row must be 0 (the smallest size present sets the time "
                          "step, so the table must say where the sizes start)", c[0]);
    if (c[rows - 1] != 100)
        return table_fail(bad_row, rows - 1, msg, len,
                          "cumulative_percent: %g: the last row must be 100 (the table must say where the sizes end)",
                          c[rows - 1]);
    return 0;
}

// Volume fractions to number fractions, class by class. A class (between
// two rows) holding a fraction ΔQ3 of the volume holds ΔQ3 / <d³> of the
// granules, up to one factor for all classes: a granule's volume is π/6 d³,
// so counting granules means dividing each class's volume by the volume of
// its granules, then renormalising so the fractions sum to 1. The convention
// for <d³> is the one the sampler reads the number table with: granules
// spread evenly over ln d inside the class, so <d³> is the mean of d³ over
// ln d, (b³ − a³)/(3 ln(b/a)) (class_mean_cube); for narrow classes it is
// the geometric-mean convention (ab)^(3/2) of ISO 9276-2. With it, a number
// table converted to volumes and back is itself again.
static void volume_to_number(const double *d, double *cum, int rows)
{
    double total = 0.0, previous = cum[0];
    for (int i = 1; i < rows; i++) {
        const double share = (cum[i] - previous) / class_mean_cube(d[i - 1], d[i]);
        previous = cum[i];
        total += share;
        cum[i] = total;
    }
    for (int i = 1; i < rows; i++) cum[i] /= total;
    cum[0] = 0.0, cum[rows - 1] = 1.0;
}

// Standard deviation of ln d for the table read as uniform in ln d per
// class: the law of total variance over the classes.
static double table_ln_sd(const dem_gsd_table *t)
{
    double mean = 0.0, second = 0.0;
    for (int i = 1; i < t->rows; i++) {
        const double p = t->cumulative[i] - t->cumulative[i - 1];
        const double a = log(t->diameter[i - 1]), b = log(t->diameter[i]);
        mean += p * 0.5 * (a + b);
        second += p * ((a * a + a * b + b * b) / 3.0); // E[x²] of a uniform on [a, b]
    }
    return sqrt(fmax(second - mean * mean, 0.0));
}

int dem_gsd_from_table(const double *diameter, const double *cumulative_percent, int rows, dem_gsd_basis basis,
                       dem_gsd *out, int *bad_row, char *msg, size_t len)
{
    if (bad_row) *bad_row = -1;
    if (!diameter || !cumulative_percent || !out) return table_fail(bad_row, -1, msg, len, "table: NULL");
    if (basis != DEM_GSD_NUMBER && basis != DEM_GSD_VOLUME)
        return table_fail(bad_row, -1, msg, len, "basis: %d is neither number nor volume", (int)basis);
    if (check_measured(diameter, cumulative_percent, rows, bad_row, msg, len)) return 1;
    // Keep from the last 0 % row to the first 100 % row: the sizes outside
    // hold nothing, and the bounds must be the sizes a draw can reach.
    int first = 0, last = rows - 1;
    while (first + 1 < rows && cumulative_percent[first + 1] == 0) first++;
    while (last - 1 > first && cumulative_percent[last - 1] == 100) last--;
    dem_gsd g = dem_gsd_lognormal(0.0, 1.0, 0.0);
    dem_gsd_table *t = &g.table;
    t->rows = last - first + 1;
    for (int i = 0; i < t->rows; i++)
        t->diameter[i] = diameter[first + i], t->cumulative[i] = cumulative_percent[first + i] / 100.0;
    if (basis == DEM_GSD_VOLUME) volume_to_number(t->diameter, t->cumulative, t->rows);
    else t->cumulative[t->rows - 1] = 1.0;
    g.median_diameter = table_quantile(t, 0.5);
    g.geometric_sd = exp(table_ln_sd(t));
    *out = g;
    if (msg && len > 0) msg[0] = '\0';
    return 0;
}
