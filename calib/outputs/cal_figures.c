// SPDX-License-Identifier: MIT
// The calibration's figures (see cal_figures.h).
#include "cal_figures.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "exp_plot.h"

enum { WIDTH = 1000, HEIGHT = 640, MAP_WIDTH = 1000, MAP_HEIGHT = 760, MAX_SHOWN = 5 };

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

int cal_figure_stiffness(const char *dir, const cal_stiffness_result *s, const char *stamp, char *err, size_t len)
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
    exp_plot_axes axes = {.title = title, .stamp = stamp,
                          .xlabel = "granule stiffness k_n (N/m, real powder)",
                          .ylabel = "coordination number (granule–granule)", .log_x = 1};
    return exp_plot_png(path, &axes, 5, series, WIDTH, HEIGHT, err, len);
}

// ---- friction stages ---------------------------------------------------------------

static const char *stage_name(const cal_friction_result *r)
{
    return r->material[0] ? r->material : "granule";
}

// What the data files are, for a legend: "data (EXTRA)", or where the file
// says its numbers are synthetic "synthetic data (λ 512; EXTRA)".
static void data_label(const cal_provenance *p, const char *extra, char *out, size_t len)
{
    char lambda[48] = "";
    if (p->synthetic && isfinite(p->lambda) && p->lambda > 0) snprintf(lambda, sizeof lambda, "λ %g", p->lambda);
    const char *sep = lambda[0] && extra ? "; " : "";
    if (!lambda[0] && !extra) snprintf(out, len, "%s", p->synthetic ? "synthetic data" : "data");
    else snprintf(out, len, "%s (%s%s%s)", p->synthetic ? "synthetic data" : "data", lambda, sep, extra ? extra : "");
}

static int map_candidates(const cal_friction_result *r)
{
    int n = 0;
    for (int i = 0; i < r->n; ++i) n += r->cand[i].predicted;
    return n;
}

// The legend of a two-tier stage's predicted candidates: the map tier's runs
// corrected, or where the map tier maps with another (levels) its runs and
// its own predictions, corrected.
static void map_legend(const cal_friction_result *r, int n, const char *note, char *out, size_t len)
{
    snprintf(out, len, "map tier '%s' runs%s + measured correction (%d%s)", cal_friction_map_tier(r),
             r->n_levels > 1 ? " and predictions" : "", n, note);
}

static int angle_map(const char *dir, const cal_bounds *b, const cal_friction_result *r, const char *stamp, char *err,
                     size_t len)
{
    double *mu_s = malloc(sizeof(double) * CAL_MAX_EVALS * 3);
    int *predicted = malloc(sizeof(int) * CAL_MAX_EVALS);
    if (!mu_s || !predicted) return free(mu_s), free(predicted), snprintf(err, len, "out of memory for the angle map"), 1;
    double *mu_r = mu_s + CAL_MAX_EVALS, *angle = mu_r + CAL_MAX_EVALS;
    for (int i = 0; i < r->n; ++i)
        mu_s[i] = r->cand[i].mu_s, mu_r[i] = r->cand[i].mu_r, angle[i] = r->cand[i].angle_deg,
        predicted[i] = r->cand[i].predicted;
    int mapped = map_candidates(r);
    char path[1200], title[160], band[160], source[64], evaluated[96], mapped_label[160], chosen[128] = "";
    snprintf(path, sizeof path, "%s/angle_map_%s.png", dir, stage_name(r));
    snprintf(title, sizeof title, "%s: dynamic angle of repose at %g rpm (Fig. %s)", stage_name(r), r->angle_rpm,
             r->material[0] ? "17" : "13");
    data_label(&r->angle_source, NULL, source, sizeof source);
    snprintf(band, sizeof band, "target angle %.1f° ± %.1f°, %s", r->angle_target, r->angle_tolerance, source);
    // A two-tier stage's map candidates are the cheap tier's runs with the
    // correction measured here added: predicted, not evaluated at this tier.
    if (mapped) snprintf(evaluated, sizeof evaluated, "runs at this tier (%d)", r->n - mapped);
    else snprintf(evaluated, sizeof evaluated, "evaluated candidates (%d)", r->n);
    map_legend(r, mapped, "; predicted, not run here", mapped_label, sizeof mapped_label);
    if (r->best >= 0)
        snprintf(chosen, sizeof chosen, "the search's choice: μs = %.3g, μr = %.3g (its status: the table)",
                 r->cand[r->best].mu_s, r->cand[r->best].mu_r);
    exp_plot_map m = {.title = title, .stamp = stamp, .xlabel = "sliding friction μs", .ylabel = "rolling friction μr",
                      .zlabel = mapped ? "angle (°), measured and predicted" : "angle (°)", .n = (size_t)r->n,
                      .x = mu_s, .y = mu_r, .z = angle,
                      .xlo = b->mu_s_min, .xhi = b->mu_s_max, .ylo = b->mu_r_min, .yhi = b->mu_r_max, .log_y = 1,
                      .band_lo = r->angle_target - r->angle_tolerance, .band_hi = r->angle_target + r->angle_tolerance,
                      .band_label = band, .points_label = evaluated, .chosen = r->best, .chosen_label = chosen,
                      .predicted = mapped ? predicted : NULL, .predicted_label = mapped_label};
    int rc = exp_plot_map_png(path, &m, MAP_WIDTH, MAP_HEIGHT, err, len);
    free(mu_s), free(predicted);
    return rc;
}

