// SPDX-License-Identifier: MIT
// Benchmark (not a test), for each integration (explicit, implicit dashpot,
// implicit springs):
//  1. restitution of a granule bouncing on a wall (Table 3 wall, k = 400) at
//     the integration's DEFAULT step and at the paper's 0.6 dt_crit (where it
//     is accepted), each reading of eq. 4. Analytic at xi = 0.7: approaching
//     0.459, always 0.046, separating 0.100, no_tension 0.210;
//  2. cost of one settled bed (Table 3, paper GSD, d50 = 2 mm, periodic slab):
//     wall time per step and per simulated second, measured side by side and
//     alternated (A B C A B C ...) like bench_features.
// Usage: build/tests/bench_restitution_default_step [granules] [steps] [rounds]
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_bed.h"
#include "dem_gsd.h"
#include "dem_stability.h"
#include "dem_world.h"

static const char *names[] = {"explicit", "implicit dashpot", "implicit springs"};

static dem_world_def integration_def(int integ)
{
    dem_world_def d = dem_default_world_def();
    d.implicit_damping = integ == 1;
    d.implicit_springs = integ == 2;
    return d;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// Rebound speed / impact speed; dt_factor 0 = the default step. Returns -1 if refused.
static double restitution(int integ, int mode, double dt_factor, double *dt_used)
{
    dem_world_def d = integration_def(integ);
    d.granule.damping = mode;
    d.granule.mu_s = d.granule.mu_r = 0;
    d.gravity = dem_v3(0, 0, 0);
    d.domain_lo = dem_v3(-1, -1, -1);
    d.domain_hi = dem_v3(1, 1, 1);
    const double R = 1e-3, m = 1800 * 4.0 / 3.0 * DEM_PI * R * R * R, dt_crit = sqrt(m / d.granule.k_n);
    d.dt = dt_factor * dt_crit;
    dem_world *w = dem_world_create(&d, NULL, 0);
    dem_contact_params wc = d.granule;
    wc.k_n = wc.k_s = wc.k_r = 400;
    dem_wall_def fl = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .contact = wc};
    dem_world_add_wall(w, &fl);
    dem_world_add_granule(w, dem_v3(0, 1.05 * R, 0), dem_v3(0, -0.1, 0), dem_v3(0, 0, 0), R, 1800);
    double e = -1;
    if (dem_world_prepare(w) == DEM_OK) {
        *dt_used = dem_world_dt(w) / dt_crit;
        dem_world_step(w, (uint64_t)(0.05 / dem_world_dt(w)));
        e = dem_world_granules(w).velocity[0].y / 0.1;
    }
    dem_world_destroy(w);
    return e;
}

// The benchmark bed (bench_bed.h): 2 mm granules in an 8 x 4 cm slab, settled 0.4 s.
static dem_world *settled_bed(int integ, int n)
{
    return bench_settled_bed(integration_def(integ), n, 0.08, 0.04, 1.0, 2e-3, 0.4);
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 2000, steps = argc > 2 ? atoi(argv[2]) : 500;
    int rounds = argc > 3 ? atoi(argv[3]) : 3;
    const char *modes[] = {"approaching", "always", "separating", "no_tension"};
    const double analytic[] = {0.459, 0.046, 0.100, 0.210};
    printf("restitution on a wall (k = 400), xi = 0.7\n%-17s %-12s %9s %8s %14s\n", "integration", "reading",
           "analytic", "default", "at 0.6 dt_crit");
    for (int integ = 0; integ < 3; ++integ)
        for (int mode = 0; mode < 4; ++mode) {
            double dt_def = 0, dt06 = 0;
            double e_def = restitution(integ, mode, 0, &dt_def), e06 = restitution(integ, mode, 0.6, &dt06);
            char at06[32];
            if (e06 < 0) snprintf(at06, sizeof at06, "refused");
            else snprintf(at06, sizeof at06, "%.4f", e06);
            printf("%-17s %-12s %9.3f %8.4f %14s   (default step %.3f dt_crit)\n", names[integ], modes[mode],
                   analytic[mode], e_def, at06, dt_def);
        }
    dem_world *w[3];
    double dt[3], best[3] = {1e300, 1e300, 1e300};
    for (int k = 0; k < 3; ++k) {
        w[k] = settled_bed(k, n);
        dt[k] = dem_world_dt(w[k]);
        dem_diagnostics d = dem_world_diagnose(w[k]);
        printf("bed, %s: %d granules, coordination %.2f, %s\n", names[k], n, d.coordination, dem_world_dt_report(w[k]));
    }
    for (int r = 0; r < rounds; ++r)
        for (int k = 0; k < 3; ++k) {
            double t0 = now();
            dem_world_step(w[k], (uint64_t)steps);
            double per = (now() - t0) / steps;
            best[k] = per < best[k] ? per : best[k];
        }
    printf("%-17s %12s %12s %18s %16s\n", "integration", "dt/dt_crit", "us per step", "s per simulated s",
           "vs explicit");
    for (int k = 0; k < 3; ++k) {
        dem_stability st = dem_stability_apriori(w[k]);
        printf("%-17s %12.3f %12.1f %18.1f %16.2f\n", names[k], dt[k] / st.dt_crit, 1e6 * best[k], best[k] / dt[k],
               (best[k] / dt[k]) / (best[0] / dt[0]));
    }
    for (int k = 0; k < 3; ++k) dem_world_destroy(w[k]);
    return 0;
}
