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

#include "bench_bed.h"
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

// The benchmark bed (bench_bed.h): 1 mm granules in a 4 x 2 cm slab, settled 0.3 s.
static dem_world *settled_bed(int n, double dt)
{
    dem_world_def def = dem_default_world_def();
    def.dt = dt;
    return bench_settled_bed(def, n, 0.04, 0.02, 0.5, 1e-3, 0.3);
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
