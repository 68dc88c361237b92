// SPDX-License-Identifier: MIT
// `granucal simulate configs/compression.yaml`: run and outputs
// (exp_compress_runner.h).
#include "exp_compress_runner.h"

#include <stdio.h>

#include "exp_common.h"
#include "exp_compress_config.h"
#include "exp_result.h"

static void write_json(FILE *f, const exp_compress_def *d, const exp_compress_result *r,
                       const dem_world *w, const char *status, double wall)
{
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    fprintf(f,
            "{\"experiment\": \"compression\", \"status\": \"%s\", \"k_n\": %g, \"mu_s\": %g, \"wall_mu_s\": %g, "
            "\"lambda\": %g, \"seed\": %d, \"sigma_min_Pa\": %g, \"sigma_max_Pa\": %g, \"piston_speed_m_s\": %g, "
            "\"e_confined_Pa\": %.6g, \"e_confined_loading_Pa\": %.6g, \"stable\": %s, \"cycles\": [",
            status, d->granule.k_n, d->granule.mu_s, d->wall.mu_s, d->lambda, (int)d->seed, d->sigma_min, d->sigma_max, d->piston_speed,
            r->e_confined, r->e_confined_loading, r->stable ? "true" : "false");
    for (int k = 0; k < r->n_cycles; ++k) {
        const exp_compress_cycle *c = &r->cycle[k];
        fprintf(f,
                "%s{\"e_loading_Pa\": %.6g, \"e_unloading_Pa\": %.6g, \"strain_start\": %.6g, \"strain_turn\": %.6g, "
                "\"strain_end\": %.6g, \"permanent_strain\": %.6g, \"work_in_J\": %.6g, \"work_out_J\": %.6g}",
                k ? ", " : "", c->e_loading, c->e_unloading, c->strain_start, c->strain_turn, c->strain_end,
                c->permanent_strain, c->work_in, c->work_out);
    }
    fprintf(f,
            "], \"bed_height_m\": %.6g, \"solid_fraction\": %.4f, \"coordination_at_sigma_max\": %.3f, "
            "\"max_ke_over_elastic\": %.3g, \"granules\": %zu, \"fill_time_s\": %.4f, \"simulated_time_s\": %.4f, "
            "\"wall_time_s\": %.2f, \"particle_steps\": %llu, \"dt_s\": %.6g, \"effects\": \"%s\"}\n",
            r->bed_height, r->solid_fraction, r->coordination_turn, r->max_ke_over_elastic, r->granules, r->fill_time_s,
            r->simulated_time_s, wall, r->particle_steps, dem_world_dt(w), effects);
}

static int write_outputs(const char *dir, const exp_compress_def *d,
                         const exp_compress_result *r, const dem_world *w, double wall)
{
    char path[1100], png[1100], err[1200], tmp[1200];
    snprintf(path, sizeof path, "%s/curve.csv", dir);
    snprintf(png, sizeof png, "%s/force_displacement.png", dir);
    int bad = exp_compress_write_curve(r, path, png, err, sizeof err);
    if (!bad) bad = exp_result_write_h5(dir, w, err, sizeof err);
    if (!bad) {
        snprintf(path, sizeof path, "%s/result.json", dir);
        snprintf(tmp, sizeof tmp, "%s.tmp", path);
        FILE *f = fopen(tmp, "w");
        if (f) write_json(f, d, r, w, r->stable ? "ok" : "not stable", wall);
        bad = !f || fclose(f) != 0 || rename(tmp, path) != 0;
        if (bad) snprintf(err, sizeof err, "cannot write '%s'", path);
    }
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

int exp_compress_simulate(const char *path, int n_sets, char **sets, const char *out)
{
    char err[1024], dir[1024];
    exp_compress_def d;
    if (exp_compress_load(path, n_sets, sets, &d, err, sizeof err))
        return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    snprintf(dir, sizeof dir, "%s", out ? out : "results/runs/compression");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_progress_printer p = {.scene = "compression", .start = exp_wall_seconds()};
    exp_compress_result r;
    dem_world *w = exp_compress_run(&d, exp_print_progress, &p, &r, err, sizeof err);
    int rc = 1;
    if (!w) {
        fprintf(stderr, "granucal simulate: %s\n", err);
        printf("{\"experiment\": \"compression\", \"status\": \"failed\", \"error\": \"%s\"}\n", err);
    } else {
        double wall = exp_wall_seconds() - p.start;
        fprintf(stderr, "granucal simulate: %zu granules; %s\n", r.granules, dem_world_dt_report(w));
        int bad = write_outputs(dir, &d, &r, w, wall);
        write_json(stdout, &d, &r, w, r.stable ? "ok" : "not stable", wall);
        rc = bad;
    }
    exp_compress_result_free(&r);
    dem_world_destroy(w);
    return rc;
}
