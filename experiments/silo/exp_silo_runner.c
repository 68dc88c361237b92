// SPDX-License-Identifier: MIT
// The silo discharge benchmark's runner: fill, discharge, write the results.
// See exp_silo_runner.h.
#include "exp_silo_runner.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_atomic_file.h"
#include "exp_plot.h"
#include "exp_result.h"


int exp_silo_write_liggghts_data(const char *path, const dem_world *w, const exp_silo_def *d, size_t plate_spheres,
                                 char *err, size_t len)
{
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    dem_granules_view g = dem_world_granules(w);
    double r = d->silo_radius;
    fprintf(f, "LIGGGHTS data file: silo discharge at t = 0 (granucal exp_silo; type 1 flowing, 2 plate)\n\n");
    fprintf(f, "%zu atoms\n3 atom types\n\n", g.count);
    fprintf(f, "%.6f %.6f xlo xhi\n%.6f %.6f ylo yhi\n%.6f %.6f zlo zhi\n\nAtoms\n\n", -1.2 * r, 1.2 * r, -1.2 * r, 1.2 * r,
            -2.0, d->plate_z + 4 * (double)d->n_granules / (r * r) + 20);
    // atom_style granular: atom-ID atom-type diameter density x y z
    for (size_t i = 0; i < g.count; ++i) {
        int plate = g.id[i] < plate_spheres;
        fprintf(f, "%llu %d %.17g %.17g %.17g %.17g %.17g\n", (unsigned long long)g.id[i] + 1, plate ? 2 : 1,
                2 * g.radius[i], d->density, g.position[i].x, g.position[i].y, g.position[i].z);
    }
    if (exp_atomic_commit(&a, err, len)) return 1;
    return 0;
}

int exp_silo_write_series(const exp_silo_result *r, const char *csv_path, const char *png_prefix, char *err, size_t len)
{
    exp_atomic_file a;
    if (exp_atomic_open(&a, csv_path, err, len)) return 1;
    FILE *f = a.f;
    fprintf(f, "t_s,contacts,wall_contacts,ke_translational_J,ke_rotational_J,ke_total_J,discharged,discharged_mass_kg\n");
    for (size_t k = 0; k < r->n_series; ++k) {
        const exp_silo_sample *s = &r->series[k];
        fprintf(f, "%.4f,%zu,%zu,%.6g,%.6g,%.6g,%zu,%.6g\n", s->t, s->contacts, s->wall_contacts, s->ke_translational,
                s->ke_rotational, s->ke_translational + s->ke_rotational, s->discharged, s->discharged_mass);
    }
    if (exp_atomic_commit(&a, err, len)) return 1;
    if (!png_prefix) return 0;
    size_t n = r->n_series;
    double *t = malloc((n + 1) * sizeof *t), *c = malloc((n + 1) * sizeof *c), *ke = malloc((n + 1) * sizeof *ke);
    if (!t || !c || !ke) return free(t), free(c), free(ke), exp_fail(err, len, "out of memory");
    for (size_t k = 0; k < n; ++k)
        t[k] = r->series[k].t, c[k] = (double)r->series[k].contacts,
        ke[k] = r->series[k].ke_translational + r->series[k].ke_rotational;
    char path[1200];
    exp_plot_series s = {.n = n, .x = t, .y = c, .label = "granucal", .rgb = {0.12, 0.47, 0.71}};
    exp_plot_axes ax = {.title = "Silo discharge: contacts (Fig. A.4)", .xlabel = "t (s)", .ylabel = "contacts"};
    snprintf(path, sizeof path, "%scontacts.png", png_prefix);
    int rc = exp_plot_png(path, &ax, 1, &s, 900, 500, err, len);
    s.y = ke;
    exp_plot_axes ax2 = {.title = "Silo discharge: kinetic energy (Fig. A.5)", .xlabel = "t (s)", .ylabel = "kinetic energy (J)",
                         .log_y = 1};
    snprintf(path, sizeof path, "%skinetic_energy.png", png_prefix);
    if (!rc) rc = exp_plot_png(path, &ax2, 1, &s, 900, 500, err, len);
    free(t), free(c), free(ke);
    return rc;
}

