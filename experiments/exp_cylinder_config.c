// SPDX-License-Identifier: MIT
// The poured cylinder (section 4.1) as a YAML scene: load, --set, validate,
// run through exp_cylinder_run (the same pour as the calibration's stage 1),
// report. See exp_cylinder_config.h.
#include "exp_cylinder_config.h"

#include <cyaml/cyaml.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_scaling.h"
#include "exp_contact_rules.h"
#include "exp_pour.h"
#include "exp_result.h"
#include "exp_scene.h"
#include "exp_yaml.h"

// exp_cylinder.c settles until the kinetic energy ratio drops below this
// (its SETTLE_KE_RATIO) or 2 s have passed: above it the bed is not at rest.
#define REST_KE_RATIO 1e-6

typedef struct cylinder_yaml {
    char *experiment;
    double diameter, depth, density, median_diameter, geometric_sd, truncation_sigmas, lambda;
    double k_n, xi, mu_s, mu_r;
    char *damping;
    int seed;
} cylinder_yaml;

#define F(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, cylinder_yaml, member)
static const cyaml_schema_field_t cylinder_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, cylinder_yaml, experiment, 1, 16),
    F("diameter", diameter), F("depth", depth), F("density", density), F("median_diameter", median_diameter),
    F("geometric_sd", geometric_sd), F("truncation_sigmas", truncation_sigmas), F("lambda", lambda), F("k_n", k_n),
    F("xi", xi), F("mu_s", mu_s), F("mu_r", mu_r),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cylinder_yaml, damping, 1, 32),
    CYAML_FIELD_INT("seed", CYAML_FLAG_DEFAULT, cylinder_yaml, seed), CYAML_FIELD_END};
#undef F
static const cyaml_schema_value_t cylinder_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cylinder_yaml, cylinder_fields)};

int exp_is_cylinder_config(const char *path) { return exp_yaml_starts_with(path, "experiment: cylinder"); }

int exp_cylinder_check(const exp_cylinder_def *d, char *msg, size_t len)
{
    char sub[256];
    if (!(isfinite(d->diameter) && d->diameter > 0)) return exp_fail(msg, len, "diameter = %g: must be > 0", d->diameter);
    if (!(isfinite(d->depth) && d->depth > 0)) return exp_fail(msg, len, "depth = %g: must be > 0", d->depth);
    if (!(isfinite(d->density) && d->density > 0)) return exp_fail(msg, len, "density = %g: must be > 0", d->density);
    if (!(isfinite(d->lambda) && d->lambda >= 1) || dem_scale_check(d->lambda, sub, sizeof sub))
        return exp_fail(msg, len, "lambda = %g: must be finite and >= 1 (lambda = N_real/N_scaled, eq. 15)", d->lambda);
    if (dem_gsd_check(&d->gsd, sub, sizeof sub)) return exp_fail(msg, len, "%s", sub);
    if (dem_contact_params_check(&d->granule, sub, sizeof sub)) return exp_fail(msg, len, "granule_contact.%s", sub);
    if (dem_contact_params_check(&d->wall, sub, sizeof sub)) return exp_fail(msg, len, "wall_contact.%s", sub);
    // The pour's lattice pitch is 1.05 d_max and keeps 0.55 pitch off the wall
    // (exp_pour_to_rim): the container must hold a lattice point and a granule.
    double dmax = dem_gsd_max_diameter(&d->gsd) * cbrt(d->lambda);
    if (d->diameter < 2.2 * dmax || d->depth < dmax)
        return exp_fail(msg, len,
                        "lambda = %g: the largest scaled granule (%.3g m) does not fit the %.3g x %.3g m container",
                        d->lambda, dmax, d->diameter, d->depth);
    return 0;
}

static int to_def(const cylinder_yaml *y, exp_cylinder_def *d, char *err, size_t len)
{
    *d = exp_default_cylinder_def();
    d->diameter = y->diameter, d->depth = y->depth, d->density = y->density, d->lambda = y->lambda;
    d->gsd = dem_gsd_lognormal(y->median_diameter, y->geometric_sd, y->truncation_sigmas);
    dem_damping_mode mode;
    if (exp_damping_from_name(y->damping, "damping", &mode, err, len)) return 1;
    // The container's friction is the granules' (as in the calibration's
    // stage 1); exp_cylinder_run gives it Table 3's boundary stiffness.
    d->granule = exp_granule_pair(y->k_n, y->xi, y->mu_s, y->mu_r, mode);
    d->wall = d->granule;
    d->seed = (uint64_t)y->seed;
    return 0;
}

