// SPDX-License-Identifier: MIT
// A calibration's progress and time left (see cal_progress.h).
#include "cal_progress.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const kind_name[CAL_RUN_KINDS] = {"cylinder", "drum", "map-tier drum", "level-2 map drum",
                                                      "level-3 map drum"};

cal_run_kind cal_progress_drum_kind(int level)
{
    if (level <= 0) return CAL_RUN_DRUM;
    return (cal_run_kind)(CAL_RUN_MAP_DRUM + (level <= CAL_MAX_MAP_DEPTH ? level : CAL_MAX_MAP_DEPTH) - 1);
}

void cal_progress_level_name(const char *stage, int level, char *out, size_t len)
{
    if (level <= 0) snprintf(out, len, "%s", stage);
    else if (level == 1) snprintf(out, len, "%.50s (map)", stage);
    else snprintf(out, len, "%.50s (map %d)", stage, level);
}

void cal_progress_init(cal_progress *p, int parallel)
{
    memset(p, 0, sizeof *p);
    p->current = -1;
    p->parallel = parallel > 0 ? parallel : 1;
}

int cal_progress_plan(cal_progress *p, const char *name, cal_run_kind kind, int planned)
{
    if (!p) return 0;
    if (p->n_stages == CAL_PROGRESS_MAX_STAGES) return 1;
    cal_progress_stage *s = &p->stage[p->n_stages++];
    snprintf(s->name, sizeof s->name, "%s", name);
    s->kind = kind, s->planned = s->expected = planned > 0 ? planned : 0, s->done = 0;
    return 0;
}

int cal_progress_expect(cal_progress *p, const char *name, int expected)
{
    if (!p) return 0;
    for (int k = 0; k < p->n_stages; ++k)
        if (strcmp(p->stage[k].name, name) == 0) {
            cal_progress_stage *s = &p->stage[k];
            s->expected = expected < 0 ? 0 : expected > s->planned ? s->planned : expected;
            return 0;
        }
    return 1;
}

int cal_progress_enter(cal_progress *p, const char *name)
{
    if (!p) return 0;
    for (int k = 0; k < p->n_stages; ++k)
        if (strcmp(p->stage[k].name, name) == 0) return p->current = k, 0;
    return 1;
}

void cal_progress_count(cal_progress *p, cal_run_kind kind, double wall_s)
{
    if (!p || p->current < 0) return;
    p->stage[p->current].done++;
    if (isfinite(wall_s) && wall_s >= 0) p->cost_sum[kind] += wall_s, p->cost_n[kind]++;
}

// Simulations stage k may still run (a search that ran past its plan has none left).
static int left_in(const cal_progress *p, int k)
{
    int left = p->stage[k].planned - p->stage[k].done;
    return left > 0 ? left : 0;
}

// Simulations stage k runs still if it runs its expected count.
static int expected_left_in(const cal_progress *p, int k)
{
    int left = p->stage[k].expected - p->stage[k].done;
    return left > 0 ? left : 0;
}

// The stages' `left` simulations at their kinds' measured costs, shared by those run at once.
static double time_left(const cal_progress *p, int (*left_of)(const cal_progress *, int))
{
    if (!p || p->n_stages == 0) return NAN;
    double seconds = 0;
    for (int k = p->current < 0 ? 0 : p->current; k < p->n_stages; ++k) {
        int left = left_of(p, k);
        cal_run_kind kind = p->stage[k].kind;
        if (left == 0) continue;
        if (p->cost_n[kind] == 0) return NAN;
        seconds += left * p->cost_sum[kind] / p->cost_n[kind];
    }
    return seconds / p->parallel;
}

double cal_progress_eta_s(const cal_progress *p) { return time_left(p, left_in); }

double cal_progress_expected_eta_s(const cal_progress *p) { return time_left(p, expected_left_in); }

// The first kind still to run without a cost, for "time left after the first ... run".
static const char *uncosted_kind(const cal_progress *p)
{
    for (int k = p->current < 0 ? 0 : p->current; k < p->n_stages; ++k)
        if (left_in(p, k) > 0 && p->cost_n[p->stage[k].kind] == 0) return kind_name[p->stage[k].kind];
    return "";
}

void cal_progress_format_duration(double s, char *out, size_t len)
{
    if (s < 90) snprintf(out, len, "%.0f s", s);
    else if (s < 5400) snprintf(out, len, "%.0f min", s / 60);
    else snprintf(out, len, "%.1f h", s / 3600);
}

void cal_progress_describe(const cal_progress *p, char *out, size_t len)
{
    if (len) out[0] = '\0';
    if (!p || p->n_stages == 0 || len == 0) return;
    int done = 0, planned = 0;
    for (int k = 0; k < p->n_stages; ++k) done += p->stage[k].done, planned += p->stage[k].planned;
    if (planned < done) planned = done;
    int at = p->current < 0 ? 0 : p->current;
    char left[96];
    double eta = cal_progress_eta_s(p), expected = cal_progress_expected_eta_s(p);
    if (isfinite(eta)) {
        char d[32], e[32];
        cal_progress_format_duration(eta, d, sizeof d), cal_progress_format_duration(expected, e, sizeof e);
        // The expected time beside the bound only where they differ as printed.
        if (isfinite(expected) && strcmp(d, e) != 0) snprintf(left, sizeof left, "~%s left expected, ≤ %s", e, d);
        else snprintf(left, sizeof left, "≤ %s left", d);
    } else snprintf(left, sizeof left, "time left after the first %s run", uncosted_kind(p));
    snprintf(out, len, "step %d of %d (%s), %d of ≤ %d simulations, %s", at + 1, p->n_stages, p->stage[at].name, done,
             planned, left);
}