// What result.json says of a finished discharge (exp_result_json_fn's ctx).
typedef struct silo_report {
    const exp_silo_def *d;
    const exp_silo_result *r;
    const dem_world *w;
    const char *status;
} silo_report;

static void write_json(FILE *f, const void *ctx)
{
    const silo_report *rep = ctx;
    const exp_silo_def *d = rep->d;
    const exp_silo_result *r = rep->r;
    char effects[1024];
    dem_world_describe_features(rep->w, effects, sizeof effects);
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
            "\"particle_steps\": %llu, \"orifice_clear_radius_m\": %.3f, \"final_contacts\": %zu, \"final_ke_J\": %.6g, "
            "\"discharged_final\": %zu, \"t_half_discharged_s\": %s, \"t_90_discharged_s\": %s, \"effects\": \"%s\"}\n",
            rep->status, r->granules, r->plate_spheres, (unsigned long long)d->seed, dem_world_dt(rep->w),
            last ? last->t : 0.0, r->fill_time_s, r->wall_time_s, r->particle_steps, exp_silo_orifice_clear_radius(d),
            last ? last->contacts : 0, last ? last->ke_translational + last->ke_rotational : 0.0,
            last ? last->discharged : 0, s50, s90, effects);
}

// Fill, prepare and write the t = 0 state for LIGGGHTS: the discharge's world,
// or NULL with the message on stderr. *bad: the data file could not be written.
static dem_world *fill_silo(const exp_silo_def *d, const char *dir, exp_progress_printer *ps, size_t *plate, int *bad,
                            double *fill_wall)
{
    char err[1400], p[1200];
    dem_world *w = exp_silo_prepare(d, exp_print_progress, ps, plate, err, sizeof err);
    if (!w) return fprintf(stderr, "granucal simulate: %s\n", err), NULL;
    *fill_wall = exp_wall_seconds() - ps->start;
    if (dem_world_prepare(w) != DEM_OK) {
        fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    snprintf(p, sizeof p, "%s/silo_initial.data", dir);
    *bad = exp_silo_write_liggghts_data(p, w, d, *plate, err, sizeof err);
    if (*bad) fprintf(stderr, "granucal simulate: %s\n", err);
    fprintf(stderr, "granucal simulate: silo filled (%zu granules, %zu plate spheres) in %.0f s; %s\n",
            dem_world_granules(w).count - *plate, *plate, *fill_wall, dem_world_dt_report(w));
    return w;
}

static int write_outputs(const char *dir, const silo_report *rep)
{
    char err[1400], p[1200], prefix[1100];
    snprintf(p, sizeof p, "%s/series.csv", dir);
    snprintf(prefix, sizeof prefix, "%s/", dir);
    int bad = exp_silo_write_series(rep->r, p, prefix, err, sizeof err);
    if (!bad) bad = exp_result_write_h5(dir, rep->w, err, sizeof err);
    if (!bad) bad = exp_result_write_json(dir, write_json, rep, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

int exp_silo_simulate(const exp_silo_def *d, const char *out_dir)
{
    char err[1400], dir[1024];
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/silo");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_progress_printer ps = {.scene = "silo", .start = exp_wall_seconds()};
    size_t plate = 0;
    int bad = 0;
    double fill_wall = 0;
    dem_world *w = fill_silo(d, dir, &ps, &plate, &bad, &fill_wall);
    if (!w) return 1;
    exp_silo_result r;
    double t0 = exp_wall_seconds();
    dem_status st = exp_silo_discharge(w, d, plate, exp_print_progress, &ps, &r);
    r.wall_time_s = exp_wall_seconds() - t0;
    r.fill_time_s = fill_wall;
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
    silo_report rep = {d, &r, w, st == DEM_OK ? "ok" : "failed"};
    if (!bad) bad = write_outputs(dir, &rep);
    write_json(stdout, &rep);
    exp_silo_result_free(&r);
    dem_world_destroy(w);
    return bad || st != DEM_OK;
}
