// SPDX-License-Identifier: MIT
// The confined compression test's runner: run, report, write the results.
// See exp_compress_runner.h.
#include "exp_compress_runner.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_atomic_file.h"
#include "exp_plot.h"
#include "exp_result.h"


int exp_compress_write_curve(const exp_compress_result *r, const char *csv_path, const char *png_path, char *err,
                             size_t len)
{
    exp_atomic_file a;
    if (exp_atomic_open(&a, csv_path, err, len)) return 1;
    FILE *f = a.f;
    // The engine's axial totals come last, so the columns before keep their places.
    fprintf(f, "t_s,cycle,loading,piston_y_m,displacement_m,strain,force_top_N,force_bottom_N,force_side_normal_N,"
               "sigma_Pa,ke_over_elastic,piston_axial_total_N,floor_axial_total_N,side_axial_total_N\n");
    for (size_t k = 0; k < r->n_curve; ++k) {
        const exp_compress_sample *s = &r->curve[k];
        fprintf(f, "%.6g,%d,%d,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.3g,%.6g,%.6g,%.6g\n", s->t, s->cycle, s->loading,
                s->piston_y, s->displacement, s->strain, s->f_top, s->f_bottom, s->f_side, s->sigma, s->ke_over_elastic,
                s->f_piston_axial, s->f_floor_axial, s->f_side_axial);
    }
    if (exp_atomic_commit(&a, err, len)) return 1;
    if (!png_path) return 0;
    // One series per cycle, displacement in mm against the piston force.
    int nc = r->n_cycles > 0 ? r->n_cycles : 1;
    size_t n = r->n_curve;
    double *x = malloc((n + 1) * sizeof *x), *y = malloc((n + 1) * sizeof *y);
    exp_plot_series *series = calloc((size_t)nc + 1, sizeof *series);
    char (*labels)[32] = calloc((size_t)nc + 1, sizeof *labels);
    if (!x || !y || !series || !labels) return free(x), free(y), free(series), free(labels), exp_fail(err, len, "out of memory");
    size_t used = 0;
    int ns = 0;
    for (int c = 1; c <= nc; ++c) {
        size_t first = used;
        for (size_t k = 0; k < n; ++k)
            if (r->curve[k].cycle == c && r->curve[k].displacement != 0)
                x[used] = 1e3 * r->curve[k].displacement, y[used++] = r->curve[k].f_top;
        if (used == first) continue;
        snprintf(labels[ns], sizeof labels[ns], "cycle %d", c);
        series[ns] = (exp_plot_series){.n = used - first, .x = x + first, .y = y + first, .label = labels[ns]};
        exp_plot_colour(c - 1, series[ns].rgb);
        ns++;
    }
    exp_plot_axes ax = {.title = "Confined compression: force on the piston", .xlabel = "piston displacement (mm)",
                        .ylabel = "force (N)"};
    int rc = exp_plot_png(png_path, &ax, (size_t)ns, series, 900, 600, err, len);
    free(x), free(y), free(series), free(labels);
    return rc;
}

// What result.json says of a finished run (exp_result_json_fn's ctx).
typedef struct compress_report {
    const exp_compress_def *d;
    const exp_compress_result *r;
    const dem_world *w;
    const char *status;
    double wall_time_s;
} compress_report;

static void write_json(FILE *f, const void *ctx)
{
    const compress_report *rep = ctx;
    const exp_compress_def *d = rep->d;
    const exp_compress_result *r = rep->r;
    char effects[1024];
    dem_world_describe_features(rep->w, effects, sizeof effects);
    fprintf(f,
            "{\"experiment\": \"compression\", \"status\": \"%s\", \"k_n\": %g, \"mu_s\": %g, \"wall_mu_s\": %g, "
            "\"lambda\": %g, \"seed\": %llu, \"sigma_min_Pa\": %g, \"sigma_max_Pa\": %g, \"piston_speed_m_s\": %g, "
            "\"e_confined_Pa\": %.6g, \"e_confined_loading_Pa\": %.6g, \"stable\": %s, \"cycles\": [",
            rep->status, d->granule.k_n, d->granule.mu_s, d->wall.mu_s, d->lambda, (unsigned long long)d->seed,
            d->sigma_min, d->sigma_max, d->piston_speed, r->e_confined, r->e_confined_loading,
            r->stable ? "true" : "false");
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
            r->simulated_time_s, rep->wall_time_s, r->particle_steps, dem_world_dt(rep->w), effects);
}

static int write_outputs(const char *dir, const compress_report *rep)
{
    char path[1100], png[1100], err[1200];
    snprintf(path, sizeof path, "%s/curve.csv", dir);
    snprintf(png, sizeof png, "%s/force_displacement.png", dir);
    int bad = exp_compress_write_curve(rep->r, path, png, err, sizeof err);
    if (!bad) bad = exp_result_write_h5(dir, rep->w, err, sizeof err);
    if (!bad) bad = exp_result_write_json(dir, write_json, rep, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    return bad;
}

int exp_compress_simulate(const exp_compress_def *d, const char *out_dir)
{
    char err[1024], dir[1024];
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/compression");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_progress_printer p = {.scene = "compression", .start = exp_wall_seconds()};
    exp_compress_result r;
    dem_world *w = exp_compress_run(d, exp_print_progress, &p, &r, err, sizeof err);
    int rc = 1;
    if (!w) {
        fprintf(stderr, "granucal simulate: %s\n", err);
        exp_result_print_failure("compression", err);
    } else {
        compress_report rep = {d, &r, w, r.stable ? "ok" : "not stable", exp_wall_seconds() - p.start};
        fprintf(stderr, "granucal simulate: %zu granules; %s\n", r.granules, dem_world_dt_report(w));
        rc = write_outputs(dir, &rep);
        write_json(stdout, &rep);
    }
    exp_compress_result_free(&r);
    dem_world_destroy(w);
    return rc;
}
