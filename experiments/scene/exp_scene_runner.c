// SPDX-License-Identifier: MIT
// An explicit scene's runner: build, run, one frame per output interval. See
// exp_scene_runner.h.
#include "exp_scene_runner.h"

#include <stdint.h>
#include <stdio.h>

#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_result.h"

typedef struct sim_outputs {
    exp_atomic_file csv;
    dem_h5_writer *h5;
} sim_outputs;

static void write_rows(FILE *f, const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    double t = dem_world_time(w);
    for (size_t i = 0; i < g.count; ++i)
        fprintf(f, "%.10g,%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", t,
                (unsigned long long)g.id[i] + 1, g.position[i].x, g.position[i].y, g.position[i].z, g.velocity[i].x,
                g.velocity[i].y, g.velocity[i].z, g.omega[i].x, g.omega[i].y, g.omega[i].z);
}

static int write_frame(sim_outputs *o, const dem_world *w)
{
    write_rows(o->csv.f, w);
    return exp_result_h5_frame(o->h5, w);
}

static int open_outputs(sim_outputs *o, const char *dir, char *err, size_t len)
{
    char path[1100];
    if (exp_mkdirs(dir, err, len)) return 1;
    snprintf(path, sizeof path, "%s/trajectory.csv", dir);
    if (exp_atomic_open(&o->csv, path, err, len)) return 1;
    fprintf(o->csv.f, "t,id,x,y,z,vx,vy,vz,wx,wy,wz\n");
    o->h5 = exp_result_h5_open(dir, err, len);
    if (!o->h5) {
        exp_atomic_abort(&o->csv);
        return 1;
    }
    return 0;
}

// Run the scene, one frame per output interval; returns the engine status.
static dem_status run_scene(const exp_scene *s, dem_world *w, sim_outputs *o, uint64_t *steps_done)
{
    double dt = dem_world_dt(w);
    uint64_t per_frame = (uint64_t)(s->output_interval / dt + 0.5);
    if (per_frame == 0) per_frame = 1;
    uint64_t total = (uint64_t)(s->duration / dt + 0.5);
    dem_status st = DEM_OK;
    if (write_frame(o, w)) return DEM_ERR_INVALID;
    for (*steps_done = 0; *steps_done < total && st == DEM_OK;) {
        uint64_t n = total - *steps_done < per_frame ? total - *steps_done : per_frame;
        st = dem_world_step(w, n);
        *steps_done += n;
        if (write_frame(o, w)) return DEM_ERR_INVALID;
    }
    return st;
}

// What result.json says of a run (exp_result_json_fn's ctx).
typedef struct scene_report {
    const exp_scene *s;
    const dem_world *w;
    dem_status st;
    uint64_t steps;
    double wall;
} scene_report;

static void summary_json(FILE *f, const void *ctx)
{
    const scene_report *r = ctx;
    const exp_scene *s = r->s;
    const dem_world *w = r->w;
    dem_status st = r->st;
    uint64_t steps = r->steps;
    double wall = r->wall;
    char features[1024];
    dem_world_describe_features(w, features, sizeof features);
    dem_diagnostics d = dem_world_diagnose(w);
    fprintf(f,
            "{\"scene\": \"%s\", \"status\": \"%s\", \"granules\": %zu, \"dt_s\": %.6g, \"steps\": %llu, "
            "\"simulated_time_s\": %.6g, \"wall_time_s\": %.3f, \"particle_steps\": %llu, "
            "\"contacts\": %zu, \"wall_contacts\": %zu, \"ke_translational_J\": %.6g, \"ke_rotational_J\": %.6g, "
            "\"effects\": \"%s\"",
            s->name, st == DEM_OK ? "ok" : "failed", d.granules, dem_world_dt(w), (unsigned long long)steps,
            dem_world_time(w), wall, (unsigned long long)(steps * d.granules), d.contacts, d.wall_contacts,
            d.ke_translational, d.ke_rotational, features);
    if (st != DEM_OK) fprintf(f, ", \"error\": \"%s\"", dem_world_error(w));
    fprintf(f, "}\n");
}

static int finish(const char *dir, sim_outputs *o, const scene_report *r)
{
    char err[1024];
    int bad = exp_atomic_commit(&o->csv, err, sizeof err);
    bad = bad || dem_h5_close(o->h5, err, sizeof err);
    if (!bad) bad = exp_result_write_json(dir, summary_json, r, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    summary_json(stdout, r);
    if (r->st != DEM_OK) fprintf(stderr, "granucal simulate: run failed: %s\n", dem_world_error(r->w));
    return bad || r->st != DEM_OK ? 1 : 0;
}

int exp_scene_simulate(const exp_scene *s, const char *out_dir, const char *path)
{
    char err[1024], dir[1024];
    if (out_dir) snprintf(dir, sizeof dir, "%s", out_dir);
    else snprintf(dir, sizeof dir, "results/runs/%s", s->name);
    dem_world *w = exp_scene_build(s, err, sizeof err);
    if (!w) return fprintf(stderr, "granucal simulate: %s: %s\n", path, err), 1;
    int rc = 1;
    sim_outputs o = {0};
    if (dem_world_prepare(w) != DEM_OK) {
        fprintf(stderr, "granucal simulate: %s: %s\n", path, dem_world_error(w));
    } else if (open_outputs(&o, dir, err, sizeof err)) {
        fprintf(stderr, "granucal simulate: %s\n", err);
    } else {
        fprintf(stderr, "granucal simulate: %s\n", dem_world_dt_report(w));
        double t0 = exp_wall_seconds();
        scene_report r = {s, w, DEM_OK, 0, 0};
        r.st = run_scene(s, w, &o, &r.steps);
        r.wall = exp_wall_seconds() - t0;
        rc = finish(dir, &o, &r);
    }
    dem_world_destroy(w);
    return rc;
}