// The objective of this tier's runs in their order, those matching the angle
// apart from the others; the best so far among them as a staircase; the
// chosen one. A two-tier stage's map candidates (the cheap tier's runs plus
// the correction measured here: never run at this tier, never chosen) stand
// apart at run 0 and are not counted as runs.
typedef struct convergence_data {
    double index[CAL_MAX_EVALS], matching[CAL_MAX_EVALS], outside[CAL_MAX_EVALS];
    double map_index[CAL_MAX_EVALS], mapped[CAL_MAX_EVALS];
    double step_x[2 * CAL_MAX_EVALS], step_best[2 * CAL_MAX_EVALS]; ///< the best so far as a staircase
    double chosen_index[1], chosen_objective[1];
    int runs, map_points;
} convergence_data;

static void convergence_collect(const cal_friction_result *r, convergence_data *d)
{
    double running = HUGE_VAL;
    d->runs = d->map_points = 0;
    d->chosen_index[0] = d->chosen_objective[0] = NAN;
    for (int i = 0; i < r->n; ++i) {
        const cal_candidate *k = &r->cand[i];
        if (k->predicted) {
            d->map_index[d->map_points] = 0, d->mapped[d->map_points++] = k->objective;
            continue;
        }
        int j = d->runs++, matches = cal_candidate_angle_matched(k);
        d->index[j] = j + 1;
        d->matching[j] = matches ? k->objective : NAN;
        d->outside[j] = !matches ? k->objective : NAN;
        if (r->angle_in_misfit || matches) running = fmin(running, k->objective);
        d->step_x[2 * j] = j + 1, d->step_x[2 * j + 1] = j + 2; // holds until the next evaluation
        d->step_best[2 * j] = d->step_best[2 * j + 1] = isfinite(running) ? running : NAN;
        if (i == r->best) d->chosen_index[0] = j + 1, d->chosen_objective[0] = k->objective;
    }
    // The last step holds half a run past the last run: seen even when the
    // first candidate matching the angle is the last run.
    if (d->runs > 0) d->step_x[2 * d->runs - 1] = d->runs + 0.5;
}

