// SPDX-License-Identifier: MIT
// Coarse-graining laws (engine/dem_scaling.c) against the identities of
// eq. 15–18 and the paper's worked case λ = 27.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "dem_contact.h"
#include "dem_gsd.h"
#include "dem_scaling.h"
#include "dem_vec.h"

static const double LAMBDAS[] = {8.0, 27.0, 64.0, 125.0};
enum { N_LAMBDAS = sizeof LAMBDAS / sizeof LAMBDAS[0] };
static const double R_REAL = 100e-6, RHO_REAL = 1800.0, K_REAL = 1.5e3;
// A few ulps: each identity below is two or three roundings apart.
static const double ROUNDOFF = 8 * 2.220446049250313e-16;

static void assert_rel(double got, double want, double rel, const char *what)
{
    double err = fabs(got - want) / fabs(want);
    if (!(err <= rel)) {
        print_error("%s: got %.17g, want %.17g, relative error %.3g > %.3g\n", what, got, want, err, rel);
        fail();
    }
}

static double sphere_mass(double r, double rho) { return rho * 4.0 / 3.0 * DEM_PI * r * r * r; }

static void test_mass_conserved(void **state)
{
    (void)state;
    for (int i = 0; i < N_LAMBDAS; i++) {
        double l = LAMBDAS[i];
        double r = dem_scale_radius(R_REAL, l), rho = dem_scale_density(RHO_REAL, l);
        // Eq. 16: ρ^s V^s = ρ^r V^r.
        assert_rel(sphere_mass(r, rho), sphere_mass(R_REAL, RHO_REAL), ROUNDOFF, "mass");
    }
}

static void test_radius_ratio_cubed_is_lambda(void **state)
{
    (void)state;
    for (int i = 0; i < N_LAMBDAS; i++) {
        double ratio = dem_scale_radius(R_REAL, LAMBDAS[i]) / R_REAL;
        assert_rel(ratio * ratio * ratio, LAMBDAS[i], ROUNDOFF, "(R^s/R^r)^3"); // eq. 15
        assert_rel(RHO_REAL / dem_scale_density(RHO_REAL, LAMBDAS[i]), LAMBDAS[i], ROUNDOFF, "rho^r/rho^s"); // eq. 17
    }
}

static void test_stiffness_inverse_to_radius(void **state)
{
    (void)state;
    for (int i = 0; i < N_LAMBDAS; i++) {
        double l = LAMBDAS[i];
        double ks = dem_scale_stiffness(K_REAL, l), rs = dem_scale_radius(R_REAL, l);
        assert_rel(ks / K_REAL, R_REAL / rs, ROUNDOFF, "k^s/k^r vs R^r/R^s"); // eq. 18
        // Why eq. 18: under one force F the overlap is F/k, and its ratio to
        // the radius, the relative overlap of Fig. 2, is the same.
        const double force = 1e-3;
        assert_rel((force / ks) / rs, (force / K_REAL) / R_REAL, ROUNDOFF, "h/R under a fixed force");
    }
}

static void test_paper_lambda_27(void **state)
{
    (void)state;
    // λ = 27: radius × 3, density / 27, stiffness / 3.
    assert_rel(dem_scale_radius(R_REAL, 27.0), 3.0 * R_REAL, ROUNDOFF, "radius x3");
    assert_rel(dem_scale_density(RHO_REAL, 27.0), RHO_REAL / 27.0, ROUNDOFF, "density /27");
    assert_rel(dem_scale_stiffness(K_REAL, 27.0), K_REAL / 3.0, ROUNDOFF, "stiffness /3");
    // λ = 1 is the real system, exactly.
    assert_true(dem_scale_radius(R_REAL, 1.0) == R_REAL);
    assert_true(dem_scale_density(RHO_REAL, 1.0) == RHO_REAL);
    assert_true(dem_scale_stiffness(K_REAL, 1.0) == K_REAL);
}

static void test_scale_contact(void **state)
{
    (void)state;
    dem_contact_params p = {.k_n = 1e3, .k_s = 2e3, .k_r = 3e3, .xi = 0.7, .mu_s = 0.5, .mu_r = 0.3,
                            .damping = DEM_DAMPING_SEPARATING};
    dem_contact_params s = dem_scale_contact(&p, 27.0);
    assert_rel(s.k_n, p.k_n / 3.0, ROUNDOFF, "k_n / 3");
    assert_rel(s.k_s, p.k_s / 3.0, ROUNDOFF, "k_s / 3");
    assert_rel(s.k_r, p.k_r / 3.0, ROUNDOFF, "k_r / 3");
    assert_true(s.xi == p.xi && s.mu_s == p.mu_s && s.mu_r == p.mu_r);
    assert_int_equal(s.damping, p.damping);
}

static void test_scale_gsd(void **state)
{
    (void)state;
    dem_gsd g = dem_default_gsd();
    dem_gsd s = dem_scale_gsd(&g, 27.0);
    assert_rel(s.median_diameter, 600e-6, ROUNDOFF, "median x3");
    assert_true(s.geometric_sd == g.geometric_sd && s.truncation_sigmas == g.truncation_sigmas);
    // Each granule's volume × λ, so a volume needs λ times fewer granules.
    assert_rel(dem_gsd_mean_volume(&s), 27.0 * dem_gsd_mean_volume(&g), 1e-12, "mean volume x27");
    assert_rel(dem_gsd_min_diameter(&s), 3.0 * dem_gsd_min_diameter(&g), ROUNDOFF, "min diameter x3");
    double v = 27000.0 * dem_gsd_mean_volume(&g);
    assert_int_equal(dem_gsd_count_for_volume(&g, v), 27000);
    assert_int_equal(dem_gsd_count_for_volume(&s, v), 1000);
}

static void expect_bad_lambda(double lambda)
{
    char msg[256] = "";
    assert_int_not_equal(dem_scale_check(lambda, msg, sizeof msg), 0);
    print_message("rejected: %s\n", msg);
    assert_non_null(strstr(msg, "lambda"));
    assert_true(isnan(dem_scale_radius(R_REAL, lambda)));
    assert_true(isnan(dem_scale_density(RHO_REAL, lambda)));
    assert_true(isnan(dem_scale_stiffness(K_REAL, lambda)));
    dem_contact_params p = {.k_n = 1e3, .k_s = 1e3, .k_r = 1e3, .xi = 0.7, .mu_s = 0.5, .mu_r = 0.3};
    dem_contact_params s = dem_scale_contact(&p, lambda);
    assert_true(isnan(s.k_n) && isnan(s.k_s) && isnan(s.k_r));
    dem_gsd g = dem_default_gsd(), sg = dem_scale_gsd(&g, lambda);
    assert_int_not_equal(dem_gsd_check(&sg, NULL, 0), 0);
}

static void test_bad_lambda(void **state)
{
    (void)state;
    expect_bad_lambda(0.5);
    expect_bad_lambda(0.0);
    expect_bad_lambda(-27.0);
    expect_bad_lambda(NAN);
    expect_bad_lambda(INFINITY);
    char msg[64];
    assert_int_equal(dem_scale_check(1.0, msg, sizeof msg), 0);
    assert_int_equal(dem_scale_check(27.0, NULL, 0), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mass_conserved),   cmocka_unit_test(test_radius_ratio_cubed_is_lambda),
        cmocka_unit_test(test_stiffness_inverse_to_radius), cmocka_unit_test(test_paper_lambda_27),
        cmocka_unit_test(test_scale_contact),    cmocka_unit_test(test_scale_gsd),
        cmocka_unit_test(test_bad_lambda),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
