// SPDX-License-Identifier: MIT
// `granucal simulate drum.yaml`: fill, turn to a steady state, measure.
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cal_commands.h"
#include "cal_util.h"
#include "dem_output.h"
#include "exp_drum_config.h"

typedef struct progress_state {
    int tty;
    double last_wall, start;
} progress_state;

static void show_progress(const char *phase, double t, size_t granules, void *ctx)
{
    progress_state *p = ctx;
    double now = cal_wall_seconds();
    if (now - p->last_wall < (p->tty ? 0.5 : 10.0)) return;
    p->last_wall = now;
    fprintf(stderr, p->tty ? "\r%-6s t = %6.3f s  granules %zu  wall %6.0f s   " : "%s t = %.3f s granules %zu wall %.0f s\n",
            phase, t, granules, now - p->start);
}

static void write_json(FILE *f, const exp_drum_yaml *y, const exp_drum_result *r, const dem_world *w, const char *status)
{
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    fprintf(f,
            "{\"experiment\": \"drum\", \"status\": \"%s\", \"rpm\": %g, \"wall\": \"%s\", \"mu_s\": %g, \"mu_r\": %g, "
            "\"k_n\": %g, \"lambda\": %g, \"seed\": %d, \"angle_deg\": %.4f, \"angle_sd_deg\": %.4f, "
            "\"csa_percent\": %.4f, \"csa_sd_percent\": %.4f, \"surface_fit_sd_m\": %.4g, \"steady\": %s, "
            "\"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"granules\": %zu, \"particle_steps\": %llu, "
            "\"dt_s\": %.6g, \"effects\": \"%s\"}\n",
            status, y->rpm, y->wall, y->mu_s, y->mu_r, y->k_n, y->lambda, y->seed, r->angle_deg, r->angle_sd_deg,
            r->csa_percent, r->csa_sd_percent, r->fit_sd_m, r->steady ? "true" : "false", r->simulated_time_s,
            r->wall_time_s, r->granules, r->particle_steps, dem_world_dt(w), effects);
}

static int save(const char *dir, const exp_drum_yaml *y, const exp_drum_result *r, const dem_world *w,
                const char *status)
{
    char path[1100], err[1024];
    snprintf(path, sizeof path, "%s/result.h5", dir);
    dem_h5_writer *h5 = dem_h5_open(path, err, sizeof err);
    dem_granules_view g = dem_world_granules(w);
    dem_diagnostics d = dem_world_diagnose(w);
    int bad = !h5 || dem_h5_write_frame(h5, dem_world_time(w), &g, &d) ||
              dem_h5_write_attribute_string(h5, "dt_report", dem_world_dt_report(w));
    if (h5) bad |= dem_h5_close(h5, err, sizeof err);
    cal_atomic_file json;
    snprintf(path, sizeof path, "%s/result.json", dir);
    if (!bad && !cal_atomic_open(&json, path, err, sizeof err)) {
        write_json(json.f, y, r, w, status);
        bad = cal_atomic_commit(&json, err, sizeof err);
    }
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

int cal_simulate_drum(const char *path, int n_sets, char **sets, const char *out)
{
    char err[1024], dir[1024];
    exp_drum_yaml *y = exp_drum_config_load(path, n_sets, sets, err, sizeof err);
    if (!y) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_drum_def def;
    exp_drum_run_opts run;
    exp_drum_config_defs(y, &def, &run, err, sizeof err);
    snprintf(dir, sizeof dir, "%s", out ? out : "results/runs/drum");
    if (cal_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), exp_drum_config_free(y), 1;
    progress_state p = {isatty(2), 0, cal_wall_seconds()};
    dem_world *w = exp_drum_fill(&def, show_progress, &p, err, sizeof err);
    if (!w) return fprintf(stderr, "\ngranucal simulate: %s\n", err), exp_drum_config_free(y), 1;
    exp_drum_result r;
    dem_status st = exp_drum_rotate(w, &def, &run, show_progress, &p, &r);
    r.wall_time_s = cal_wall_seconds() - p.start;
    if (p.tty) fputc('\n', stderr);
    const char *status = st != DEM_OK ? "failed" : r.steady ? "ok" : "not steady";
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: %s\n", dem_world_error(w));
    fprintf(stderr, "granucal simulate: %s\n", dem_world_dt_report(w));
    int bad = save(dir, y, &r, w, status);
    write_json(stdout, y, &r, w, status);
    dem_world_destroy(w);
    exp_drum_config_free(y);
    return bad || st != DEM_OK ? 1 : 0;
}
