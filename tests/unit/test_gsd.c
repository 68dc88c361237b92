// SPDX-License-Identifier: MIT
// Truncated log-normal GSD (engine/dem_gsd.c) against independent results:
// sample statistics against the truncated-normal formulae, the analytic mean
// volume against quadrature and Monte Carlo, determinism, and bad input.
// Measured tables: a table written from a log-normal's CDF samples that
// log-normal; a volume-based one converts to the number distribution the
// Hatch-Choate relation predicts; bad tables are refused with the row named.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>

#include "dem_gsd.h"
#include "dem_scaling.h"
#include "dem_vec.h"
#include "dem_world.h"
#include "exp_gsd_table.h"

enum { N_DRAWS = 200000 };
static const uint64_t SEED = 20190501u;

// cmocka's assert_float_equal works in float; this keeps doubles and says
// what was compared.
static void assert_rel(double got, double want, double rel, const char *what)
{
    double err = fabs(got - want) / fabs(want);
    if (!(err <= rel)) {
        print_error("%s: got %.10g, want %.10g, relative error %.3g > %.3g\n", what, got, want, err, rel);
        fail();
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double *draw(const dem_gsd *g, uint64_t seed, size_t n)
{
    double *d = malloc(n * sizeof *d);
    assert_non_null(d);
    assert_int_equal(dem_gsd_sample(g, seed, n, d), DEM_OK);
    return d;
}

static void test_default_is_paper(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    assert_true(g.median_diameter == 200e-6);
    assert_true(g.geometric_sd == 1.43);
    assert_true(g.truncation_sigmas == 2.0);
    char msg[256];
    assert_int_equal(dem_gsd_check(&g, msg, sizeof msg), 0);
    // Bounds computed here from the definition: 200 µm · 1.43^(∓2).
    assert_rel(dem_gsd_min_diameter(&g), 200e-6 / (1.43 * 1.43), 1e-14, "min diameter");
    assert_rel(dem_gsd_max_diameter(&g), 200e-6 * 1.43 * 1.43, 1e-14, "max diameter");
}

static void test_sample_median(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double *d = draw(&g, SEED, N_DRAWS);
    qsort(d, N_DRAWS, sizeof *d, cmp_double);
    double median = 0.5 * (d[N_DRAWS / 2 - 1] + d[N_DRAWS / 2]);
    print_message("sample median %.6g m (want 200e-6)\n", median);
    assert_rel(median, 200e-6, 0.01, "sample median");
    free(d);
}

// Standard deviation of a standard normal truncated to [−t, t]:
// Var = 1 − 2tφ(t)/(Φ(t) − Φ(−t)) (the symmetric case of the textbook
// truncated-normal variance; the mean is 0).
static double truncated_normal_sd(double t)
{
    double kept = gsl_cdf_ugaussian_P(t) - gsl_cdf_ugaussian_P(-t);
    return sqrt(1.0 - 2.0 * t * gsl_ran_ugaussian_pdf(t) / kept);
}

static void test_sample_geometric_sd(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double *d = draw(&g, SEED, N_DRAWS);
    double sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < N_DRAWS; i++) sum += log(d[i]);
    double mean = sum / N_DRAWS;
    for (size_t i = 0; i < N_DRAWS; i++) sum2 += (log(d[i]) - mean) * (log(d[i]) - mean);
    double sd = sqrt(sum2 / (N_DRAWS - 1));
    double want = log(1.43) * truncated_normal_sd(2.0);
    print_message("sd of ln d %.6g (truncated analytic %.6g, untruncated %.6g); geometric sd %.5g vs %.5g\n", sd,
                  want, log(1.43), exp(sd), exp(want));
    assert_rel(sd, want, 0.01, "sd of ln d");
    assert_rel(exp(sd), exp(want), 0.01, "geometric sd");
    assert_rel(mean, log(200e-6), 0.01, "mean of ln d");
    free(d);
}

static void test_draws_inside_bounds(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double *d = draw(&g, SEED, N_DRAWS);
    double lo = dem_gsd_min_diameter(&g), hi = dem_gsd_max_diameter(&g);
    double dmin = d[0], dmax = d[0];
    for (size_t i = 0; i < N_DRAWS; i++) {
        assert_true(d[i] >= lo && d[i] <= hi);
        dmin = fmin(dmin, d[i]);
        dmax = fmax(dmax, d[i]);
    }
    print_message("draws span [%.4g, %.4g] m, bounds [%.4g, %.4g] m\n", dmin, dmax, lo, hi);
    // The tails are populated up to the cut (the density there is not small).
    assert_true(dmin < lo * 1.01 && dmax > hi * 0.99);
    free(d);
}

static void test_determinism(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    const size_t n = 10000;
    double *a = draw(&g, SEED, n), *b = draw(&g, SEED, n), *c = draw(&g, SEED + 1, n);
    double *prefix = draw(&g, SEED, n / 2);
    // High bits must count too: GSL's mt19937 alone keeps only 32 of them.
    double *high = draw(&g, SEED + (UINT64_C(1) << 32), n);
    assert_memory_equal(a, b, n * sizeof *a);
    assert_memory_equal(a, prefix, (n / 2) * sizeof *a);
    size_t same_c = 0, same_high = 0;
    for (size_t i = 0; i < n; i++) {
        same_c += a[i] == c[i];
        same_high += a[i] == high[i];
    }
    assert_true(same_c < n / 100);
    assert_true(same_high < n / 100);
    free(a), free(b), free(c), free(prefix), free(high);
}

struct cube_ctx {
    double zeta, sigma;
};

static double cube_times_pdf(double d, void *p)
{
    const struct cube_ctx *c = p;
    return d * d * d * gsl_ran_lognormal_pdf(d, c->zeta, c->sigma);
}

// π/6·E[d³] over the truncated range by adaptive quadrature of the
// log-normal density, normalised by the kept fraction: independent of the
// closed form in dem_gsd.c.
static double quadrature_mean_volume(const dem_gsd *g)
{
    struct cube_ctx c = {log(g->median_diameter), log(g->geometric_sd)};
    gsl_function f = {cube_times_pdf, &c};
    gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
    double moment = 0.0, err = 0.0;
    gsl_integration_qags(&f, dem_gsd_min_diameter(g), dem_gsd_max_diameter(g), 0.0, 1e-12, 1000, w, &moment, &err);
    gsl_integration_workspace_free(w);
    double t = g->truncation_sigmas;
    return DEM_PI / 6.0 * moment / (gsl_cdf_ugaussian_P(t) - gsl_cdf_ugaussian_P(-t));
}

static void test_mean_volume(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double *d = draw(&g, SEED, N_DRAWS);
    double sum = 0.0;
    for (size_t i = 0; i < N_DRAWS; i++) sum += DEM_PI / 6.0 * d[i] * d[i] * d[i];
    double mc = sum / N_DRAWS, analytic = dem_gsd_mean_volume(&g), quad = quadrature_mean_volume(&g);
    print_message("mean volume: analytic %.8g, quadrature %.8g, Monte Carlo %.8g m^3 (median sphere %.8g)\n",
                  analytic, quad, mc, DEM_PI / 6.0 * pow(200e-6, 3));
    assert_rel(analytic, quad, 1e-9, "analytic vs quadrature mean volume");
    assert_rel(analytic, mc, 0.01, "analytic vs Monte Carlo mean volume");
    // A wider cut keeps more of the heavy upper tail: the mean volume grows.
    dem_gsd wide = g;
    wide.truncation_sigmas = 3.0;
    assert_rel(dem_gsd_mean_volume(&wide), quadrature_mean_volume(&wide), 1e-9, "mean volume at 3 sigma");
    assert_true(dem_gsd_mean_volume(&wide) > analytic);
    free(d);
}

static void test_monodisperse(void **state)
{
    (void)state;
    dem_gsd g = {.median_diameter = 1e-3, .geometric_sd = 1.0, .truncation_sigmas = 2.0};
    double d[64];
    assert_int_equal(dem_gsd_sample(&g, SEED, 64, d), DEM_OK);
    for (size_t i = 0; i < 64; i++) assert_true(d[i] == 1e-3);
    assert_rel(dem_gsd_mean_volume(&g), DEM_PI / 6.0 * 1e-9, 1e-14, "monodisperse mean volume");
}

static void test_count_for_volume(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double v = dem_gsd_mean_volume(&g);
    assert_int_equal(dem_gsd_count_for_volume(&g, 1000.0 * v), 1000);
    assert_int_equal(dem_gsd_count_for_volume(&g, 1000.5 * v), 1001);
    assert_int_equal(dem_gsd_count_for_volume(&g, 0.25 * v), 1);
    assert_int_equal(dem_gsd_count_for_volume(&g, 0.0), 0);
    assert_int_equal(dem_gsd_count_for_volume(&g, -1.0), 0);
    assert_int_equal(dem_gsd_count_for_volume(&g, NAN), 0);
}

static void expect_rejected(dem_gsd g, const char *field)
{
    char msg[256] = "";
    assert_int_not_equal(dem_gsd_check(&g, msg, sizeof msg), 0);
    print_message("rejected: %s\n", msg);
    assert_non_null(strstr(msg, field));
    double d[4];
    assert_int_equal(dem_gsd_sample(&g, SEED, 4, d), DEM_ERR_INVALID);
    assert_true(isnan(dem_gsd_mean_volume(&g)));
    assert_int_equal(dem_gsd_count_for_volume(&g, 1.0), 0);
}

static void test_bad_parameters(void **state)
{
    (void)state;
    const dem_gsd ok = dem_default_gsd();
    dem_gsd g = ok;
    g.median_diameter = -200e-6;
    expect_rejected(g, "median_diameter");
    g.median_diameter = NAN;
    expect_rejected(g, "median_diameter");
    g = ok;
    g.geometric_sd = 0.9;
    expect_rejected(g, "geometric_sd");
    g.geometric_sd = NAN;
    expect_rejected(g, "geometric_sd");
    g = ok;
    g.truncation_sigmas = NAN;
    expect_rejected(g, "truncation_sigmas");
    g.truncation_sigmas = INFINITY;
    expect_rejected(g, "truncation_sigmas");
    g.truncation_sigmas = 0.0;
    expect_rejected(g, "truncation_sigmas");
    assert_int_equal(dem_gsd_sample(&ok, SEED, 4, NULL), DEM_ERR_INVALID);
    assert_int_equal(dem_gsd_sample(&ok, SEED, 0, NULL), DEM_OK);
}


// ------------------------------------------------------------ measured tables

// Mean and standard deviation of a normal truncated to [a, b] (the textbook
// formulae), for the ln d of a log-normal cut where a table starts and ends.
static void truncated_normal_moments(double a, double b, double *mean, double *sd)
{
    double z = gsl_cdf_ugaussian_P(b) - gsl_cdf_ugaussian_P(a);
    double pa = gsl_ran_ugaussian_pdf(a), pb = gsl_ran_ugaussian_pdf(b);
    *mean = (pa - pb) / z;
    *sd = sqrt(1.0 + (a * pa - b * pb) / z - *mean * *mean);
}

// A table of `rows` sizes evenly spaced in ln d over median·σg^[lo, hi],
// with the log-normal's cumulative percentage, renormalised to 0..100 over
// that range (a measured table covers the sizes present).
static void lognormal_table(double median, double sigma_g, double lo, double hi, int rows, double *d, double *pct)
{
    const double s = log(sigma_g), cut_lo = gsl_cdf_ugaussian_P(lo), cut_hi = gsl_cdf_ugaussian_P(hi);
    for (int i = 0; i < rows; i++) {
        double z = lo + (hi - lo) * i / (rows - 1);
        d[i] = median * exp(s * z);
        pct[i] = 100.0 * (gsl_cdf_ugaussian_P(z) - cut_lo) / (cut_hi - cut_lo);
    }
    pct[0] = 0.0, pct[rows - 1] = 100.0;
}

// Sample median and standard deviation of ln d.
static void ln_statistics(const dem_gsd *g, size_t n, double *median, double *mean, double *sd)
{
    double *d = draw(g, SEED, n), sum = 0.0, sum2 = 0.0;
    for (size_t i = 0; i < n; i++) sum += log(d[i]);
    *mean = sum / n;
    for (size_t i = 0; i < n; i++) sum2 += (log(d[i]) - *mean) * (log(d[i]) - *mean);
    *sd = sqrt(sum2 / (n - 1));
    qsort(d, n, sizeof *d, cmp_double);
    *median = 0.5 * (d[n / 2 - 1] + d[n / 2]);
    free(d);
}

enum { TABLE_ROWS = 161 };

// Sampling error of a median of ln d (sqrt(pi/2) s / sqrt(N)) and of a
// standard deviation (s / sqrt(2N)), with 4 of them as the tolerance; the
// table's own discretisation (classes 0.05 s wide) is far below.
static double median_tolerance(double s) { return 4.0 * sqrt(DEM_PI / 2.0) * s / sqrt(N_DRAWS); }
static double sd_tolerance(double s) { return 4.0 * s / sqrt(2.0 * N_DRAWS); }

static void test_number_table_is_its_lognormal(void **state)
{
    (void)state;
    double d[TABLE_ROWS], pct[TABLE_ROWS];
    const double s = log(1.43);
    lognormal_table(200e-6, 1.43, -4.0, 4.0, TABLE_ROWS, d, pct);
    dem_gsd g;
    int row = 0;
    char msg[256];
    assert_int_equal(dem_gsd_from_table(d, pct, TABLE_ROWS, DEM_GSD_NUMBER, &g, &row, msg, sizeof msg), 0);
    assert_int_equal(dem_gsd_check(&g, msg, sizeof msg), 0);
    double median, mean, sd, want_mean, want_sd;
    ln_statistics(&g, N_DRAWS, &median, &mean, &sd);
    truncated_normal_moments(-4.0, 4.0, &want_mean, &want_sd);
    print_message("number table: median %.6g (table %.6g, want 200e-6), sd of ln d %.6g (want %.6g), geometric sd "
                  "%.5g (table %.5g)\n", median, g.median_diameter, sd, s * want_sd, exp(sd), g.geometric_sd);
    assert_true(fabs(log(median / 200e-6)) < median_tolerance(s));
    assert_true(fabs(log(g.median_diameter / 200e-6)) < median_tolerance(s));
    assert_true(fabs(sd - s * want_sd) < sd_tolerance(s));
    assert_true(fabs(log(g.geometric_sd) - s * want_sd) < sd_tolerance(s));
    assert_true(dem_gsd_min_diameter(&g) == d[0] && dem_gsd_max_diameter(&g) == d[TABLE_ROWS - 1]);
}

// Laser diffraction reports volume. The volume distribution of a log-normal
// number distribution (median d_n, σg) is log-normal with the same σg and
// median d_v = d_n exp(3 ln²σg) (Hatch-Choate); converting a volume table
// written from it must give back d_n and σg.
static void test_volume_table_hatch_choate(void **state)
{
    (void)state;
    const double sigma_g = 1.43, s = log(sigma_g), d_n = 200e-6, d_v = d_n * exp(3.0 * s * s);
    double d[TABLE_ROWS], pct[TABLE_ROWS];
    lognormal_table(d_v, sigma_g, -5.0, 5.0, TABLE_ROWS, d, pct);
    dem_gsd g;
    int row = 0;
    char msg[256];
    assert_int_equal(dem_gsd_from_table(d, pct, TABLE_ROWS, DEM_GSD_VOLUME, &g, &row, msg, sizeof msg), 0);
    double median, mean, sd, want_mean, want_sd;
    ln_statistics(&g, N_DRAWS, &median, &mean, &sd);
    // In the number distribution's own z the volume table's ±5 spans 3s ∓ 5.
    truncated_normal_moments(3.0 * s - 5.0, 3.0 * s + 5.0, &want_mean, &want_sd);
    print_message("volume table (d_v %.5g m): number median %.6g (table %.6g, Hatch-Choate %.6g), sd of ln d %.6g "
                  "(want %.6g)\n", d_v, median, g.median_diameter, d_n, sd, s * want_sd);
    assert_true(fabs(log(median / d_n)) < median_tolerance(s));
    assert_true(fabs(log(g.median_diameter / d_n)) < median_tolerance(s));
    assert_true(fabs(sd - s * want_sd) < sd_tolerance(s));
    // Read as a number table instead, its median would be d_v: 47 % larger.
    dem_gsd wrong;
    assert_int_equal(dem_gsd_from_table(d, pct, TABLE_ROWS, DEM_GSD_NUMBER, &wrong, &row, msg, sizeof msg), 0);
    assert_true(fabs(log(wrong.median_diameter / d_v)) < median_tolerance(s));
}

// The table's mean volume (exact for its classes) against Monte Carlo of its
// own draws, the same draws for the same seed, and coarse graining scaling
// every row by λ^(1/3).
static void test_table_volume_scaling_determinism(void **state)
{
    (void)state;
    double d[TABLE_ROWS], pct[TABLE_ROWS];
    lognormal_table(293.6e-6, 1.43, -3.0, 3.0, TABLE_ROWS, d, pct);
    dem_gsd g;
    int row = 0;
    char msg[256];
    assert_int_equal(dem_gsd_from_table(d, pct, TABLE_ROWS, DEM_GSD_VOLUME, &g, &row, msg, sizeof msg), 0);
    double *a = draw(&g, SEED, N_DRAWS), *b = draw(&g, SEED, N_DRAWS / 2), sum = 0.0;
    for (size_t i = 0; i < N_DRAWS; i++) sum += DEM_PI / 6.0 * a[i] * a[i] * a[i];
    assert_memory_equal(a, b, (N_DRAWS / 2) * sizeof *a);
    for (size_t i = 0; i < N_DRAWS; i++) assert_true(a[i] >= d[0] && a[i] <= d[TABLE_ROWS - 1]);
    assert_rel(dem_gsd_mean_volume(&g), sum / N_DRAWS, 0.01, "table mean volume vs Monte Carlo");
    dem_gsd big = dem_scale_gsd(&g, 27.0);
    assert_rel(dem_gsd_min_diameter(&big), 3.0 * d[0], 1e-14, "scaled smallest row x3");
    assert_rel(big.median_diameter, 3.0 * g.median_diameter, 1e-14, "scaled median x3");
    assert_rel(dem_gsd_mean_volume(&big), 27.0 * dem_gsd_mean_volume(&g), 1e-12, "scaled mean volume x27");
    assert_true(dem_gsd_table_fingerprint(&g) != 0 && dem_gsd_table_fingerprint(&big) != dem_gsd_table_fingerprint(&g));
    dem_gsd lognormal = dem_default_gsd();
    assert_true(dem_gsd_table_fingerprint(&lognormal) == 0);
    free(a), free(b);
}

// Classes for a deck's insertion: fractions sum to 1 and the classes carry
// the distribution's mean volume, for a log-normal and for a table (its own
// classes, and merged into fewer).
static void expect_classes(const dem_gsd *g, int max, int want_n)
{
    double d[64], p[64], sum = 0.0, volume = 0.0;
    int n = dem_gsd_classes(g, max, d, p);
    assert_int_equal(n, want_n);
    for (int k = 0; k < n; k++) {
        sum += p[k], volume += p[k] * DEM_PI / 6.0 * d[k] * d[k] * d[k];
        assert_true(d[k] >= dem_gsd_min_diameter(g) && d[k] <= dem_gsd_max_diameter(g));
        if (k) assert_true(d[k] > d[k - 1]);
    }
    assert_rel(sum, 1.0, 1e-12, "class fractions sum to 1");
    assert_rel(volume, dem_gsd_mean_volume(g), 1e-9, "classes carry the mean volume");
}

static void test_classes(void **state)
{
    (void)state;
    dem_gsd lognormal = dem_default_gsd();
    expect_classes(&lognormal, 12, 12);
    double d[40], pct[40];
    lognormal_table(293.6e-6, 1.43, -3.0, 3.0, 40, d, pct);
    dem_gsd g;
    int row;
    char msg[256];
    assert_int_equal(dem_gsd_from_table(d, pct, 40, DEM_GSD_VOLUME, &g, &row, msg, sizeof msg), 0);
    expect_classes(&g, 64, 39);
    expect_classes(&g, 10, 10);
    assert_int_equal(dem_gsd_classes(&g, 0, d, pct), 0);
}

// A table `rows` long with one value replaced must be refused at that row,
// naming the field.
static void expect_bad_row(int rows, int at, double size_um, double percent, int want_row, const char *field)
{
    double d[4] = {100e-6, 200e-6, 300e-6, 400e-6}, pct[4] = {0, 40, 80, 100};
    if (at >= 0) {
        if (!isnan(size_um)) d[at] = size_um * 1e-6;
        if (!isnan(percent)) pct[at] = percent;
    }
    dem_gsd g;
    int row = 99;
    char msg[256] = "";
    assert_int_not_equal(dem_gsd_from_table(d, pct, rows, DEM_GSD_VOLUME, &g, &row, msg, sizeof msg), 0);
    print_message("rejected (row %d): %s\n", row, msg);
    assert_int_equal(row, want_row);
    assert_non_null(strstr(msg, field));
}

static void test_bad_tables(void **state)
{
    (void)state;
    expect_bad_row(4, 2, NAN, 30, 2, "cumulative_percent");   // decreasing
    expect_bad_row(4, 2, NAN, 120, 2, "cumulative_percent");  // above 100
    expect_bad_row(4, 1, NAN, -1, 1, "cumulative_percent");   // below 0
    expect_bad_row(4, 0, NAN, 5, 0, "cumulative_percent");    // not starting at 0
    expect_bad_row(4, 3, NAN, 99, 3, "cumulative_percent");   // not ending at 100
    expect_bad_row(4, 2, 150, NAN, 2, "size");                // not increasing
    expect_bad_row(4, 0, -100, NAN, 0, "size");               // not positive
    expect_bad_row(4, 1, INFINITY, NAN, 1, "size");
    expect_bad_row(1, -1, NAN, NAN, -1, "rows");              // one row
}

static const char *write_temp(const char *text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/test_gsd_table_%d.csv", (int)getpid());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

// The CSV file: read with comments, and its errors named by file, line and field.
static void test_table_file(void **state)
{
    (void)state;
    dem_gsd g;
    char err[512];
    const char *path = write_temp("# laser diffraction, by volume\nsize_um,cumulative_percent\n100,0\n\n200,40\n"
                                  "300,80\n400,100\n");
    assert_int_equal(exp_gsd_table_load(path, "volume", &g, err, sizeof err), 0);
    assert_int_equal(g.table.rows, 4);
    assert_rel(dem_gsd_max_diameter(&g), 400e-6, 1e-14, "last row in m");
    struct { const char *text, *basis, *want; } bad[] = {
        {"size_um,cumulative_percent\n100,0\n200,40\n300,30\n400,100\n", "volume", ":4: cumulative_percent: 30 is below"},
        {"size_um,cumulative_percent\n100,0\n200,x\n400,100\n", "volume", ":3: cumulative_percent: 'x'"},
        {"size_um,cumulative_percent\n100,0\n200,40,1\n400,100\n", "volume", ":3: row: expected 2 fields"},
        {"# c\nsize,percent\n100,0\n400,100\n", "volume", ":2: header: expected size_um,cumulative_percent"},
        {"size_um,cumulative_percent\n100,0\n", "volume", ": rows: 1 given"},
        {"size_um,cumulative_percent\n100,0\n400,100\n", "mass", "gsd_basis: 'mass'"},
        // The CSV grammar (exp_csv, libcsv): a stray quote, a quote left open at the end of its line.
        {"size_um,cumulative_percent\n100,0\n2\"00,40\n400,100\n", "volume", ":3: row: malformed CSV"},
        {"size_um,cumulative_percent\n100,0\n\"200,40\n400,100\n", "volume", ":3: row: unterminated quoted field"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
        path = write_temp(bad[k].text);
        err[0] = '\0';
        assert_int_not_equal(exp_gsd_table_load(path, bad[k].basis, &g, err, sizeof err), 0);
        print_message("rejected: %s\n", err);
        assert_non_null(strstr(err, bad[k].want));
    }
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_is_paper),   cmocka_unit_test(test_sample_median),
        cmocka_unit_test(test_sample_geometric_sd), cmocka_unit_test(test_draws_inside_bounds),
        cmocka_unit_test(test_determinism),        cmocka_unit_test(test_mean_volume),
        cmocka_unit_test(test_monodisperse),       cmocka_unit_test(test_count_for_volume),
        cmocka_unit_test(test_bad_parameters),
        cmocka_unit_test(test_number_table_is_its_lognormal), cmocka_unit_test(test_volume_table_hatch_choate),
        cmocka_unit_test(test_table_volume_scaling_determinism), cmocka_unit_test(test_bad_tables),
        cmocka_unit_test(test_table_file), cmocka_unit_test(test_classes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
