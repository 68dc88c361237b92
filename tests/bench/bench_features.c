// SPDX-License-Identifier: MIT
// Benchmark (not a test): particle-steps per second of one dense bed with
// each effect switched on and off, measured side by side in one run and
// alternated (A B A B ...) so the shared machine's noise hits all alike.
// Shows that an effect a scene does not use costs nothing in the inner loop.
//
//   build/tests/bench_features [granules] [steps] [rounds]
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <time.h>

#include "dem_gsd.h"
#include "dem_world.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct variant {
    const char *name;
    double mu_s, mu_r, xi;
} variant;

// A bed poured into a periodic slab (periodic along z) on a floor, settled.
static dem_world *settled_bed(int n, double dt)
{
    dem_world_def def = dem_default_world_def();
    const double width = 0.04, depth = 0.02;
    def.domain_lo = dem_v3(-width, -0.01, 0);
    def.domain_hi = dem_v3(width, 0.5, depth);
    def.periodic_axis = 2;
    def.dt = dt;
    dem_world *w = dem_world_create(&def, NULL, 0);
    dem_contact_params wall = def.granule;
    wall.k_n = wall.k_s = wall.k_r = 400;
    dem_wall_def planes[3] = {{.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .contact = wall},
                              {.kind = DEM_WALL_PLANE, .point = {-width / 2, 0, 0}, .normal = {1, 0, 0}, .contact = wall},
                              {.kind = DEM_WALL_PLANE, .point = {width / 2, 0, 0}, .normal = {-1, 0, 0}, .contact = wall}};
    for (int k = 0; k < 3; ++k) dem_world_add_wall(w, &planes[k]);
    dem_gsd g = dem_default_gsd();
    g.median_diameter = 1e-3;
    double *d = malloc((size_t)n * sizeof *d);
    dem_gsd_sample(&g, 1, (size_t)n, d);
    double pitch = dem_gsd_max_diameter(&g) * 1.05;
    int nx = (int)(width / pitch) - 1, nz = (int)(depth / pitch);
    for (int i = 0; i < n; ++i) {
        int ix = i % nx, iz = (i / nx) % nz, iy = i / (nx * nz);
        dem_world_add_granule(w, dem_v3(-width / 2 + pitch * (ix + 1), pitch * (iy + 1), pitch * (iz + 0.5)),
                              dem_v3(0.01 * sin(i), 0, 0), dem_v3(0, 0, 0), 0.5 * d[i], 1800);
    }
    free(d);
    if (dem_world_prepare(w) != DEM_OK) {
        fprintf(stderr, "%s\n", dem_world_error(w));
        exit(1);
    }
    dem_world_step(w, (uint64_t)(0.3 / dem_world_dt(w)));
    return w;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 20000, steps = argc > 2 ? atoi(argv[2]) : 2000;
    int rounds = argc > 3 ? atoi(argv[3]) : 3;
    const variant variants[] = {{"all on (Table 3)", 0.8, 0.2, 0.7},
                                {"rolling off", 0.8, 0.0, 0.7},
                                {"tangential and rolling off", 0.0, 0.0, 0.7},
                                {"damping off", 0.8, 0.2, 0.0}};
    const int nv = sizeof variants / sizeof *variants;
    dem_world *w = settled_bed(n, 0.0);
    printf("bed: %d granules, %s\n", n, dem_world_dt_report(w));
    double best[8] = {0};
    for (int r = 0; r < rounds; ++r)
        for (int v = 0; v < nv; ++v) {
            dem_contact_params p = dem_default_world_def().granule;
            p.mu_s = variants[v].mu_s, p.mu_r = variants[v].mu_r, p.xi = variants[v].xi;
            dem_world_set_granule_contact(w, &p);
            double t0 = now();
            dem_world_step(w, (uint64_t)steps);
            double rate = (double)n * steps / (now() - t0);
            best[v] = rate > best[v] ? rate : best[v];
        }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("%-30s %16s %10s\n", "effects", "particle-steps/s", "vs all on");
    for (int v = 0; v < nv; ++v)
        printf("%-30s %16.3e %10.2f\n", variants[v].name, best[v], best[v] / best[0]);
    printf("peak memory %.1f MiB (%.0f bytes per granule)\n", ru.ru_maxrss / 1024.0, ru.ru_maxrss * 1024.0 / n);
    dem_world_destroy(w);
    return 0;
}
