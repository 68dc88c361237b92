// SPDX-License-Identifier: MIT
// The poured cylinder's runner: pour through exp_cylinder_run (the same pour
// as the calibration's stage 1), report, write the results. See
// exp_cylinder_runner.h.
#include "exp_cylinder_runner.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dem_scaling.h"
#include "exp_contact_rules.h"
#include "exp_pour.h"
#include "exp_result.h"

// exp_cylinder.c settles until the kinetic energy ratio drops below this
// (its SETTLE_KE_RATIO) or 2 s have passed: above it the bed is not at rest.
#define REST_KE_RATIO 1e-6

typedef struct progress_state {
    int verbose;
    double last_print, start;
} progress_state;

static void on_progress(const char *phase, double t, size_t granules, void *ctx)
{
    progress_state *p = ctx;
    if (!p->verbose) return;
    double now = exp_wall_seconds();
    if (now - p->last_print < 10.0) return;
    p->last_print = now;
    fprintf(stderr, "cylinder: %s t = %.2f s, %zu granules, wall %.0f s\n", phase, t, granules, now - p->start);
}

dem_world *exp_cylinder_pour_and_report(const exp_cylinder_def *d, int verbose, exp_cylinder_result *r,
                                        exp_cylinder_report *rep, char *err, size_t len)
{
    memset(rep, 0, sizeof *rep);
    progress_state p = {verbose, 0, exp_wall_seconds()};
    p.last_print = p.start;
    dem_world *w = exp_cylinder_run(d, on_progress, &p, r, err, len);
    rep->wall_time_s = exp_wall_seconds() - p.start;
    if (!w) return NULL;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    rep->ke_ratio = exp_ke_ratio(w, gsd.median_diameter);
    rep->bed_surface_m = exp_bed_surface(w, 0);
    dem_granules_view g = dem_world_granules(w);
    for (size_t i = 0; i < g.count; ++i) rep->bed_top_m = fmax(rep->bed_top_m, g.position[i].y + g.radius[i]);
    return w;
}

static void json_number(FILE *f, const char *key, double v, const char *fmt)
{
    fprintf(f, ", \"%s\": ", key);
    if (isfinite(v)) fprintf(f, fmt, v);
    else fputs("null", f); // JSON has no NaN (no interior granule at a coarse lambda)
}

void exp_cylinder_write_json(FILE *f, const exp_cylinder_def *d, const exp_cylinder_result *r,
                             const exp_cylinder_report *rep, const dem_world *w)
{
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    fprintf(f,
            "{\"experiment\": \"cylinder\", \"status\": \"%s\", \"k_n\": %g, \"wall_k_n\": %g, \"mu_s\": %g, "
            "\"mu_r\": %g, \"xi\": %g, \"lambda\": %g, \"seed\": %llu, \"diameter_m\": %g, \"depth_m\": %g, "
            "\"granules\": %zu",
            rep->ke_ratio < REST_KE_RATIO ? "ok" : "not at rest", d->granule.k_n, exp_boundary_stiffness(d->granule.k_n), d->granule.mu_s,
            d->granule.mu_r, d->granule.xi, d->lambda, (unsigned long long)d->seed, d->diameter, d->depth,
            r->granules);
    json_number(f, "coordination", r->coordination, "%.4f");
    json_number(f, "coordination_interior", r->coordination_interior, "%.4f");
    json_number(f, "wall_contacts_per_granule", r->wall_contacts_per_granule, "%.4f");
    json_number(f, "coordination_with_walls", r->coordination + r->wall_contacts_per_granule, "%.4f");
    json_number(f, "solid_fraction", r->solid_fraction, "%.4f");
    json_number(f, "bed_surface_m", rep->bed_surface_m, "%.5g");
    json_number(f, "bed_top_m", rep->bed_top_m, "%.5g");
    json_number(f, "ke_ratio", rep->ke_ratio, "%.3g");
    fprintf(f,
            ", \"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"particle_steps\": %.0f, \"dt_s\": %.6g, "
            "\"effects\": \"%s\"}\n",
            r->simulated_time_s, rep->wall_time_s, r->particle_steps, dem_world_dt(w), effects);
}

// result.json's writer (exp_result_json_fn) over exp_cylinder_write_json.
typedef struct cylinder_json {
    const exp_cylinder_def *d;
    const exp_cylinder_result *r;
    const exp_cylinder_report *rep;
    const dem_world *w;
} cylinder_json;

static void write_json(FILE *f, const void *ctx)
{
    const cylinder_json *j = ctx;
    exp_cylinder_write_json(f, j->d, j->r, j->rep, j->w);
}

int exp_cylinder_write_outputs(const char *dir, const exp_cylinder_def *d, const exp_cylinder_result *r,
                               const exp_cylinder_report *rep, const dem_world *w, char *err, size_t len)
{
    const cylinder_json j = {d, r, rep, w};
    if (exp_mkdirs(dir, err, len)) return 1;
    if (exp_result_write_h5(dir, w, err, len)) return 1;
    return exp_result_write_json(dir, write_json, &j, err, len);
}

int exp_cylinder_simulate(const exp_cylinder_def *def, const char *out_dir)
{
    char err[1400], dir[1024];
    const exp_cylinder_def d = *def;
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/cylinder");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_cylinder_result r;
    exp_cylinder_report rep;
    dem_world *w = exp_cylinder_pour_and_report(&d, 1, &r, &rep, err, sizeof err);
    if (!w) {
        fprintf(stderr, "granucal simulate: %s\n", err);
        exp_result_print_failure("cylinder", err);
        return 1;
    }
    fprintf(stderr, "granucal simulate: %zu granules; %s\n", r.granules, dem_world_dt_report(w));
    int bad = exp_cylinder_write_outputs(dir, &d, &r, &rep, w, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    exp_cylinder_write_json(stdout, &d, &r, &rep, w);
    if (!(rep.ke_ratio < REST_KE_RATIO))
        fprintf(stderr,
                "granucal simulate: the settle stopped at its time limit (kinetic energy ratio %.3g, at rest below "
                "%.0e): status \"not at rest\"; the contacts are counted as they are\n",
                rep.ke_ratio, REST_KE_RATIO);
    dem_world_destroy(w);
    return bad;
}
