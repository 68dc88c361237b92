// SPDX-License-Identifier: MIT
// The posterior of a friction stage (calib/search/cal_posterior.c) on maps whose
// posterior is known in closed form: an angle linear in u with a Gaussian
// spread (the posterior of u a Gaussian, of v flat: uniform in log10 μr), and
// the kriging's variance growing away from its runs.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "cal_posterior.h"

static const cal_bounds bounds = {0.1, 1.0, 1e-5, 0.5};

// A stage measuring the angle alone, whose map is angle = 30 + 10 u (u: μs
// over its bounds), target 35 ± 0.5: u* = 0.5 (μs 0.55), σ_u = 0.05.
static cal_friction_result *linear_stage(void)
{
    cal_friction_result *r = calloc(1, sizeof *r);
    r->angle_target = 35, r->angle_tolerance = 0.5, r->angle_rpm = 4;
    r->best = -1, r->has_map = 1;
    r->cheap_map.n_y = 1, r->cheap_map.n_terms = 3;
    r->cheap_map.coef[0][0] = 30, r->cheap_map.coef[0][1] = 10; // 1, u, v
    return r;
}

static void test_a_linear_angle_gives_a_gaussian_in_mu_s_and_a_flat_mu_r(void **state)
{
    (void)state;
    cal_friction_result *r = linear_stage();
    cal_posterior p;
    char err[200];
    assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
    // μs = 0.1 + 0.9 u: median 0.55, 95 % interval 0.55 ± 1.96 × 0.9 × 0.05 = 0.55 ± 0.0882.
    // Monte Carlo error of a quantile with ~12 000 correlated samples: allow 0.01.
    assert_float_equal(p.median[0], 0.55, 0.01);
    assert_float_equal(p.lo[0], 0.55 - 0.0882, 0.01);
    assert_float_equal(p.hi[0], 0.55 + 0.0882, 0.01);
    assert_false(p.reaches_lower[0] || p.reaches_upper[0]);
    // log10 μr uniform over [-5, log10 0.5]: median at its middle, the interval its 2.5 and 97.5 %.
    double a = -5, b = log10(0.5);
    assert_float_equal(log10(p.median[1]), a + 0.5 * (b - a), 0.03 * (b - a));
    assert_float_equal(log10(p.lo[1]), a + 0.025 * (b - a), 0.015 * (b - a));
    assert_float_equal(log10(p.hi[1]), a + 0.975 * (b - a), 0.015 * (b - a));
    assert_true(p.reaches_lower[1] && p.reaches_upper[1]); // a flat posterior runs to both bounds
    // The angle moves 10° = 20 spreads across μs, nothing across μr: μr is blind.
    assert_float_equal(p.sensitivity[0][0], 20, 1e-9);
    assert_float_equal(p.sensitivity[0][1], 0, 1e-9);
    assert_false(cal_posterior_blind(&p, 0));
    assert_true(cal_posterior_blind(&p, 1));
    assert_true(p.acceptance > 0.1 && p.acceptance < 0.7);
    assert_true(p.chain_spread[0] < 0.02);
    cal_posterior_free(&p);
    free(r);
}

static void test_a_target_beyond_the_map_piles_on_the_bound(void **state)
{
    (void)state;
    cal_friction_result *r = linear_stage();
    r->angle_target = 45; // the map reaches 40 at most (u = 1): the posterior presses on μs's upper bound
    cal_posterior p;
    char err[200];
    assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
    assert_true(p.reaches_upper[0] && !p.reaches_lower[0]);
    assert_true(p.median[0] > 0.95);
    cal_posterior_free(&p);
    free(r);
}