static int convergence(const char *dir, const cal_friction_result *r, const char *stamp, char *err, size_t len)
{
    convergence_data *d = malloc(sizeof *d);
    if (!d) return snprintf(err, len, "out of memory for the convergence plot"), 1;
    convergence_collect(r, d);
    char path[1200], title[160], map_label[160];
    snprintf(path, sizeof path, "%s/convergence_%s.png", dir, stage_name(r));
    if (d->map_points)
        snprintf(title, sizeof title, "%s: search convergence (%d runs at this tier)", stage_name(r), d->runs);
    else snprintf(title, sizeof title, "%s: search convergence (%d evaluations)", stage_name(r), d->runs);
    map_legend(r, d->map_points, ", at 0: not run here, never chosen", map_label, sizeof map_label);
    size_t n = (size_t)d->runs, ns = 0;
    exp_plot_series s[5];
    s[ns++] = points(n, d->index, d->matching, "run matching the angle", blue, EXP_MARK_CIRCLE);
    s[ns++] = points(n, d->index, d->outside, "run outside the angle's tolerance", grey, EXP_MARK_OPEN_CIRCLE);
    s[ns++] = (exp_plot_series){.n = 2 * n, .x = d->step_x, .y = d->step_best,
                                .rgb = {black[0], black[1], black[2]},
                                .label = r->angle_in_misfit ? "best so far" : "best matching the angle so far"};
    if (isfinite(d->chosen_index[0]))
        s[ns++] = points(1, d->chosen_index, d->chosen_objective, "the search's choice", red, EXP_MARK_STAR);
    if (d->map_points)
        s[ns++] = points((size_t)d->map_points, d->map_index, d->mapped, map_label, grey, EXP_MARK_OPEN_DIAMOND);
    exp_plot_axes axes = {.title = title, .stamp = stamp,
                          .xlabel = d->map_points ? "run at this tier (0: the map tier's candidates, predicted)" : "evaluation",
                          .ylabel = r->angle_in_misfit ? "angle and CSA misfit (mean squared z)"
                                                       : "CSA misfit (mean squared z)",
                          .log_y = 1};
    int rc = exp_plot_png(path, &axes, ns, s, WIDTH, HEIGHT, err, len);
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
        if (i == r->best || !(any_identified ? k->identified : cal_candidate_angle_matched(k))) continue;
        if (n == max && k->objective >= r->cand[shown[max - 1]].objective) continue;
        int at = n < max ? n++ : max - 1; // insertion into the sorted list, the worst dropped
        while (at > 0 && r->cand[shown[at - 1]].objective > k->objective) shown[at] = shown[at - 1], at--;
        shown[at] = i;
    }
    return n;
}

cal_speed_axis cal_figures_speed_axis(int n, const double *rpm, int n_series)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int j = 0; j < n; ++j) lo = fmin(lo, rpm[j]), hi = fmax(hi, rpm[j]);
    if (!(lo <= hi)) return (cal_speed_axis){0, 1, 0, 0};
    cal_speed_axis a;
    if (hi - lo < 1e-9) // one speed: a narrow axis around it, the series side by side across it
        a = (cal_speed_axis){lo - 2, hi + 2, n_series > 1 ? 0.06 : 0, 0};
    else a = (cal_speed_axis){lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo), n_series > 1 ? 0.004 : 0, 0};
    a.widest_shift = cal_figures_dodge(n_series - 1, a.step) * (a.hi - a.lo);
    if (a.widest_shift < 0) a.widest_shift = -a.widest_shift;
    return a;
}

double cal_figures_dodge(int k, double step)
{
    return (k % 2 ? -1 : 1) * ((k + 1) / 2) * step; // 0, -1, +1, -2, +2, ... steps
}

