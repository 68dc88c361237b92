// SPDX-License-Identifier: MIT
// The cost model of the plans (cal_plan.h).
#include "cal_plan.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_store.h"

// One stored run: kept if it is a usable drum run under the MSER rule.
static void keep_mser_run(const cal_record *r, void *ctx)
{
    cal_plan_history *h = ctx;
    if (!cal_record_usable(r) || strncmp(r->key, "drum ", 5) != 0 || !strstr(r->key, " steady=mser")) return;
    if (h->n == h->cap) {
        int cap = h->cap ? 2 * h->cap : 64;
        char **kind = realloc(h->kind, (size_t)cap * sizeof *kind);
        if (kind) h->kind = kind;
        char **any_scale = kind ? realloc(h->any_scale, (size_t)cap * sizeof *any_scale) : NULL;
        if (any_scale) h->any_scale = any_scale;
        double *turn_s = any_scale ? realloc(h->turn_s, (size_t)cap * sizeof *turn_s) : NULL;
        if (turn_s) h->turn_s = turn_s;
        if (!turn_s) return; // out of memory: the plan knows one run fewer
        h->cap = cap;
    }
    char text[4096], scale_free[4096];
    cal_drum_key_kind(r->key, 0, text, sizeof text), cal_drum_key_kind(r->key, 1, scale_free, sizeof scale_free);
    h->kind[h->n] = strdup(text), h->any_scale[h->n] = strdup(scale_free);
    if (!h->kind[h->n] || !h->any_scale[h->n]) {
        free(h->kind[h->n]), free(h->any_scale[h->n]);
        return;
    }
    h->turn_s[h->n++] = r->simulated_time_s;
}

int cal_plan_history_read(cal_plan_history *h, const char *store, char *err, size_t len)
{
    memset(h, 0, sizeof *h);
    return cal_store_each(store, keep_mser_run, h, err, len) < 0;
}

void cal_plan_history_free(cal_plan_history *h)
{
    for (int i = 0; i < h->n; ++i) free(h->kind[i]), free(h->any_scale[i]);
    free(h->kind), free(h->any_scale), free(h->turn_s);
    memset(h, 0, sizeof *h);
}

double cal_plan_history_mean(const cal_plan_history *h, const char *kind, int any_scale, int *n)
{
    double sum = 0;
    *n = 0;
    for (int i = 0; h && i < h->n; ++i)
        if (strcmp(any_scale ? h->any_scale[i] : h->kind[i], kind) == 0) sum += h->turn_s[i], ++*n;
    return *n ? sum / *n : NAN;
}

double cal_plan_turn_time(const cal_drum_case *d, double rpm, int worst, const cal_plan_history *history,
                          int *from_store)
{
    exp_drum_run_opts o = cal_drum_run_opts(d, rpm);
    *from_store = 0;
    if (worst) return o.max_time;
    if (o.steady_rule != EXP_STEADY_MSER) return fmin(o.max_time, 2 * o.window + o.average_time);
    // The MSER rule stops when the run's own series says so: only runs of
    // the same kind tell when that tends to be.
    char key[4096], kind[4096];
    cal_drum_key(d, rpm, key, sizeof key);
    for (int any_scale = 0; any_scale < 2; ++any_scale) {
        int n;
        cal_drum_key_kind(key, any_scale, kind, sizeof kind);
        double mean = cal_plan_history_mean(history, kind, any_scale, &n);
        if (n >= CAL_PLAN_HISTORY_MIN) return *from_store = 1 + any_scale, fmin(o.max_time, mean);
    }
    return o.max_time;
}

double cal_plan_makespan(const double *task_s, int n, int parallel)
{
    double longest = 0, total = 0;
    for (int i = 0; i < n; ++i) longest = fmax(longest, task_s[i]), total += task_s[i];
    return fmax(longest, total / (parallel > 0 ? parallel : 1));
}

