// SPDX-License-Identifier: MIT
// `granucal simulate drum.yaml`: fill, turn to a steady state, measure. See
// exp_drum_runner.h.
#include "exp_drum_runner.h"

#include <math.h>
#include <stdio.h>
#include <unistd.h>

#include "dem_checkpoint.h"
#include "exp_common.h"
#include "exp_drum_turn.h"
#include "exp_image.h"
#include "exp_result.h"

typedef struct progress_state {
    int tty;
    double last_wall, start;
} progress_state;

static void show_progress(const char *phase, double t, size_t granules, void *ctx)
{
    progress_state *p = ctx;
    double now = exp_wall_seconds();
    if (now - p->last_wall < (p->tty ? 0.5 : 10.0)) return;
    p->last_wall = now;
    fprintf(stderr, p->tty ? "\r%-6s t = %6.3f s  granules %zu  wall %6.0f s   " : "%s t = %.3f s granules %zu wall %.0f s\n",
            phase, t, granules, now - p->start);
}

// What result.json says of one turn (exp_result_json_fn's ctx).
typedef struct drum_report {
    const exp_drum_yaml *y;
    const exp_drum_result *r;
    const dem_world *w;
    const char *status;
} drum_report;

static void write_json(FILE *f, const void *ctx)
{
    const drum_report *rep = ctx;
    const exp_drum_yaml *y = rep->y;
    const exp_drum_result *r = rep->r;
    char effects[1024], margin[32];
    dem_world_describe_features(rep->w, effects, sizeof effects);
    snprintf(margin, sizeof margin, isnan(r->dt_margin_min) ? "null" : "%.4f", r->dt_margin_min); // JSON has no NaN
    fprintf(f,
            "{\"experiment\": \"drum\", \"status\": \"%s\", \"rpm\": %g, \"wall\": \"%s\", \"mu_s\": %g, \"mu_r\": %g, "
            "\"k_n\": %g, \"lambda\": %g, \"seed\": %d, \"angle_deg\": %.4f, \"angle_sd_deg\": %.4f, "
            "\"csa_percent\": %.4f, \"csa_sd_percent\": %.4f, \"surface_fit_sd_m\": %.4g, \"steady\": %s, "
            "\"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"granules\": %zu, \"particle_steps\": %llu, "
            "\"dt_s\": %.6g, \"dt_margin_min\": %s, \"dt_lowered\": %d, \"start_tilt_deg\": %g, \"effects\": \"%s\"}\n",
            rep->status, y->rpm, y->wall, y->mu_s, y->mu_r, y->k_n, y->lambda, y->seed, r->angle_deg, r->angle_sd_deg,
            r->csa_percent, r->csa_sd_percent, r->fit_sd_m, r->steady ? "true" : "false", r->simulated_time_s,
            r->wall_time_s, r->granules, r->particle_steps, dem_world_dt(rep->w), margin, r->dt_lowered,
            r->start_tilt_deg, effects);
}

static int save(const char *dir, const drum_report *rep)
{
    char path[1200], err[1024];
    int bad = exp_result_write_h5(dir, rep->w, err, sizeof err);
    // The drum face at the end of the run (like the paper's Fig. 14), by size.
    snprintf(path, sizeof path, "%s/drum_face.png", dir);
    if (!bad) bad = exp_render_drum_png(path, rep->w, 0.5 * rep->y->diameter, 800, EXP_COLOUR_SIZE, err, sizeof err);
    if (!bad) bad = exp_result_write_json(dir, write_json, rep, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

// One speed's turn: where its results go, and how it runs.
typedef struct drum_turn_job {
    const exp_drum_def *def;
    exp_drum_run_opts run;
    const exp_drum_simulate_opts *o;
    const char *dir;
    int sweep;   ///< several speeds: results in DIR/rpm_<rpm>/
    progress_state *p;
} drum_turn_job;

// Turn one copy of the settled bed at `rpm`; its JSON on stdout (after ", "
// unless `first`).
static int turn_copy(dem_world *bed, exp_drum_yaml *y, const drum_turn_job *j, double rpm, int first)
{
    char sub[1100], err[1024];
    if (j->sweep) snprintf(sub, sizeof sub, "%s/rpm_%g", j->dir, rpm);
    else snprintf(sub, sizeof sub, "%s", j->dir);
    if (exp_mkdirs(sub, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_drum_run_opts run = j->run;
    run.rpm = y->rpm = rpm;
    char key[2048] = "", ck_path[1200];
    if (j->o->key) j->o->key(j->def, &run, key, sizeof key);
    snprintf(ck_path, sizeof ck_path, "%s/checkpoint.h5", sub);
    const exp_drum_turn turn = {.def = j->def, .run = run, .checkpoint_path = ck_path, .key = key,
                                .checkpoint_every_s = j->o->key ? j->o->checkpoint_every_s : 0,
                                .progress = show_progress, .progress_ctx = j->p, .progress_line_open = j->p->tty,
                                .log_prefix = "granucal simulate:"};
    exp_drum_result r;
    dem_status st;
    dem_world *w = exp_drum_turn_bed(bed, 0, &turn, &r, &st);
    if (!w) return fprintf(stderr, "granucal simulate: out of memory copying the bed\n"), 1;
    const drum_report rep = {y, &r, w, st != DEM_OK ? "failed" : r.steady ? "ok" : "not steady"};
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: %g rpm: %s\n", rpm, dem_world_error(w));
    int bad = save(sub, &rep);
    if (!bad) dem_checkpoint_remove(ck_path); // result.json holds the result now
    if (!first) fputs(", ", stdout);
    write_json(stdout, &rep);
    dem_world_destroy(w);
    return bad || st != DEM_OK;
}

int exp_drum_simulate(const exp_drum_yaml *config, const char *out_dir, const exp_drum_simulate_opts *o)
{
    char err[1024], dir[1024];
    exp_drum_yaml y = *config; // its rpm is each turn's in turn
    const double *rpms = o->n_rpm > 0 ? o->rpm : &config->rpm;
    int n_rpm = o->n_rpm > 0 ? o->n_rpm : 1;
    exp_drum_def def;
    exp_drum_run_opts run;
    exp_drum_config_defs(&y, &def, &run, err, sizeof err);
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/drum");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    progress_state p = {isatty(2), 0, exp_wall_seconds()};
    dem_world *bed = exp_drum_fill(&def, show_progress, &p, err, sizeof err);
    if (!bed) return fprintf(stderr, "\ngranucal simulate: %s\n", err), 1;
    fprintf(stderr, "%sgranucal simulate: bed of %zu granules settled after %.2f s; %s\n", p.tty ? "\n" : "",
            dem_world_granules(bed).count, dem_world_time(bed), dem_world_dt_report(bed));
    const drum_turn_job job = {&def, run, o, dir, n_rpm > 1, &p};
    int bad = 0;
    if (n_rpm > 1) fputs("{\"experiment\": \"drum speed sweep\", \"runs\": [", stdout);
    for (int k = 0; k < n_rpm; ++k) bad |= turn_copy(bed, &y, &job, rpms[k], k == 0);
    if (n_rpm > 1) fputs("]}\n", stdout);
    dem_world_destroy(bed);
    return bad;
}
