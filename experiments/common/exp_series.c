// SPDX-License-Identifier: MIT
// Output analysis of a run's time series (exp_series.h): MSER-m truncation
// and batch-means standard errors.
#include "exp_series.h"

#include <math.h>
#include <stdlib.h>

double exp_series_mean(const double *x, int from, int to)
{
    double s = 0;
    for (int i = from; i < to; ++i) s += x[i];
    return s / (to - from);
}

// The sum of squared deviations of z[from..to) from their own mean (two
// passes: an angle of ~35° varies by tenths).
static double squared_deviations(const double *z, int from, int to)
{
    const double mean = exp_series_mean(z, from, to);
    double ss = 0;
    for (int j = from; j < to; ++j) ss += (z[j] - mean) * (z[j] - mean);
    return ss;
}

// MSER's statistic for cutting the first d of k batch means.
static double mser_statistic(const double *z, int k, int d)
{
    return squared_deviations(z, d, k) / ((double)(k - d) * (k - d));
}

int exp_series_mser_start(const double *x, int n, int m, int *at_limit)
{
    if (at_limit) *at_limit = 0;
    const int k = m > 0 ? n / m : 0;
    if (k < 4) return -1;
    double *z = malloc((size_t)k * sizeof *z);
    if (!z) return -1;
    for (int j = 0; j < k; ++j) z[j] = exp_series_mean(x, j * m, (j + 1) * m);
    const int limit = k / 2;
    int best = 0;
    double best_stat = mser_statistic(z, k, 0);
    for (int d = 1; d <= limit; ++d) {
        const double stat = mser_statistic(z, k, d);
        if (stat < best_stat) best = d, best_stat = stat;
    }
    free(z);
    if (at_limit) *at_limit = best == limit;
    return best * m;
}

double exp_series_batch_se(const double *x, int n, int k)
{
    if (k < 2 || n < k) return NAN;
    double *z = malloc((size_t)k * sizeof *z);
    if (!z) return NAN;
    const int b = n / k, skip = n % k;
    for (int j = 0; j < k; ++j) z[j] = exp_series_mean(x, skip + j * b, skip + (j + 1) * b);
    const double var = squared_deviations(z, 0, k) / (k - 1); // the batch means' sample variance
    free(z);
    return sqrt(var / k);
}