static void test_kriging_sd_is_the_nugget_at_a_run_and_the_scale_far_away(void **state)
{
    (void)state;
    // Two runs 0.5 apart (kernel length 0.25), scale 2, nugget 1e-9: at a run the variance is
    // scale² (1 - kᵀK⁻¹k) = 0 up to the nugget; far from both, scale.
    cal_mf_correction c = {0};
    c.n_runs = 2, c.run_u[0] = 0.25, c.run_v[0] = 0.5, c.run_u[1] = 0.75, c.run_v[1] = 0.5;
    c.scale[0] = 2, c.nugget[0][0] = c.nugget[0][1] = 1e-9;
    assert_float_equal(cal_mf_correction_sd(&c, 0, 0.25, 0.5), 0, 1e-3);
    assert_float_equal(cal_mf_correction_sd(&c, 0, 0.5, 5.0), 2, 1e-9);
    // Between the runs: k = exp(-0.25²/(2·0.25²)) = e^-0.5 each; K = [[1, e^-2], [e^-2, 1]]:
    // 1 - 2 e^-1 / (1 + e^-2) = 0.35240, times scale².
    assert_float_equal(cal_mf_correction_sd(&c, 0, 0.5, 0.5), 2 * sqrt(1 - 2 * exp(-1) / (1 + exp(-2))), 1e-6);
    // No kriging: no variance model.
    c.scale[0] = 0;
    assert_float_equal(cal_mf_correction_sd(&c, 0, 0.5, 0.5), 0, 0);
}

// Kriging runs at (u, v) pairs with this scale, no residual weights (the
// correction adds nothing: only its variance model matters here).
static void kriging_at(cal_friction_result *r, const double *u, const double *v, int n, double scale)
{
    memset(&r->discrepancy, 0, sizeof r->discrepancy);
    r->discrepancy.n_runs = n;
    for (int i = 0; i < n; ++i) r->discrepancy.run_u[i] = u[i], r->discrepancy.run_v[i] = v[i];
    r->discrepancy.scale[0] = scale;
    for (int i = 0; i < n; ++i) r->discrepancy.nugget[0][i] = 1e-9;
}

static void a_run_is_asked_only_where_the_map_holds_the_posterior_wide(void **state)
{
    (void)state;
    cal_friction_result *r = linear_stage(); // the angle pins u near 0.5; v is blind
    // The correction measured at two runs far from u = 0.5: there its variance (scale 2, against the angle's
    // spread 0.5) is most of the angle's: a run is wanted, inside the posterior's mass.
    const double far_u[] = {0.05, 0.95}, far_v[] = {0.5, 0.5};
    kriging_at(r, far_u, far_v, 2, 2.0);
    cal_posterior p;
    char err[200];
    assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
    double u = -1, v = -1;
    cal_posterior_need need;
    assert_int_equal(cal_posterior_next_run(r, &bounds, &p, &u, &v, &need), 0);
    assert_int_equal(need.measurement, 0);
    assert_true(need.share >= CAL_POSTERIOR_MAP_SHARE);
    double mu_lo = p.lo[0], mu_hi = p.hi[0];
    double at_mu_s = bounds.mu_s_min + u * (bounds.mu_s_max - bounds.mu_s_min);
    assert_true(at_mu_s > mu_lo - 0.05 && at_mu_s < mu_hi + 0.05);
    cal_posterior_free(&p);
    // Runs along the posterior's ridge u = 0.5, every 0.2 in v, the discrepancy's scale the angle's spread:
    // the kriging's variance is small wherever the posterior lies, the width is the angle's own: no run.
    // (With a scale 4 times the spread, a run 0.05 off the ridge still leaves the kriging a third of the
    // variance there: that map would still hold the posterior wide.)
    const double ridge_u[] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5}, ridge_v[] = {0, 0.2, 0.4, 0.6, 0.8, 1.0};
    kriging_at(r, ridge_u, ridge_v, 6, 0.5);
    assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
    assert_int_equal(cal_posterior_next_run(r, &bounds, &p, &u, &v, &need), 1);
    printf("ridge: the map's share of the angle's variance %.3f\n", need.share);
    assert_int_equal(need.measurement, 0);
    assert_true(need.share < CAL_POSTERIOR_MAP_SHARE);
    cal_posterior_free(&p);
    // A measurement that moves with no parameter the data can tell asks for nothing, however unsure the map.
    r->cheap_map.coef[0][1] = 0.1; // the angle moves 0.2 spreads across μs: blind
    kriging_at(r, far_u, far_v, 2, 2.0);
    assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
    assert_int_equal(cal_posterior_next_run(r, &bounds, &p, &u, &v, &need), 1);
    assert_int_equal(need.measurement, -1);
    cal_posterior_free(&p);
    free(r);
}

