// SPDX-License-Identifier: MIT
// What each level of the calibration buys (issue 37.2; a figure, not a test):
// for committed calibrations decided at different levels (the ci tier alone,
// λ 1000, λ 512), each friction's value, status and 95 % credible interval
// (calibrated_parameters.csv) against the core-hours its simulations took
// (simulations.csv: every record the run used, at the cost it had, turning
// and the bed it settled). Prints one Markdown row per level and friction and
// draws them: core-hours on x, the rolling frictions on a log y (the sliding
// ones sit at or near their bound at every level run so far), a bar for each
// credible interval, the value as a marker, hollow where the data did not
// choose it (one-sided, bounded, not a result, not identified).
// A run that took stage 1 from another run's folder lists none of it: +H adds
// those core-hours, so that every level carries the same stage 1.
//   usage: bench_accuracy_vs_cost OUT.png LABEL=RESULTS_DIR[+H] [LABEL=RESULTS_DIR[+H] ...]
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_csv.h"
#include "exp_plot.h"

enum { MAX_LEVELS = 8, MAX_FRICTIONS = 8 };

// One CSV file read by its header's names (exp_csv): the header, then each row to on_row.
typedef struct csv_rows {
    exp_csv_row header;
    const exp_csv_row *row;
    int header_seen;
    void (*on_row)(struct csv_rows *r, void *ctx);
    void *ctx;
} csv_rows;

static int on_csv_row(const exp_csv_row *row, void *data)
{
    csv_rows *r = data;
    if (!r->header_seen) r->header = *row, r->header_seen = 1;
    else r->row = row, r->on_row(r, r->ctx);
    return 0;
}

static const char *field(const csv_rows *r, const char *name)
{
    int k = exp_csv_column(&r->header, name);
    return k >= 0 && k < r->row->n && k < EXP_CSV_MAX_FIELDS ? r->row->field[k] : "";
}

static int read_csv(const char *path, void (*row)(csv_rows *, void *), void *ctx)
{
    csv_rows *r = calloc(1, sizeof *r);
    if (!r) return 1;
    r->on_row = row, r->ctx = ctx;
    char err[1200];
    int bad = exp_csv_read(path, on_csv_row, NULL, r, err, sizeof err);
    if (bad) fprintf(stderr, "%s\n", err);
    free(r);
    return bad;
}

typedef struct friction {
    char name[64], status[48];
    double value, lo, hi;
} friction;

enum { MAX_RECORDS = 4096 };

typedef struct level {
    char label[64];
    double core_s;
    friction f[MAX_FRICTIONS];
    int n;
    char (*seen)[17]; ///< records counted (a record several stages use, e.g. the walls' shared grid, is listed by each)
    int n_seen;
} level;

static void add_cost(csv_rows *r, void *ctx)
{
    level *l = ctx;
    const char *record = field(r, "record");
    for (int k = 0; k < l->n_seen; ++k)
        if (strcmp(l->seen[k], record) == 0) return;
    if (l->n_seen < MAX_RECORDS) snprintf(l->seen[l->n_seen++], sizeof l->seen[0], "%s", record);
    l->core_s += atof(field(r, "wall_time_s")) + atof(field(r, "fill_wall_time_s"));
}

static void add_friction(csv_rows *r, void *ctx)
{
    level *l = ctx;
    const char *p = field(r, "parameter");
    if (strncmp(p, "mu_", 3) != 0 || l->n == MAX_FRICTIONS) return;
    friction *f = &l->f[l->n++];
    const char *m = field(r, "material");
    snprintf(f->name, sizeof f->name, "%s %s", m[0] ? m : "granule", p);
    snprintf(f->status, sizeof f->status, "%s", field(r, "status"));
    f->value = atof(field(r, "value"));
    f->lo = field(r, "credible_min")[0] ? atof(field(r, "credible_min")) : NAN;
    f->hi = field(r, "credible_max")[0] ? atof(field(r, "credible_max")) : NAN;
}

