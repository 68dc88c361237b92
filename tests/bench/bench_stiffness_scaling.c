// SPDX-License-Identifier: MIT
// Stage 1 across λ (not a test): the coordination number of each committed
// stiffness study against k·λ^(1/3), on one plot. If the knee of CN(k)
// moved as λ^(−1/3) (eq. 15-18 keep the relative overlap under a given
// force; results/stiffness_low_k/README.md) the curves' knees would line up.
// Each study is read by stage 1 itself (cal_stage_stiffness) from its own
// store, which must hold every bed: nothing is simulated here.
// Usage: build/tests/bench_stiffness_scaling OUT_PREFIX STUDY_DIR...   (from the source root)
//   STUDY_DIR: a results folder with calibration.yaml (tier standard) and store/.
//   Writes OUT_PREFIX_cn.png (CN against k·λ^(1/3)) and OUT_PREFIX_rise.png
//   (CN less each curve's stiff limit: the levels of different beds differ).
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cal_case_runs.h"
#include "cal_stages.h"
#include "exp_plot.h"

enum { MAX_STUDIES = 8 };

typedef struct study {
    char label[160];
    double lambda;
    cal_stiffness_result s;
    double x[CAL_MAX_K], rise[CAL_MAX_K];
} study;

// 0 if the store holds every bed of stage 1 at tier t (so stage 1 runs nothing).
static int store_complete(const char *store, const cal_config *c, const cal_tier *t)
{
    unsigned n;
    const double *k = cal_tier_stiffness(c, t, &n);
    for (unsigned i = 0; i < n; ++i)
        for (int j = 0; j < t->seeds; ++j) {
            cal_bed_case b = cal_bed_case_make(c, t, k[i], (uint64_t)(c->seed + j));
            char key[2048], err[512];
            cal_bed_key(&b, key, sizeof key);
            cal_record r;
            int got = cal_store_get(store, key, &r, err, sizeof err);
            if (got == 0) cal_record_free(&r);
            if (got != 0)
                return fprintf(stderr, "%s: no record of k_n = %g N/m, seed %d%s%s\n", store, k[i], c->seed + j,
                               got < 0 ? ": " : " (run the study's command first)", got < 0 ? err : ""), 1;
        }
    return 0;
}

static int read_study(const char *dir, study *out)
{
    char path[1100], err[1024];
    snprintf(path, sizeof path, "%s/calibration.yaml", dir);
    cal_config *c = cal_config_load(path, "standard", err, sizeof err);
    if (!c) return fprintf(stderr, "%s\n", err), 1;
    const cal_tier *t = cal_config_tier(c);
    cal_env env;
    memset(&env, 0, sizeof env);
    snprintf(env.store, sizeof env.store, "%s/store", dir);
    env.workers = 1;
    int bad = store_complete(env.store, c, t) || cal_stage_stiffness(&env, c, t, &out->s, err, sizeof err);
    if (bad && err[0]) fprintf(stderr, "%s: %s\n", dir, err);
    if (!bad && env.simulations_run != 0) bad = fprintf(stderr, "%s: stage 1 ran simulations\n", dir) > 0;
    int drum = cal_tier_stiffness_on_drum(t);
    out->lambda = drum ? t->lambda : t->cylinder_lambda;
    int granules = out->s.granules[out->s.n - 1];
    snprintf(out->label, sizeof out->label, "%s λ %g (~%d granules): rule chooses %g N/m%s", drum ? "drum bed" : "cylinder",
             out->lambda, granules, out->s.chosen_k, out->s.resolved ? "" : " (not resolved)");
    cal_config_free(c);
    return bad;
}

static void print_study(const char *dir, study *d)
{
    const cal_stiffness_result *s = &d->s;
    printf("\n%s: %s; tolerance %.4f (%s)\n", dir, d->label, s->tolerance, s->tolerance_rule);
    printf("%10s %14s %10s %8s %14s %9s\n", "k_n (N/m)", "k·λ^(1/3)", "CN mean", "CN sd", "CN - stiffest", "granules");
    for (int i = 0; i < s->n; ++i) {
        d->x[i] = s->k[i] * cbrt(d->lambda), d->rise[i] = s->cn_mean[i] - s->stiff_limit;
        printf("%10g %14.1f %10.4f %8.4f %14.4f %9d\n", s->k[i], d->x[i], s->cn_mean[i], s->cn_sd[i], d->rise[i],
               s->granules[i]);
    }
}

static int plot(const char *path, const char *title, const char *ylabel, study *d, int n, int rise)
{
    exp_plot_series series[MAX_STUDIES];
    static const exp_plot_marker marks[] = {EXP_MARK_CIRCLE, EXP_MARK_SQUARE, EXP_MARK_TRIANGLE, EXP_MARK_DIAMOND};
    for (int k = 0; k < n; ++k) {
        series[k] = (exp_plot_series){.n = (size_t)d[k].s.n, .x = d[k].x, .y = rise ? d[k].rise : d[k].s.cn_mean,
                                      .err = d[k].s.cn_sd, .label = d[k].label, .style = EXP_PLOT_LINE_POINTS,
                                      .marker = marks[k % 4]};
        exp_plot_colour(k, series[k].rgb);
    }
    exp_plot_axes axes = {.title = title, .xlabel = "k_n · λ^(1/3) (N/m; real k_n)", .ylabel = ylabel, .log_x = 1};
    char err[512];
    if (exp_plot_png(path, &axes, (size_t)n, series, 1000, 640, err, sizeof err)) return fprintf(stderr, "%s\n", err), 1;
    printf("wrote %s\n", path);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc - 2 > MAX_STUDIES)
        return fprintf(stderr, "usage: %s OUT_PREFIX STUDY_DIR... (at most %d)\n", argv[0], MAX_STUDIES), 2;
    static study d[MAX_STUDIES];
    int n = argc - 2;
    for (int k = 0; k < n; ++k) {
        if (read_study(argv[k + 2], &d[k])) return 1;
        print_study(argv[k + 2], &d[k]);
    }
    char cn[1100], rise[1100];
    snprintf(cn, sizeof cn, "%s_cn.png", argv[1]), snprintf(rise, sizeof rise, "%s_rise.png", argv[1]);
    return plot(cn, "Stage 1 across λ: the knees line up only if they move as λ^(-1/3)",
                "coordination number (2C/N, granule–granule)", d, n, 0) ||
           plot(rise, "Stage 1 across λ: CN above each curve's stiffest candidate",
                "CN − CN(stiffest k_n)  (bars: seed sd)", d, n, 1);
}
