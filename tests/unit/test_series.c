// SPDX-License-Identifier: MIT
// Output analysis of a run's series (experiments/common/exp_series.c) against
// analytic results: the batch-means standard error of an AR(1) series against
// its exact variance of the mean, MSER-m against a known exponential
// transient, and a drift that never ends reported as such.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>

#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "exp_series.h"

enum { N = 4000, REPLICAS = 400 };

// x_t = phi x_{t-1} + e_t, e_t ~ N(0, sigma^2), started from its stationary law.
static void ar1(gsl_rng *rng, double phi, double sigma, double *x, int n)
{
    x[0] = gsl_ran_gaussian(rng, sigma / sqrt(1 - phi * phi));
    for (int t = 1; t < n; ++t) x[t] = phi * x[t - 1] + gsl_ran_gaussian(rng, sigma);
}

// The exact variance of the mean of n samples of a stationary AR(1):
// gamma0/n * [1 + 2 sum_{h=1}^{n-1} (1 - h/n) phi^h], gamma0 = sigma^2/(1-phi^2).
static double ar1_variance_of_mean(double phi, double sigma, int n)
{
    double s = 1, p = 1;
    for (int h = 1; h < n; ++h) p *= phi, s += 2 * (1 - (double)h / n) * p;
    return sigma * sigma / (1 - phi * phi) / n * s;
}

// With batches 40 correlation times long (phi 0.8: 1/(1-phi) = 5 samples;
// 20 batches of 200), the batch-means variance of the mean is unbiased to a
// few per cent; 400 replicas pin its average to ~1.6 % (the estimate's own
// relative spread sqrt(2/19) / sqrt(400)). The naive iid formula would be 9x low.
static void batch_se_matches_ar1(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 20261128);
    double *x = malloc(N * sizeof *x), mean_se2 = 0, naive = 0;
    assert_non_null(x);
    for (int r = 0; r < REPLICAS; ++r) {
        ar1(rng, 0.8, 1.0, x, N);
        const double se = exp_series_batch_se(x, N, 20);
        mean_se2 += se * se / REPLICAS;
        naive += exp_series_batch_se(x, N, N) * exp_series_batch_se(x, N, N) / REPLICAS;
    }
    const double exact = ar1_variance_of_mean(0.8, 1.0, N);
    print_message("AR(1) phi 0.8: batch-means var of the mean %.4g, exact %.4g (ratio %.3f); one-sample batches %.4g\n",
                  mean_se2, exact, mean_se2 / exact, naive);
    assert_true(fabs(mean_se2 / exact - 1) < 0.08);
    assert_true(naive < exact / 5); // why batches: the iid formula misses the correlation
    free(x);
    gsl_rng_free(rng);
}

// x_i = A exp(-i / tau) + e_i: A = 5, tau = 200 samples, unit noise. The
// untruncated mean is biased by A tau / N = 0.25, 16 standard errors of one
// run. MSER-5 must cut past the transient's bulk: what it leaves is the
// transient's analytic tail beyond its cut, sum_{i>=d} A e^{-i/tau} / (N - d),
// which must be of the order of one run's standard error: MSER trades the
// last of the transient for samples (here it leaves ~1.8 standard errors of
// a bias that was 15), it does not remove it exactly.
static void mser_cuts_an_exponential_transient(void **state)
{
    (void)state;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 7);
    double *x = malloc(N * sizeof *x), bias_cut = 0, bias_all = 0, start_sum = 0, tail = 0;
    assert_non_null(x);
    int limits = 0;
    enum { R = 100 };
    for (int r = 0; r < R; ++r) {
        for (int i = 0; i < N; ++i) x[i] = 5.0 * exp(-i / 200.0) + gsl_ran_gaussian(rng, 1.0);
        int at_limit;
        const int start = exp_series_mser_start(x, N, 5, &at_limit);
        assert_true(start > 200 && start < N / 2);
        limits += at_limit, start_sum += start;
        tail += 5.0 * exp(-start / 200.0) / (1 - exp(-1 / 200.0)) / (N - start) / R; // the geometric tail's sum
        bias_cut += exp_series_mean(x, start, N) / R, bias_all += exp_series_mean(x, 0, N) / R;
    }
    const double se_one_run = 1.0 / sqrt(N - start_sum / R), se_of_average = 1.0 / sqrt((double)N / 2 * R);
    print_message("MSER-5: mean start %.0f samples; bias %.4f cut (the analytic tail beyond the cuts %.4f), %.4f uncut;"
                  " one run's standard error %.4f\n", start_sum / R, bias_cut, tail, bias_all, se_one_run);
    assert_int_equal(limits, 0);
    assert_true(fabs(bias_all - 0.25) < 0.01);
    assert_true(fabs(bias_cut - tail) < 4 * se_of_average); // what is left is the tail, and noise
    assert_true(tail < 2 * se_one_run && bias_cut < bias_all / 5);
    free(x);
    gsl_rng_free(rng);
}

// A drift through the whole run has no steady part: the statistic falls
// with every batch cut, and the minimum lies at the search's limit.
static void mser_reports_a_drift_at_its_limit(void **state)
{
    (void)state;
    double x[400];
    for (int i = 0; i < 400; ++i) x[i] = 35.0 - 0.01 * i;
    int at_limit = 0;
    assert_int_equal(exp_series_mser_start(x, 400, 5, &at_limit), 200);
    assert_int_equal(at_limit, 1);
}

static void edge_cases(void **state)
{
    (void)state;
    double x[40];
    for (int i = 0; i < 40; ++i) x[i] = 34.5;
    int at_limit = 1;
    assert_int_equal(exp_series_mser_start(x, 40, 5, &at_limit), 0); // constant: nothing to cut
    assert_int_equal(at_limit, 0);
    assert_int_equal(exp_series_mser_start(x, 19, 5, NULL), -1); // under 4 batches
    assert_true(exp_series_batch_se(x, 40, 4) == 0.0);
    assert_true(isnan(exp_series_batch_se(x, 40, 1)));
    assert_true(isnan(exp_series_batch_se(x, 3, 4)));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(batch_se_matches_ar1),
        cmocka_unit_test(mser_cuts_an_exponential_transient),
        cmocka_unit_test(mser_reports_a_drift_at_its_limit),
        cmocka_unit_test(edge_cases),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
