// SPDX-License-Identifier: MIT
// `granucal simulate configs/silo.yaml`: fill, discharge, and the run's
// outputs (exp_silo_runner.h).
#include "exp_silo_runner.h"

#include <math.h>
#include <stdio.h>

#include "exp_common.h"
#include "exp_result.h"
#include "exp_silo_config.h"

static void write_json(FILE *f, const exp_silo_def *d, const exp_silo_result *r, const dem_world *w, const char *status)
{
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    const exp_silo_sample *last = r->n_series ? &r->series[r->n_series - 1] : NULL;
    // Time at which half and 90 % of the granules were below the plate.
    double t50 = NAN, t90 = NAN;
    for (size_t k = 0; k < r->n_series; ++k) {
        if (isnan(t50) && r->series[k].discharged * 2 >= r->granules) t50 = r->series[k].t;
        if (isnan(t90) && r->series[k].discharged * 10 >= r->granules * 9) t90 = r->series[k].t;
    }
    char s50[32], s90[32]; // JSON has no NaN: null when not reached
    snprintf(s50, sizeof s50, isnan(t50) ? "null" : "%.3f", t50);
    snprintf(s90, sizeof s90, isnan(t90) ? "null" : "%.3f", t90);
    fprintf(f,
            "{\"experiment\": \"silo\", \"status\": \"%s\", \"granules\": %zu, \"plate_spheres\": %zu, \"seed\": %llu, "
            "\"dt_s\": %.6g, \"simulated_time_s\": %.4f, \"fill_time_s\": %.3f, \"wall_time_s\": %.2f, "
            "\"particle_steps\": %llu, \"orifice_clear_radius_m\": %.3f, \"final_contacts\": %zu, \"final_ke_J\": %.6g, \"discharged_final\": %zu, "
            "\"t_half_discharged_s\": %s, \"t_90_discharged_s\": %s, \"effects\": \"%s\"}\n",
            status, r->granules, r->plate_spheres, (unsigned long long)d->seed, dem_world_dt(w), last ? last->t : 0.0,
            r->fill_time_s, r->wall_time_s, r->particle_steps, exp_silo_orifice_clear_radius(d), last ? last->contacts : 0,
            last ? last->ke_translational + last->ke_rotational : 0.0, last ? last->discharged : 0, s50, s90, effects);
}

int exp_silo_simulate(const char *path, int n_sets, char **sets, const char *out)
{
    char err[1400], dir[1024], p[1200];
    exp_silo_def d;
    if (exp_silo_load(path, n_sets, sets, &d, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    snprintf(dir, sizeof dir, "%s", out ? out : "results/runs/silo");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_progress_printer ps = {.scene = "silo", .start = exp_wall_seconds()};
    size_t plate = 0;
    dem_world *w = exp_silo_prepare(&d, exp_print_progress, &ps, &plate, err, sizeof err);
    if (!w) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    double fill_wall = exp_wall_seconds() - ps.start;
    if (dem_world_prepare(w) != DEM_OK) {
        fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
        dem_world_destroy(w);
        return 1;
    }
    snprintf(p, sizeof p, "%s/silo_initial.data", dir);
    int bad = exp_silo_write_liggghts_data(p, w, &d, plate, err, sizeof err);
    fprintf(stderr, "granucal simulate: silo filled (%zu granules, %zu plate spheres) in %.0f s; %s\n",
            dem_world_granules(w).count - plate, plate, fill_wall, dem_world_dt_report(w));
    exp_silo_result r;
    double t0 = exp_wall_seconds();
    dem_status st = exp_silo_discharge(w, &d, plate, exp_print_progress, &ps, &r);
    r.wall_time_s = exp_wall_seconds() - t0;
    r.fill_time_s = fill_wall;
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
    char prefix[1100];
    snprintf(p, sizeof p, "%s/series.csv", dir);
    snprintf(prefix, sizeof prefix, "%s/", dir);
    bad = bad || exp_silo_write_series(&r, p, prefix, err, sizeof err);
    if (!bad) bad = exp_result_write_h5(dir, w, err, sizeof err);
    const char *status = st == DEM_OK ? "ok" : "failed";
    if (!bad) {
        char tmp[1300];
        snprintf(p, sizeof p, "%s/result.json", dir);
        snprintf(tmp, sizeof tmp, "%s.tmp", p);
        FILE *f = fopen(tmp, "w");
        if (f) write_json(f, &d, &r, w, status);
        bad = !f || fclose(f) != 0 || rename(tmp, p) != 0;
        if (bad) snprintf(err, sizeof err, "cannot write '%s'", p);
    }
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    write_json(stdout, &d, &r, w, status);
    exp_silo_result_free(&r);
    dem_world_destroy(w);
    return bad || st != DEM_OK;
}
