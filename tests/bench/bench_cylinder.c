// SPDX-License-Identifier: MIT
// The poured cylinder (section 4.1) over a list of stiffnesses (not a test):
// the coordination number of the bed at rest against k (Fig. 12).
// Usage: build/tests/bench_cylinder LAMBDA K1 [K2 ...]   (k real, N/m)
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "exp_cylinder.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv)
{
    if (argc < 3) return fprintf(stderr, "usage: %s LAMBDA K1 [K2 ...]\n", argv[0]), 2;
    printf("%10s %8s %12s %14s %16s %14s %10s\n", "k_n (N/m)", "granules", "coordination", "interior CN",
           "wall contacts/N", "solid fraction", "wall (s)");
    for (int a = 2; a < argc; ++a) {
        exp_cylinder_def d = exp_default_cylinder_def();
        d.lambda = atof(argv[1]);
        d.granule.k_n = d.granule.k_s = d.granule.k_r = atof(argv[a]);
        char err[512];
        exp_cylinder_result r;
        double t0 = now();
        dem_world *w = exp_cylinder_run(&d, NULL, NULL, &r, err, sizeof err);
        if (!w) {
            printf("k = %s: %s\n", argv[a], err);
            continue;
        }
        printf("%10g %8zu %12.3f %14.3f %16.3f %14.3f %10.0f\n", d.granule.k_n, r.granules, r.coordination,
               r.coordination_interior, r.wall_contacts_per_granule, r.solid_fraction, now() - t0);
        fflush(stdout);
        dem_world_destroy(w);
    }
    return 0;
}
