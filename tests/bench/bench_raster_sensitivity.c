// SPDX-License-Identifier: MIT
// Effect of the raster's pixel size and closing radius on the measured CSA
// (eq. 20) and surface angle (issue 3: "pixel size and closing are stated and
// their effect measured"). Not a test: fills the drum of configs/drum.yaml
// (λ, slice and Table 3 contact as shipped), measures the settled bed, turns
// it at 4 rpm for TURN_S seconds (a tilted, sheared surface) and measures
// again, each time on a grid of pixel sizes and closing radii, both in units
// of the scaled d50. Prints a Markdown table (results/raster_sensitivity.md).
//   build/tests/bench_raster_sensitivity [TURN_S (default 1.5)] [SEED]
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "exp_drum_config.h"

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
    double turn = argc > 1 ? atof(argv[1]) : 1.5;
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