// Coverage: with a map that is the truth and data drawn around it with the
// spreads the likelihood uses, a flat prior and a linear map make the
// posterior a Gaussian whose 95 % credible interval is also a 95 %
// confidence interval, marginals included. Angle and CSA both move with μs
// and log μr, in a valley (correlated): over 400 data sets the interval of
// each must cover the truth 380 ± 13 times (three binomial sd), the MCMC's
// own quantile error included. Truth at the square's centre, each posterior
// sd ~0.05 of the range, so the flat prior's edges do not truncate it.
static void test_credible_intervals_cover_the_truth_at_their_level(void **state)
{
    (void)state;
    enum { SETS = 400 };
    cal_friction_result *r = calloc(1, sizeof *r);
    r->angle_tolerance = 0.5, r->angle_rpm = 4, r->best = -1, r->has_map = 1;
    r->n_rpm = 1, r->rpm[0] = 40, r->csa_data_sd[0] = 0.5;
    r->cheap_map.n_y = 2, r->cheap_map.n_terms = 3;                                     // 1, u, v
    r->cheap_map.coef[0][0] = 20, r->cheap_map.coef[0][1] = 12, r->cheap_map.coef[0][2] = 8; // angle
    r->cheap_map.coef[1][0] = 45, r->cheap_map.coef[1][1] = 4, r->cheap_map.coef[1][2] = -6; // CSA
    const double truth_u = 0.5, truth_v = 0.5;
    double angle_sd = cal_friction_angle_spread(r), csa_sd = cal_friction_csa_spread(r, 0);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 35);
    int covered[2] = {0, 0};
    for (int set = 0; set < SETS; ++set) {
        r->angle_target = 20 + 12 * truth_u + 8 * truth_v + gsl_ran_gaussian(rng, angle_sd);
        r->csa_data[0] = 45 + 4 * truth_u - 6 * truth_v + gsl_ran_gaussian(rng, csa_sd);
        cal_posterior p;
        char err[200];
        assert_int_equal(cal_posterior_sample(r, &bounds, &p, err, sizeof err), 0);
        double lo_u, lo_v, hi_u, hi_v;
        cal_friction_to_unit(&bounds, p.lo[0], p.lo[1], &lo_u, &lo_v);
        cal_friction_to_unit(&bounds, p.hi[0], p.hi[1], &hi_u, &hi_v);
        covered[0] += lo_u <= truth_u && truth_u <= hi_u;
        covered[1] += lo_v <= truth_v && truth_v <= hi_v;
        cal_posterior_free(&p);
    }
    gsl_rng_free(rng);
    printf("95 %% credible intervals covering the truth over %d data sets: mu_s %d, log mu_r %d\n", SETS, covered[0],
           covered[1]);
    for (int k = 0; k < 2; ++k) assert_true(covered[k] >= 367 && covered[k] <= 393);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_linear_angle_gives_a_gaussian_in_mu_s_and_a_flat_mu_r),
        cmocka_unit_test(test_a_target_beyond_the_map_piles_on_the_bound),
        cmocka_unit_test(test_kriging_sd_is_the_nugget_at_a_run_and_the_scale_far_away),
        cmocka_unit_test(a_run_is_asked_only_where_the_map_holds_the_posterior_wide),
        cmocka_unit_test(test_credible_intervals_cover_the_truth_at_their_level),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