static int apply_set(cylinder_yaml *y, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("mu_s", &y->mu_s), EXP_SET_NUMBER("mu_r", &y->mu_r),
        EXP_SET_NUMBER("xi", &y->xi), EXP_SET_NUMBER("lambda", &y->lambda), EXP_SET_INTEGER("seed", &y->seed),
        EXP_SET_NUMBER("diameter", &y->diameter), EXP_SET_NUMBER("depth", &y->depth),
        EXP_SET_NUMBER("density", &y->density)};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

int exp_cylinder_load(const char *path, int n_sets, char **sets, exp_cylinder_def *d, char *err, size_t len)
{
    cylinder_yaml *y = NULL;
    if (exp_yaml_load(path, &cylinder_schema, (void **)&y, "check the keys and value types against configs/cylinder.yaml",
                      err, len))
        return 1;
    char msg[300];
    int bad = 0;
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "cylinder") != 0)
        bad = exp_field_error(path, 0, NULL, "experiment", "must be cylinder", err, len);
    if (!bad && y->seed < 0) {
        snprintf(msg, sizeof msg, "seed = %d: must be >= 0", y->seed);
        bad = exp_field_error(path, 0, NULL, "seed", msg, err, len);
    }
    if (!bad && (to_def(y, d, msg, sizeof msg) || exp_cylinder_check(d, msg, sizeof msg))) {
        // Messages start with the field: "depth = ...", "granule_contact.mu_s = ...",
        // "gsd.geometric_sd = ..."; the YAML key is the last part.
        char field[EXP_FIELD_LEN];
        bad = exp_field_error(path, n_sets, sets, exp_message_field(msg, field), msg, err, len);
    }
    exp_yaml_free(&cylinder_schema, y);
    return bad;
}

// ------------------------------------------------------------ run + report

typedef struct progress_state {
    int verbose;
    double last_print, start;
    double last_t, granule_seconds; ///< Σ granules × simulated time, for the particle-step estimate
} progress_state;

static void on_progress(const char *phase, double t, size_t granules, void *ctx)
{
    progress_state *p = ctx;
    // exp_run_for reports after each chunk of steps, with the granules the chunk ran.
    if (t > p->last_t) p->granule_seconds += (t - p->last_t) * (double)granules;
    p->last_t = t;
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
    progress_state p = {verbose, 0, exp_wall_seconds(), 0, 0};
    p.last_print = p.start;
    dem_world *w = exp_cylinder_run(d, on_progress, &p, r, err, len);
    rep->wall_time_s = exp_wall_seconds() - p.start;
    if (!w) return NULL;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    rep->ke_ratio = exp_ke_ratio(w, gsd.median_diameter);
    rep->particle_steps_est = dem_world_dt(w) > 0 ? p.granule_seconds / dem_world_dt(w) : 0;
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
            ", \"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"particle_steps_est\": %.0f, \"dt_s\": %.6g, "
            "\"effects\": \"%s\"}\n",
            r->simulated_time_s, rep->wall_time_s, rep->particle_steps_est, dem_world_dt(w), effects);
}

int exp_cylinder_write_outputs(const char *dir, const exp_cylinder_def *d, const exp_cylinder_result *r,
                               const exp_cylinder_report *rep, const dem_world *w, char *err, size_t len)
{
    char path[1100], tmp[1200];
    if (exp_mkdirs(dir, err, len)) return 1;
    if (exp_result_write_h5(dir, w, err, len)) return 1;
    snprintf(path, sizeof path, "%s/result.json", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (f) exp_cylinder_write_json(f, d, r, rep, w);
    if (!f || fclose(f) != 0 || rename(tmp, path) != 0) {
        remove(tmp);
        return exp_fail(err, len, "cannot write '%s'", path);
    }
    return 0;
}

int exp_cylinder_simulate(const char *path, int n_sets, char **sets, const char *out)
{
    char err[1400], dir[1024];
    exp_cylinder_def d;
    if (exp_cylinder_load(path, n_sets, sets, &d, err, sizeof err))
        return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    snprintf(dir, sizeof dir, "%s", out ? out : "results/runs/cylinder");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_cylinder_result r;
    exp_cylinder_report rep;
    dem_world *w = exp_cylinder_pour_and_report(&d, 1, &r, &rep, err, sizeof err);
    if (!w) {
        fprintf(stderr, "granucal simulate: %s\n", err);
        printf("{\"experiment\": \"cylinder\", \"status\": \"failed\", \"error\": \"");
        for (const char *c = err; *c; ++c) // a JSON string: escape quotes, backslashes, control characters
            if (*c == '"' || *c == '\\') printf("\\%c", *c);
            else if ((unsigned char)*c < 0x20) printf("\\u%04x", (unsigned)(unsigned char)*c);
            else putchar(*c);
        printf("\"}\n");
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