static int read_level(const char *arg, level *l)
{
    const char *eq = strchr(arg, '=');
    if (!eq) return fprintf(stderr, "'%s': want LABEL=RESULTS_DIR[+CORE_HOURS]\n", arg), 1;
    snprintf(l->label, sizeof l->label, "%.*s", (int)(eq - arg), arg);
    // +H: core-hours the run used but does not list (stage 1 read from another run's folder).
    char dir[1024], path[1200];
    snprintf(dir, sizeof dir, "%s", eq + 1);
    char *plus = strrchr(dir, '+');
    if (plus) l->core_s = 3600 * atof(plus + 1), *plus = 0;
    snprintf(path, sizeof path, "%s/simulations.csv", dir);
    l->seen = calloc(MAX_RECORDS, sizeof *l->seen);
    int bad = !l->seen || read_csv(path, add_cost, l);
    free(l->seen), l->seen = NULL;
    if (bad) return 1;
    snprintf(path, sizeof path, "%s/calibrated_parameters.csv", dir);
    return read_csv(path, add_friction, l);
}

// The rolling frictions against core-hours: per friction, its credible bars
// (a line broken between levels) and its values (filled: chosen by the data).
static int draw(const char *out, const level *lv, int n_levels)
{
    static double x[MAX_FRICTIONS][3 * MAX_LEVELS], y[MAX_FRICTIONS][3 * MAX_LEVELS];
    static double vx[MAX_FRICTIONS][2][MAX_LEVELS], vy[MAX_FRICTIONS][2][MAX_LEVELS];
    exp_plot_series s[3 * MAX_FRICTIONS];
    int n_series = 0;
    for (int k = 0; k < lv[0].n; ++k) {
        if (!strstr(lv[0].f[k].name, "mu_r")) continue;
        size_t nb = 0, nv[2] = {0, 0};
        for (int i = 0; i < n_levels; ++i) {
            if (k >= lv[i].n) continue;
            const friction *f = &lv[i].f[k];
            const double h = lv[i].core_s / 3600;
            x[k][nb] = h, y[k][nb++] = f->lo, x[k][nb] = h, y[k][nb++] = f->hi, x[k][nb] = h, y[k][nb++] = NAN;
            const int chosen = strcmp(f->status, "calibrated") == 0;
            vx[k][chosen][nv[chosen]] = h, vy[k][chosen][nv[chosen]++] = f->value;
        }
        double rgb[3];
        exp_plot_colour(n_series / 3, rgb);
        const double dodge = 0.012 * (n_series / 3);
        s[n_series++] = (exp_plot_series){.n = nb, .x = x[k], .y = y[k], .label = lv[0].f[k].name, .rgb = {rgb[0], rgb[1], rgb[2]},
                                          .style = EXP_PLOT_LINE, .dodge = dodge};
        for (int c = 0; c < 2; ++c)
            s[n_series++] = (exp_plot_series){.n = nv[c], .x = vx[k][c], .y = vy[k][c], .rgb = {rgb[0], rgb[1], rgb[2]},
                                              .style = EXP_PLOT_POINTS,
                                              .marker = c ? EXP_MARK_CIRCLE : EXP_MARK_OPEN_CIRCLE, .dodge = dodge};
    }
    exp_plot_axes a = {.title = "What each level buys: rolling frictions (bar: 95 % credible; filled: calibrated)",
                       .xlabel = "core-hours of the calibration's simulations", .ylabel = "mu_r",
                       .log_y = 1};
    char err[512];
    if (exp_plot_png(out, &a, (size_t)n_series, s, 1000, 650, err, sizeof err)) return fprintf(stderr, "%s\n", err), 1;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc - 2 > MAX_LEVELS)
        return fprintf(stderr, "usage: %s OUT.png LABEL=RESULTS_DIR[+H] [LABEL=RESULTS_DIR[+H] ...] (at most %d)\n", argv[0],
                       MAX_LEVELS),
               2;
    level lv[MAX_LEVELS] = {0};
    for (int i = 0; i < argc - 2; ++i)
        if (read_level(argv[2 + i], &lv[i])) return 1;
    printf("| level | core-hours | friction | value | status | 95 %% credible |\n|---|---:|---|---:|---|---|\n");
    for (int i = 0; i < argc - 2; ++i)
        for (int k = 0; k < lv[i].n; ++k) {
            const friction *f = &lv[i].f[k];
            char credible[64] = "— (no posterior)";
            if (isfinite(f->lo) && isfinite(f->hi)) snprintf(credible, sizeof credible, "%.3g – %.3g", f->lo, f->hi);
            printf("| %s | %.2f | %s | %.4g | %s | %s |\n", lv[i].label, lv[i].core_s / 3600, f->name, f->value, f->status,
                   credible);
        }
    return draw(argv[1], lv, argc - 2);
}
