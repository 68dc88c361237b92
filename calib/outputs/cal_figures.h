// SPDX-License-Identifier: MIT
/// @file cal_figures.h
/// The calibration's figures, drawn by experiments/plot/exp_plot from a stage's
/// results: what each shows (the chosen value marked, the data with their
/// spread, every series named) is decided here, how it is drawn there. Each
/// takes `stamp`, what the run is (cal_run_stamp: tier, λ, lab or synthetic
/// data, calibration or demonstration), drawn above its title; NULL: none.
#ifndef CAL_FIGURES_H
#define CAL_FIGURES_H

#include <stddef.h>

#include "cal_config.h"
#include "cal_posterior.h"
#include "cal_stages.h"

/// Stage 1 (Fig. 12): `dir`/cn_vs_k.png, the coordination number against k_n
/// on a log axis, the seed spread as error bars, the stiff limit and the
/// tolerance below it, the chosen k starred. 0 on success, else 1 with a message.
int cal_figure_stiffness(const char *dir, const cal_stiffness_result *s, const char *stamp, char *err, size_t len);

/// A friction stage (Fig. 13, 16, 17, 19), named by its material ("granule"
/// for granule–granule): `dir`/angle_map_<stage>.png (the angle filled over
/// (μs, log μr) with the target's band and every candidate),
/// convergence_<stage>.png (the objective against the evaluation) and
/// csa_vs_rpm_<stage>.png (the data with their spread and the best
/// candidates). `bounds` is the search's rectangle. 0 on success, else 1.
int cal_figures_friction(const char *dir, const cal_bounds *bounds, const cal_friction_result *r, const char *stamp,
                         char *err, size_t len);

/// A friction stage's posterior (cal_posterior.h) as a corner plot:
/// `dir`/posterior_<stage>.png, the samples of (μs, μr) over the search's
/// bounds, each median and 95 % credible interval, the search's choice
/// starred. 0 on success, else 1 with a message.
int cal_figure_posterior(const char *dir, const cal_bounds *bounds, const cal_friction_result *r,
                         const cal_posterior *p, const char *stamp, char *err, size_t len);

/// The x axis of a CSA-against-speed figure of n_series series at the n
/// speeds rpm[]: [lo, hi] (the speeds and 5 % each side; one speed: ±2 rpm
/// around it), `step`, the fraction of the axis between series drawn side by
/// side at a speed so that their error bars stay apart (0 for one series),
/// and widest_shift, the largest shift in rpm (cal_figures_dodge).
typedef struct cal_speed_axis {
    double lo, hi, step, widest_shift;
} cal_speed_axis;
cal_speed_axis cal_figures_speed_axis(int n, const double *rpm, int n_series);

/// Series k's shift at each speed, in fractions of the axis: 0, -step, +step,
/// -2 step, ... (the first series, the data, in the middle).
double cal_figures_dodge(int k, double step);

#endif
