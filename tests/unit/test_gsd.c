// SPDX-License-Identifier: MIT
// Truncated log-normal GSD (engine/dem_gsd.c) against independent results:
// sample statistics against the truncated-normal formulae, the analytic mean
// volume against quadrature and Monte Carlo, determinism, and bad input.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_randist.h>

#include "dem_gsd.h"
#include "dem_world.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

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
    return M_PI / 6.0 * moment / (gsl_cdf_ugaussian_P(t) - gsl_cdf_ugaussian_P(-t));
}

static void test_mean_volume(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    double *d = draw(&g, SEED, N_DRAWS);
    double sum = 0.0;
    for (size_t i = 0; i < N_DRAWS; i++) sum += M_PI / 6.0 * d[i] * d[i] * d[i];
    double mc = sum / N_DRAWS, analytic = dem_gsd_mean_volume(&g), quad = quadrature_mean_volume(&g);
    print_message("mean volume: analytic %.8g, quadrature %.8g, Monte Carlo %.8g m^3 (median sphere %.8g)\n",
                  analytic, quad, mc, M_PI / 6.0 * pow(200e-6, 3));
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
    assert_rel(dem_gsd_mean_volume(&g), M_PI / 6.0 * 1e-9, 1e-14, "monodisperse mean volume");
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_is_paper),   cmocka_unit_test(test_sample_median),
        cmocka_unit_test(test_sample_geometric_sd), cmocka_unit_test(test_draws_inside_bounds),
        cmocka_unit_test(test_determinism),        cmocka_unit_test(test_mean_volume),
        cmocka_unit_test(test_monodisperse),       cmocka_unit_test(test_count_for_volume),
        cmocka_unit_test(test_bad_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
