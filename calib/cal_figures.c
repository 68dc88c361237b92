// SPDX-License-Identifier: MIT
// The calibration's figures (see cal_figures.h).
#include "cal_figures.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "exp_plot.h"

enum { WIDTH = 1000, HEIGHT = 640, MAP_WIDTH = 1000, MAP_HEIGHT = 760, MAX_SHOWN = 5 };
static const double DODGE = 0.012; // of the x axis: the CSA series side by side at each speed

static const double black[3] = {0, 0, 0}, grey[3] = {0.55, 0.55, 0.55}, red[3] = {0.84, 0.10, 0.11},
                    blue[3] = {0.12, 0.40, 0.75};

static exp_plot_series points(size_t n, const double *x, const double *y, const char *label, const double rgb[3],
                              exp_plot_marker marker)
{
    return (exp_plot_series){.n = n, .x = x, .y = y, .label = label, .rgb = {rgb[0], rgb[1], rgb[2]},
                             .style = EXP_PLOT_POINTS, .marker = marker};
}

static exp_plot_series level(const double *y, const char *label, const double rgb[3], int dashed)
{
    return (exp_plot_series){.n = 1, .x = y, .y = y, .label = label, .rgb = {rgb[0], rgb[1], rgb[2]},
                             .dashed = dashed, .style = EXP_PLOT_HLINE};
}

// ---- stage 1 ----------------------------------------------------------------------

int cal_figure_stiffness(const char *dir, const cal_stiffness_result *s, char *err, size_t len)
{
    char path[1200], chosen_label[128];
    snprintf(path, sizeof path, "%s/cn_vs_k.png", dir);
    double chosen_k[1] = {s->chosen_k}, chosen_cn[1] = {NAN};
    for (int i = 0; i < s->n; ++i)
        if (s->k[i] == s->chosen_k) chosen_cn[0] = s->cn_mean[i];
    // An unresolved sweep chooses nothing: the calibration goes on with the config's k_n.
    if (s->resolved) snprintf(chosen_label, sizeof chosen_label, "chosen k_n = %.4g N/m", s->chosen_k);
    else snprintf(chosen_label, sizeof chosen_label, "k_n = %.4g N/m: within the noise already (not resolved)", s->chosen_k);
    double limit[1] = {s->stiff_limit}, lower[1] = {s->stiff_limit - s->tolerance},
           upper[1] = {s->stiff_limit + s->tolerance};
    exp_plot_series series[5];
    series[0] = (exp_plot_series){.n = (size_t)s->n, .x = s->k, .y = s->cn_mean, .err = s->cn_sd,
                                  .label = "mean over seeds (bars: seed-to-seed sd)",
                                  .rgb = {blue[0], blue[1], blue[2]},
                                  .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_CIRCLE};
    series[1] = level(limit, "stiff limit (CN of the stiffest k_n)", grey, 0);
    series[2] = level(lower, "stiff limit ± tolerance", grey, 1);
    series[3] = level(upper, NULL, grey, 1);
    series[4] = points(1, chosen_k, chosen_cn, chosen_label, red, s->resolved ? EXP_MARK_STAR : EXP_MARK_OPEN_CIRCLE);
    char title[96];
    snprintf(title, sizeof title, "Stage 1: coordination number of the %s (Fig. 12)", s->scene ? s->scene : "poured cylinder");
    exp_plot_axes axes = {.title = title,
                          .xlabel = "granule stiffness k_n (N/m, real powder)",
                          .ylabel = "coordination number (granule–granule)", .log_x = 1};
    return exp_plot_png(path, &axes, 5, series, WIDTH, HEIGHT, err, len);
}

// ---- friction stages ---------------------------------------------------------------

static const char *stage_name(const cal_friction_result *r)
{
    return r->material[0] ? r->material : "granule";
}

