// SPDX-License-Identifier: MIT
// Effect of the raster's pixel size and closing radius on the measured CSA
// (eq. 20) and surface angle (issue 3: "pixel size and closing are stated and
// their effect measured"). Not a test: fills the drum of configs/drum.yaml
// (λ, slice and Table 3 contact as shipped) and measures the settled bed;
// then either reads a turned bed from the last frame of a drum run's
// result.h5 (granucal simulate configs/drum.yaml --out DIR: DIR/result.h5)
// or turns the settled bed at 4 rpm for TURN_S seconds; each bed measured on
// a grid of pixel sizes and closing radii, both in units of the scaled d50.
// Prints Markdown tables (results/raster_sensitivity.md).
//   build/tests/bench_raster_sensitivity [TURN_S | RESULT.h5] [SEED]
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <hdf5.h>
#include <string.h>

#include "exp_drum_config.h"

// Positions and radii of /frames/000000 of a result.h5 (one frame: the end
// of a drum run) into a world with no walls: enough for the measurement.
static dem_world *read_frame(const char *path, const exp_drum_def *d)
{
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) return NULL;
    hid_t pos = H5Dopen2(f, "/frames/000000/position", H5P_DEFAULT), rad = H5Dopen2(f, "/frames/000000/radius", H5P_DEFAULT);
    hsize_t n = 0;
    if (rad >= 0) {
        hid_t sp = H5Dget_space(rad);
        H5Sget_simple_extent_dims(sp, &n, NULL);
        H5Sclose(sp);
    }
    double *p = malloc((n + 1) * 3 * sizeof *p), *r = malloc((n + 1) * sizeof *r);
    dem_world *w = NULL;
    if (pos >= 0 && rad >= 0 && n > 0 && H5Dread(pos, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, p) >= 0 &&
        H5Dread(rad, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, r) >= 0) {
        dem_world_def def = dem_default_world_def();
        def.domain_lo = dem_v3(-d->diameter, -d->diameter, -d->depth);
        def.domain_hi = dem_v3(d->diameter, d->diameter, 2 * d->depth);
        w = dem_world_create(&def, NULL, 0);
        for (hsize_t i = 0; w && i < n; ++i)
            dem_world_add_granule(w, dem_v3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), dem_v3(0, 0, 0), dem_v3(0, 0, 0), r[i], 1.0);
    }
    free(p), free(r);
    if (pos >= 0) H5Dclose(pos);
    if (rad >= 0) H5Dclose(rad);
    H5Fclose(f);
    return w;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void table(const dem_world *w, const exp_drum_def *d, const char *state)
{
    const double pixel_d50[] = {1.0 / 8, 1.0 / 4, 1.0 / 2, 1.0};
    const double closing_d50[] = {0, 0.25, 0.5, 1.0, 2.0};
    double d50 = d->gsd.median_diameter * cbrt(d->lambda);
    printf("\n### %s\n\n", state);
    printf("pixel (d50) | closing radius (d50) | closing (px) | CSA (%%) | angle (°) | fit spread (mm)\n");
    printf("---|---|---|---|---|---\n");
    for (size_t p = 0; p < sizeof pixel_d50 / sizeof *pixel_d50; ++p)
        for (size_t c = 0; c < sizeof closing_d50 / sizeof *closing_d50; ++c) {
            double pixel = pixel_d50[p] * d50;
            int px = (int)(closing_d50[c] / pixel_d50[p] + 0.5);
            if (px > 50) continue;
            exp_drum_measure m;
            int rc = exp_drum_measure_now(w, d, pixel, px, &m);
            int is_default = p == 1 && c == 2; // the shipped choice: d50/4, 2 px
            printf("%s%.3g | %.3g | %d | %.2f | %s%.2f | %.2f%s\n", is_default ? "**" : "", pixel_d50[p],
                   closing_d50[c], px, m.csa_percent, rc ? "(fit failed) " : "", m.angle_deg, 1e3 * m.angle_fit_sd_m,
                   is_default ? "**" : "");
        }
}

int main(int argc, char **argv)
{
    const char *h5 = argc > 1 && strstr(argv[1], ".h5") ? argv[1] : NULL;
    double turn = argc > 1 && !h5 ? atof(argv[1]) : 1.5;
    char path[1024], err[1024];
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, sizeof path, "%s/configs/drum.yaml", src ? src : ".");
    char seed_set[64], *sets[1] = {seed_set};
    snprintf(seed_set, sizeof seed_set, "seed=%s", argc > 2 ? argv[2] : "1");
    exp_drum_yaml *y = exp_drum_config_load(path, 1, sets, err, sizeof err);
    if (!y) return fprintf(stderr, "%s\n", err), 1;
    exp_drum_def d;
    exp_drum_run_opts run;
    if (exp_drum_config_defs(y, &d, &run, err, sizeof err)) return fprintf(stderr, "%s\n", err), 1;
    double t0 = now();
    dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!w) return fprintf(stderr, "%s\n", err), 1;
    printf("drum of %s (%s), lambda %g, %zu granules, scaled d50 %.3f mm; fill %.0f s wall\n", path, seed_set, d.lambda,
           dem_world_granules(w).count, 1e3 * d.gsd.median_diameter * cbrt(d.lambda), now() - t0);
    table(w, &d, "settled bed (fill degree 43 %)");
    if (h5) {
        dem_world *t = read_frame(h5, &d);
        if (!t) return fprintf(stderr, "cannot read the last frame of %s\n", h5), 1;
        char state[1200];
        snprintf(state, sizeof state, "turned bed: the end of the drum run in %s (%zu granules)", h5,
                 dem_world_granules(t).count);
        table(t, &d, state);
        dem_world_destroy(t), dem_world_destroy(w);
        exp_drum_config_free(y);
        return 0;
    }
    if (dem_world_adopt_network_dt(w) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
    dem_world_set_wall_spin(w, 0, 4 * 2 * DEM_PI / 60);
    t0 = now();
    if (dem_world_step(w, (uint64_t)(turn / dem_world_dt(w))) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
    char state[128];
    snprintf(state, sizeof state, "after %.2f s at 4 rpm (%.0f s wall)", turn, now() - t0);
    table(w, &d, state);
    dem_world_destroy(w);
    exp_drum_config_free(y);
    return 0;
}
