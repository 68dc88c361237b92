// SPDX-License-Identifier: MIT
// `granucal simulate drum.yaml`: fill, turn to a steady state, measure.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cal_case_runs.h"
#include "cal_commands.h"
#include "cal_files.h"
#include "dem_checkpoint.h"
#include "exp_common.h"
#include "exp_drum_config.h"
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

static void write_json(FILE *f, const exp_drum_yaml *y, const exp_drum_result *r, const dem_world *w, const char *status)
{
    char effects[1024], margin[32];
    dem_world_describe_features(w, effects, sizeof effects);
    snprintf(margin, sizeof margin, isnan(r->dt_margin_min) ? "null" : "%.4f", r->dt_margin_min); // JSON has no NaN
    fprintf(f,
            "{\"experiment\": \"drum\", \"status\": \"%s\", \"rpm\": %g, \"wall\": \"%s\", \"mu_s\": %g, \"mu_r\": %g, "
            "\"k_n\": %g, \"lambda\": %g, \"seed\": %d, \"angle_deg\": %.4f, \"angle_sd_deg\": %.4f, "
            "\"csa_percent\": %.4f, \"csa_sd_percent\": %.4f, \"surface_fit_sd_m\": %.4g, \"steady\": %s, "
            "\"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"granules\": %zu, \"particle_steps\": %llu, "
            "\"dt_s\": %.6g, \"dt_margin_min\": %s, \"dt_lowered\": %d, \"start_tilt_deg\": %g, \"effects\": \"%s\"}\n",
            status, y->rpm, y->wall, y->mu_s, y->mu_r, y->k_n, y->lambda, y->seed, r->angle_deg, r->angle_sd_deg,
            r->csa_percent, r->csa_sd_percent, r->fit_sd_m, r->steady ? "true" : "false", r->simulated_time_s,
            r->wall_time_s, r->granules, r->particle_steps, dem_world_dt(w), margin, r->dt_lowered, r->start_tilt_deg,
            effects);
}

static int save(const char *dir, const exp_drum_yaml *y, const exp_drum_result *r, const dem_world *w,
                const char *status)
{
    char path[1200], err[1024];
    int bad = exp_result_write_h5(dir, w, err, sizeof err);
    // The drum face at the end of the run (like the paper's Fig. 14), by size.
    snprintf(path, sizeof path, "%s/drum_face.png", dir);
    if (!bad) bad = exp_render_drum_png(path, w, 0.5 * y->diameter, 800, EXP_COLOUR_SIZE, err, sizeof err);
    cal_atomic_file json;
    snprintf(path, sizeof path, "%s/result.json", dir);
    if (!bad && !(bad = cal_atomic_open(&json, path, err, sizeof err))) {
        write_json(json.f, y, r, w, status);
        bad = cal_atomic_commit(&json, err, sizeof err);
    }
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

static int parse_rpm_list(const char *list, double *rpm, int cap, char *err, size_t len)
{
    int n = 0;
    const char *p = list;
    while (*p && n < cap) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !(v >= 0 && v <= 1000) || (*end && *end != ','))
            return snprintf(err, len, "--rpm-list '%s': expected numbers in [0, 1000] separated by commas", list), -1;
        rpm[n++] = v;
        p = *end ? end + 1 : end;
    }
    return n;
}

// Turn one copy of the settled bed at `rpm`; results in DIR (a sweep: in
// DIR/rpm_<rpm>/).
static int turn_copy(dem_world *bed, exp_drum_yaml *y, const exp_drum_def *def, exp_drum_run_opts run, double rpm,
                     const char *dir, int sweep, progress_state *p, FILE *json_out, int first, double checkpoint_every_s)
{
    char sub[1100], err[1024];
    if (sweep) snprintf(sub, sizeof sub, "%s/rpm_%g", dir, rpm);
    else snprintf(sub, sizeof sub, "%s", dir);
    if (cal_mkdirs(sub, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    run.rpm = y->rpm = rpm;
    // The run's checkpoint, labelled with what defines it (as a calibration's record).
    char key[2048], ck_path[1200];
    cal_drum_case whole = {.def = *def, .fill = *def, .run = run};
    cal_drum_key(&whole, rpm, key, sizeof key);
    snprintf(ck_path, sizeof ck_path, "%s/checkpoint.h5", sub);
    const exp_drum_turn turn = {.def = def, .run = run, .checkpoint_path = ck_path, .key = key,
                                .checkpoint_every_s = checkpoint_every_s, .progress = show_progress,
                                .progress_ctx = p, .progress_line_open = p->tty, .log_prefix = "granucal simulate:"};
    exp_drum_result r;
    dem_status st;
    dem_world *w = exp_drum_turn_bed(bed, 0, &turn, &r, &st);
    if (!w) return fprintf(stderr, "granucal simulate: out of memory copying the bed\n"), 1;
    const char *status = st != DEM_OK ? "failed" : r.steady ? "ok" : "not steady";
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: %g rpm: %s\n", rpm, dem_world_error(w));
    int bad = save(sub, y, &r, w, status);
    if (!bad) dem_checkpoint_remove(ck_path); // result.json holds the result now
    if (!first) fputs(", ", json_out);
    write_json(json_out, y, &r, w, status);
    dem_world_destroy(w);
    return bad || st != DEM_OK;
}

int cal_simulate_drum(const exp_drum_yaml *config, const char *out_dir, const char *rpm_list,
                      double checkpoint_every_s)
{
    char err[1024], dir[1024];
    double rpms[32];
    exp_drum_yaml y = *config; // its rpm is each turn's in turn
    int n_rpm = rpm_list ? parse_rpm_list(rpm_list, rpms, 32, err, sizeof err) : 0;
    if (n_rpm < 0) return fprintf(stderr, "granucal simulate: %s\n", err), 2;
    if (n_rpm == 0) rpms[n_rpm++] = y.rpm;
    exp_drum_def def;
    exp_drum_run_opts run;
    exp_drum_config_defs(&y, &def, &run, err, sizeof err);
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/drum");
    if (cal_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    progress_state p = {isatty(2), 0, exp_wall_seconds()};
    dem_world *bed = exp_drum_fill(&def, show_progress, &p, err, sizeof err);
    if (!bed) return fprintf(stderr, "\ngranucal simulate: %s\n", err), 1;
    fprintf(stderr, "%sgranucal simulate: bed of %zu granules settled after %.2f s; %s\n", p.tty ? "\n" : "",
            dem_world_granules(bed).count, dem_world_time(bed), dem_world_dt_report(bed));
    int bad = 0;
    if (n_rpm > 1) fputs("{\"experiment\": \"drum speed sweep\", \"runs\": [", stdout);
    for (int k = 0; k < n_rpm; ++k)
        bad |= turn_copy(bed, &y, &def, run, rpms[k], dir, n_rpm > 1, &p, stdout, k == 0, checkpoint_every_s);
    if (n_rpm > 1) fputs("]}\n", stdout);
    dem_world_destroy(bed);
    return bad;
}