void cal_plan_turned_beds(cal_plan_cost *cost, const cal_drum_case *d, int beds, int parallel)
{
    const int n = beds * d->n_turned;
    if (n <= 0) return;
    exp_drum_cost unit = exp_drum_predict_cost(&d->start, 1.0);
    const double bed_s = (unit.fill_particle_steps + unit.turn_particle_steps * d->turned_time) / CAL_PLAN_RATE;
    cost->core_s += n * bed_s;
    cost->wall_s += bed_s * ceil((double)n / (parallel > 0 ? parallel : 1));
    cost->memory_mb = fmax(cost->memory_mb, unit.memory_mb);
}

void cal_plan_drum_batch(cal_plan_cost *cost, const cal_drum_case *d, const double *rpm, int n, int m, int beds,
                         int wall_stage, int bed_kept, int parallel, int worst, const cal_plan_history *history)
{
    if (m <= 0 || n <= 0) return;
    exp_drum_cost unit = exp_drum_predict_cost(&d->def, 1.0); // turning steps per simulated second
    double fill_s = unit.fill_particle_steps / CAL_PLAN_RATE, turns_s = 0;
    double *turn_s = calloc((size_t)n, sizeof *turn_s);
    if (!turn_s) return;
    int tasks_per_bed = m * beds, shared_bed = tasks_per_bed == 1 || (wall_stage && beds == 1);
    for (int k = 0; k < n; ++k) {
        int from_store;
        turn_s[k] = unit.turn_particle_steps * cal_plan_turn_time(d, rpm[k], worst, history, &from_store) / CAL_PLAN_RATE;
        turns_s += turn_s[k];
        if (cal_drum_run_opts(d, rpm[k]).steady_rule == EXP_STEADY_MSER) {
            cost->mser_runs += tasks_per_bed;
            if (from_store == 1) cost->mser_from_store += tasks_per_bed;
            if (from_store == 2) cost->mser_from_other_scale += tasks_per_bed;
        }
    }
    int n_tasks = shared_bed ? tasks_per_bed * n : tasks_per_bed;
    double *task = calloc((size_t)n_tasks, sizeof *task);
    if (!task) return free(turn_s);
    for (int i = 0; i < n_tasks; ++i) task[i] = shared_bed ? turn_s[i % n] : fill_s + turns_s;
    double serial_fill = shared_bed && !bed_kept ? fill_s : 0;
    cost->runs += tasks_per_bed * n;
    cost->core_s += serial_fill + (shared_bed ? tasks_per_bed * turns_s : tasks_per_bed * (fill_s + turns_s));
    cost->wall_s += serial_fill + cal_plan_makespan(task, n_tasks, parallel);
    cost->memory_mb = fmax(cost->memory_mb, unit.memory_mb);
    free(task), free(turn_s);
}

void cal_plan_describe(const cal_plan_cost *c, int parallel, char *out, size_t len)
{
    snprintf(out, len, "%.2g core-hours, %.2g h on %d worker(s)", c->core_s / 3600, c->wall_s / 3600, parallel);
}

void cal_plan_describe_mser(const cal_plan_cost *c, const char *store, char *out, size_t len)
{
    snprintf(out, len, "%d of %d MSER runs from %s, %d more from runs of their kind at another λ or k_n",
             c->mser_from_store, c->mser_runs, store, c->mser_from_other_scale);
}

static void add_cost(cal_plan_cost *to, const cal_plan_cost *c)
{
    to->runs += c->runs, to->core_s += c->core_s, to->wall_s += c->wall_s, to->memory_mb = fmax(to->memory_mb, c->memory_mb);
    to->mser_runs += c->mser_runs, to->mser_from_store += c->mser_from_store;
    to->mser_from_other_scale += c->mser_from_other_scale;
}

void cal_plan_add(cal_plan *total, const cal_plan *p)
{
    add_cost(&total->expected, &p->expected), add_cost(&total->worst, &p->worst);
}

void cal_plan_add_runs(cal_plan_cost *total, const cal_plan_cost *c, int runs)
{
    if (runs <= 0 || c->runs <= 0) return;
    total->runs += runs;
    total->core_s += c->core_s * runs / c->runs, total->wall_s += c->wall_s * runs / c->runs;
}
