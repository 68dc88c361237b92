// SPDX-License-Identifier: MIT
/// @file exp_series.h
/// Output analysis of one run's time series (a drum's angle or CSA, sampled
/// at a fixed interval): where its start-up transient ends, and how well its
/// mean is known. Both are the textbook methods of steady-state simulation
/// output analysis, chosen because they need no model of the series:
/// - MSER-m (White 1997; White, Cobb & Spratt 2000): average the series in
///   batches of m samples, Z_1..Z_k, and cut the first d batches where
///   d minimises  sum_{j>d} (Z_j - mean_{j>d} Z)^2 / (k - d)^2,
///   the squared standard error of the truncated mean as if its batches
///   were independent: a transient still in the series raises it, cutting
///   too much raises it through the fewer batches left. d is searched over
///   the first half only; a minimum at that limit means the run is still in
///   its transient (too short to say).
/// - Non-overlapping batch means: the standard error of the mean of a
///   correlated series is the spread of the means of k equal batches over
///   sqrt(k), valid when a batch is much longer than the series' correlation
///   time (an avalanche cycle of the bed, ~1 s at 4 rpm).
#ifndef EXP_SERIES_H
#define EXP_SERIES_H

/// MSER-m over x[0..n): the first sample of the steady part (a multiple of
/// m), or -1 when n < 4 m (too few batches to compare). *at_limit (may be
/// NULL) is set to 1 when the minimum lies at the search's limit (half the
/// batches): the transient may go on beyond it.
int exp_series_mser_start(const double *x, int n, int m, int *at_limit);

/// The batch-means standard error of the mean of x[0..n) with k equal
/// batches of n / k samples, the first n % k samples left out (the oldest:
/// nearest the transient). NaN when k < 2 or n < k.
double exp_series_batch_se(const double *x, int n, int k);

/// The mean of x[from..to).
double exp_series_mean(const double *x, int from, int to);

#endif