static int angle_map(const char *dir, const cal_bounds *b, const cal_friction_result *r, char *err, size_t len)
{
    double *mu_s = malloc(sizeof(double) * CAL_MAX_EVALS * 3);
    if (!mu_s) return snprintf(err, len, "out of memory for the angle map"), 1;
    double *mu_r = mu_s + CAL_MAX_EVALS, *angle = mu_r + CAL_MAX_EVALS;
    for (int i = 0; i < r->n; ++i)
        mu_s[i] = r->cand[i].mu_s, mu_r[i] = r->cand[i].mu_r, angle[i] = r->cand[i].angle_deg;
    char path[1200], title[160], band[96], evaluated[64], chosen[96] = "";
    snprintf(path, sizeof path, "%s/angle_map_%s.png", dir, stage_name(r));
    snprintf(title, sizeof title, "%s: dynamic angle of repose at %g rpm (Fig. %s)", stage_name(r), r->angle_rpm,
             r->material[0] ? "17" : "13");
    snprintf(band, sizeof band, "target angle %.1f° ± %.1f° (data)", r->angle_target, r->angle_tolerance);
    snprintf(evaluated, sizeof evaluated, "evaluated candidates (%d)", r->n);
    if (r->best >= 0)
        snprintf(chosen, sizeof chosen, "chosen: μs = %.3g, μr = %.3g", r->cand[r->best].mu_s, r->cand[r->best].mu_r);
    exp_plot_map m = {.title = title, .xlabel = "sliding friction μs", .ylabel = "rolling friction μr",
                      .zlabel = "angle (°)", .n = (size_t)r->n, .x = mu_s, .y = mu_r, .z = angle,
                      .xlo = b->mu_s_min, .xhi = b->mu_s_max, .ylo = b->mu_r_min, .yhi = b->mu_r_max, .log_y = 1,
                      .band_lo = r->angle_target - r->angle_tolerance, .band_hi = r->angle_target + r->angle_tolerance,
                      .band_label = band, .points_label = evaluated, .chosen = r->best, .chosen_label = chosen};
    int rc = exp_plot_map_png(path, &m, MAP_WIDTH, MAP_HEIGHT, err, len);
    free(mu_s);
    return rc;
}

// The objective of every candidate in evaluation order (those matching the
// angle apart from the others, and apart from both a two-tier stage's map
// candidates, which this tier did not run and which are never chosen), the best
// so far among this tier's runs, and the chosen one.
typedef struct convergence_data {
    double index[CAL_MAX_EVALS], matching[CAL_MAX_EVALS], outside[CAL_MAX_EVALS], mapped[CAL_MAX_EVALS];
    double step_x[2 * CAL_MAX_EVALS], step_best[2 * CAL_MAX_EVALS]; ///< the best so far as a staircase
    double chosen_index[1], chosen_objective[1];
} convergence_data;

static void convergence_collect(const cal_friction_result *r, convergence_data *d)
{
    double running = HUGE_VAL;
    for (int i = 0; i < r->n; ++i) {
        const cal_candidate *k = &r->cand[i];
        int matches = k->angle_violation <= 0;
        d->index[i] = i + 1;
        d->mapped[i] = k->predicted ? k->objective : NAN;
        d->matching[i] = !k->predicted && matches ? k->objective : NAN;
        d->outside[i] = !k->predicted && !matches ? k->objective : NAN;
        if (!k->predicted && (r->angle_in_misfit || matches)) running = fmin(running, k->objective);
        d->step_x[2 * i] = i + 1, d->step_x[2 * i + 1] = i + 2; // holds until the next evaluation
        d->step_best[2 * i] = d->step_best[2 * i + 1] = isfinite(running) ? running : NAN;
    }
    d->chosen_index[0] = r->best + 1;
    d->chosen_objective[0] = r->best >= 0 ? r->cand[r->best].objective : NAN;
}

static int convergence(const char *dir, const cal_friction_result *r, char *err, size_t len)
{
    convergence_data *d = malloc(sizeof *d);
    if (!d) return snprintf(err, len, "out of memory for the convergence plot"), 1;
    convergence_collect(r, d);
    char path[1200], title[96];
    snprintf(path, sizeof path, "%s/convergence_%s.png", dir, stage_name(r));
    int mapped = 0;
    for (int i = 0; i < r->n; ++i) mapped += r->cand[i].predicted;
    if (mapped)
        snprintf(title, sizeof title, "%s: search convergence (%d runs, %d map candidates)", stage_name(r),
                 r->n - mapped, mapped);
    else snprintf(title, sizeof title, "%s: search convergence (%d evaluations)", stage_name(r), r->n);
    size_t n = (size_t)r->n;
    exp_plot_series s[5] = {
        points(n, d->index, d->matching, "candidate matching the angle", blue, EXP_MARK_CIRCLE),
        points(n, d->index, d->outside, "candidate outside the angle's tolerance", grey, EXP_MARK_OPEN_CIRCLE),
        {.n = 2 * n - (n > 0), .x = d->step_x, .y = d->step_best, .rgb = {black[0], black[1], black[2]},
         .label = r->angle_in_misfit ? "best so far" : "best matching the angle so far"},
        points(1, d->chosen_index, d->chosen_objective, "chosen", red, EXP_MARK_STAR),
        points(n, d->index, d->mapped, "map tier + measured correction (not run here, never chosen)", grey,
               EXP_MARK_CROSS),
    };
    exp_plot_axes axes = {.title = title, .xlabel = "evaluation",
                          .ylabel = r->angle_in_misfit ? "objective: angle and CSA misfit (mean squared z)"
                                                       : "objective: CSA misfit (mean squared z)",
                          .log_y = 1};
    if (r->best < 0) s[3] = s[4]; // no chosen point to draw
    int rc = exp_plot_png(path, &axes, (r->best >= 0 ? 4 : 3) + (mapped > 0), s, WIDTH, HEIGHT, err, len);
    free(d);
    return rc;
}

