// SPDX-License-Identifier: MIT
// One drum on 1, 2, 4, ... threads, and a node's throughput by split (a benchmark, not a test;
// issue 37.4): what a cluster user needs to choose `mpirun` ranks x threads.
//
// Fills one drum bed (LAMBDA, periodic slice SLICE_DEPTH_M, Table 3's pair) on every thread, then
//  1. "one run": a copy of that bed turned at RPM for TURN_S simulated seconds (exp_drum_rotate, as a
//     calibration turns it, measuring included) on each thread count of THREADS (e.g. 1,2,4,8,16):
//     wall time, particle-steps per second, speed-up and efficiency against 1 thread, and the
//     angle and CSA to 17 digits, which must be the same on every count (the engine's sums are in one
//     order whatever the threads);
//  2. "split" (with CORES > 0): CORES cores shared as K concurrent runs x T threads each, K*T = CORES
//     (K copies of the bed turned at once, nested OpenMP): the node's particle-steps per second by split.
//     In-process concurrency stands for K ranks or K `--jobs` workers (separate processes in a
//     calibration): the same arithmetic, one allocator.
//   usage: bench_threads LAMBDA SLICE_DEPTH_M RPM TURN_S THREADS [CORES]
// One line of key=value pairs a measurement on stdout.
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"
#include "exp_drum.h"

typedef struct turn {
    double wall_s, particle_steps, angle_deg, csa_percent;
    int ok;
} turn;

// A copy of the bed turned for turn_s on `threads` threads.
static turn turn_copy(const dem_world *bed, const exp_drum_def *d, double rpm, double turn_s, int threads)
{
    turn t = {0};
    dem_world *w = dem_world_clone(bed);
    if (!w || dem_world_set_threads(w, threads) != DEM_OK) return dem_world_destroy(w), t;
    exp_drum_run_opts o = exp_default_drum_run_opts();
    o.rpm = rpm, o.max_time = turn_s;
    o.window = turn_s; // the steady test cannot hold before max_time: every run turns turn_s
    exp_drum_result r;
    double t0 = exp_wall_seconds();
    t.ok = exp_drum_rotate(w, d, &o, NULL, NULL, &r) == DEM_OK;
    t.wall_s = exp_wall_seconds() - t0;
    t.particle_steps = (double)r.particle_steps, t.angle_deg = r.angle_deg, t.csa_percent = r.csa_percent;
    dem_world_destroy(w);
    return t;
}

static void one_run_scaling(const dem_world *bed, const exp_drum_def *d, double rpm, double turn_s, const char *list)
{
    char *copy = strdup(list), *save = NULL;
    double base = 0;
    for (char *tok = strtok_r(copy, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int threads = atoi(tok);
        turn t = turn_copy(bed, d, rpm, turn_s, threads);
        double rate = t.particle_steps / t.wall_s;
        if (base == 0) base = rate / threads; // the first count's per-thread rate (list starts at 1)
        printf("mode=one_run threads=%d ok=%d turn_sim_s=%g wall_s=%.2f particle_steps=%.6g particle_steps_per_s=%.4g "
               "speedup=%.3f efficiency=%.3f angle_deg=%.17g csa_percent=%.17g\n",
               threads, t.ok, turn_s, t.wall_s, t.particle_steps, rate, rate / base, rate / base / threads, t.angle_deg,
               t.csa_percent);
        fflush(stdout);
    }
    free(copy);
}

// K runs at once x T threads each, K*T = cores.
static void split_throughput(const dem_world *bed, const exp_drum_def *d, double rpm, double turn_s, int cores)
{
    omp_set_max_active_levels(2);
    for (int runs = cores; runs >= 1; runs /= 2) {
        int threads = cores / runs;
        turn *t = calloc((size_t)runs, sizeof *t);
        double t0 = exp_wall_seconds();
#pragma omp parallel for num_threads(runs) schedule(static, 1)
        for (int k = 0; k < runs; ++k) t[k] = turn_copy(bed, d, rpm, turn_s, threads);
        double wall = exp_wall_seconds() - t0, steps = 0;
        int ok = 1;
        for (int k = 0; k < runs; ++k) steps += t[k].particle_steps, ok &= t[k].ok;
        printf("mode=split cores=%d runs=%d threads_per_run=%d ok=%d turn_sim_s=%g wall_s=%.2f "
               "node_particle_steps_per_s=%.4g runs_per_hour_of_this_turn=%.1f\n",
               cores, runs, threads, ok, turn_s, wall, steps / wall, runs * 3600.0 / wall);
        fflush(stdout);
        free(t);
        if (runs == 1) break;
    }
}

int main(int argc, char **argv)
{
    if (argc != 6 && argc != 7)
        return fprintf(stderr, "usage: %s LAMBDA SLICE_DEPTH_M RPM TURN_S THREADS [CORES]\n", argv[0]), 2;
    exp_drum_def d = exp_default_drum_def();
    d.lambda = atof(argv[1]), d.periodic = 1, d.depth = atof(argv[2]);
    double rpm = atof(argv[3]), turn_s = atof(argv[4]);
    char err[1024];
    double t0 = exp_wall_seconds();
    dem_world *bed = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!bed) return fprintf(stderr, "%s\n", err), 1;
    printf("mode=fill lambda=%g slice_m=%g granules=%zu fill_threads=%d fill_wall_s=%.1f dt_s=%.4g\n", d.lambda, d.depth,
           dem_world_granules(bed).count, omp_get_max_threads(), exp_wall_seconds() - t0, dem_world_dt(bed));
    fflush(stdout);
    one_run_scaling(bed, &d, rpm, turn_s, argv[5]);
    if (argc == 7) split_throughput(bed, &d, rpm, turn_s, atoi(argv[6]));
    dem_world_destroy(bed);
    return 0;
}