static int csa_vs_rpm(const char *dir, const cal_friction_result *r, const char *stamp, char *err, size_t len)
{
    static char labels[MAX_SHOWN + 2][128];
    exp_plot_series s[MAX_SHOWN + 2];
    size_t n_rpm = (size_t)r->n_rpm, ns = 0;
    int shown[MAX_SHOWN], others = best_others(r, shown, MAX_SHOWN - 1);
    // One speed: markers alone, nothing to join.
    exp_plot_style style = n_rpm > 1 ? EXP_PLOT_LINE_POINTS : EXP_PLOT_POINTS;
    if (r->best >= 0) {
        const cal_candidate *k = &r->cand[r->best];
        snprintf(labels[1], sizeof labels[1], "the search's choice: μs = %.3g, μr = %.3g (bars: seed sd)", k->mu_s, k->mu_r);
        s[ns++] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = k->csa, .err = k->csa_sd, .label = labels[1],
                                    .rgb = {red[0], red[1], red[2]}, .style = style, .marker = EXP_MARK_STAR};
    }
    for (int j = 0; j < others; ++j) {
        const cal_candidate *k = &r->cand[shown[j]];
        snprintf(labels[j + 2], sizeof labels[j + 2], "μs = %.3g, μr = %.3g (%s%s)", k->mu_s, k->mu_r,
                 k->identified ? "not told apart" : "matches the angle",
                 k->predicted ? "; predicted: map tier + correction" : "");
        s[ns] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = k->csa, .err = k->csa_sd, .label = labels[j + 2],
                                  .dashed = 1, .style = style, .marker = EXP_MARK_CIRCLE};
        exp_plot_colour(j + 2, s[ns++].rgb); // palette 0 and 1 are blue and red: the data and the chosen
    }
    // The data last, over the candidates, and in the middle at each speed (the others a little aside).
    data_label(&r->csa_source, "bars: sd", labels[0], sizeof labels[0]);
    s[ns++] = (exp_plot_series){.n = n_rpm, .x = r->rpm, .y = r->csa_data, .err = r->csa_data_sd,
                                .label = labels[0], .rgb = {0, 0, 0}, .style = EXP_PLOT_POINTS,
                                .marker = EXP_MARK_OPEN_SQUARE};
    cal_speed_axis axis = cal_figures_speed_axis(r->n_rpm, r->rpm, (int)ns);
    for (size_t k = 0; k + 1 < ns; ++k) s[k].dodge = cal_figures_dodge((int)k + 1, axis.step);
    char path[1200], title[160], xlabel[160];
    snprintf(path, sizeof path, "%s/csa_vs_rpm_%s.png", dir, stage_name(r));
    snprintf(title, sizeof title, "%s: occupied cross-section area (Fig. %s)", stage_name(r),
             r->material[0] ? "19" : "16");
    if (n_rpm == 1 && ns > 1)
        snprintf(xlabel, sizeof xlabel, "drum speed (rpm): every series at %g rpm, drawn side by side", r->rpm[0]);
    else if (ns > 1)
        snprintf(xlabel, sizeof xlabel, "drum speed (rpm); the series drawn up to ±%.2g rpm aside to keep their bars apart",
                 axis.widest_shift);
    else snprintf(xlabel, sizeof xlabel, "drum speed (rpm)");
    exp_plot_axes axes = {.title = title, .stamp = stamp, .xlabel = xlabel, .ylabel = "CSA (%)", .xlo = axis.lo,
                          .xhi = axis.hi};
    return exp_plot_png(path, &axes, ns, s, WIDTH, HEIGHT, err, len);
}

int cal_figures_friction(const char *dir, const cal_bounds *bounds, const cal_friction_result *r, const char *stamp,
                         char *err, size_t len)
{
    return angle_map(dir, bounds, r, stamp, err, len) || convergence(dir, r, stamp, err, len) ||
           csa_vs_rpm(dir, r, stamp, err, len);
}

int cal_figure_posterior(const char *dir, const cal_bounds *bounds, const cal_friction_result *r,
                         const cal_posterior *p, const char *stamp, char *err, size_t len)
{
    char path[1200], title[160], note[400];
    snprintf(path, sizeof path, "%s/posterior_%s.png", dir, stage_name(r));
    snprintf(title, sizeof title, "%s: posterior of (μs, μr) given the data", stage_name(r));
    snprintf(note, sizeof note,
             "median [95 %% credible]\nμs %.2g [%.2g, %.2g]\nμr %.2g [%.2g, %.2g]\n%d samples, %d chains\n"
             "solid: median\ndashed: 2.5, 97.5 %%\n★ the search's choice",
             p->median[0], p->lo[0], p->hi[0], p->median[1], p->lo[1], p->hi[1], p->n, CAL_POSTERIOR_CHAINS);
    const cal_candidate *best = r->best >= 0 ? &r->cand[r->best] : NULL;
    exp_plot_corner c = {.title = title, .stamp = stamp, .xlabel = "sliding friction μs", .ylabel = "rolling friction μr",
                         .n = (size_t)p->n, .x = p->mu_s, .y = p->mu_r,
                         .xlo = bounds->mu_s_min, .xhi = bounds->mu_s_max, .ylo = bounds->mu_r_min, .yhi = bounds->mu_r_max,
                         .log_y = 1, .x_median = p->median[0], .x_lo = p->lo[0], .x_hi = p->hi[0],
                         .y_median = p->median[1], .y_lo = p->lo[1], .y_hi = p->hi[1],
                         .chosen_x = best ? best->mu_s : NAN, .chosen_y = best ? best->mu_r : NAN,
                         .chosen_label = "the search's choice", .note = note};
    return exp_plot_corner_png(path, &c, 1000, 760, err, len);
}