// The candidates drawn beside the chosen one, at most `max`, the lowest
// objective first: those the data cannot tell from the best (by χ²), else
// those matching the angle.
static int best_others(const cal_friction_result *r, int *shown, int max)
{
    int n = 0, any_identified = 0;
    for (int i = 0; i < r->n; ++i) any_identified |= r->cand[i].identified && i != r->best;
    for (int i = 0; i < r->n; ++i) {
        const cal_candidate *k = &r->cand[i];
        if (i == r->best || !(any_identified ? k->identified : k->angle_violation <= 0)) continue;
        if (n == max && k->objective >= r->cand[shown[max - 1]].objective) continue;
        int at = n < max ? n++ : max - 1; // insertion into the sorted list, the worst dropped
        while (at > 0 && r->cand[shown[at - 1]].objective > k->objective) shown[at] = shown[at - 1], at--;
        shown[at] = i;
    }
    return n;
}

static int csa_vs_rpm(const char *dir, const cal_friction_result *r, char *err, size_t len)
{
    static char labels[MAX_SHOWN + 1][96];
    exp_plot_series s[MAX_SHOWN + 2];
    size_t n_rpm = (size_t)r->n_rpm, ns = 0;
    s[ns++] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = r->csa_data, .err = r->csa_data_sd,
                                .label = "data (bars: sd)", .rgb = {0, 0, 0}, .style = EXP_PLOT_POINTS,
                                .marker = EXP_MARK_SQUARE};
    int shown[MAX_SHOWN], others = best_others(r, shown, MAX_SHOWN - 1);
    // Every series at the same speeds: each drawn a little aside, the data in the middle.
    if (r->best >= 0) {
        const cal_candidate *k = &r->cand[r->best];
        snprintf(labels[0], sizeof labels[0], "chosen: μs = %.3g, μr = %.3g", k->mu_s, k->mu_r);
        s[ns++] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = k->csa, .err = k->csa_sd, .label = labels[0],
                                    .rgb = {red[0], red[1], red[2]}, .style = EXP_PLOT_LINE_POINTS,
                                    .marker = EXP_MARK_STAR, .dodge = -DODGE};
    }
    for (int j = 0; j < others; ++j) {
        const cal_candidate *k = &r->cand[shown[j]];
        snprintf(labels[j + 1], sizeof labels[j + 1], "μs = %.3g, μr = %.3g (%s)", k->mu_s, k->mu_r,
                 k->identified ? "not told apart" : "matches the angle");
        s[ns] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = k->csa, .err = k->csa_sd, .label = labels[j + 1],
                                  .dashed = 1, .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_CIRCLE,
                                  .dodge = DODGE * (j + 1)};
        exp_plot_colour(j + 2, s[ns++].rgb); // palette 0 and 1 are blue and red: the data and the chosen
    }
    char path[1200], title[160];
    snprintf(path, sizeof path, "%s/csa_vs_rpm_%s.png", dir, stage_name(r));
    snprintf(title, sizeof title, "%s: occupied cross-section area (Fig. %s)", stage_name(r),
             r->material[0] ? "19" : "16");
    exp_plot_axes axes = {.title = title, .xlabel = "drum speed (rpm)", .ylabel = "CSA (%)"};
    return exp_plot_png(path, &axes, ns, s, WIDTH, HEIGHT, err, len);
}

int cal_figures_friction(const char *dir, const cal_bounds *bounds, const cal_friction_result *r, char *err, size_t len)
{
    return angle_map(dir, bounds, r, err, len) || convergence(dir, r, err, len) || csa_vs_rpm(dir, r, err, len);
}
