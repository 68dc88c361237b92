// SPDX-License-Identifier: MIT
// A drum run phase by phase (a benchmark, not a test): build the bed (pour or
// random packing, then settle), report the settled bed (granules, solid
// fraction, coordination) and each phase's wall and simulated time; then, if
// asked, turn it as a calibration does (exp_drum_rotate, Table 3's pair) and
// report the angle, the CSA and the turn's particle-steps per second.
//   usage: bench_drum_phases LAMBDA SLICE_DEPTH_M pour|pack SEED [RPM MAX_TIME_S]
// One line of key=value pairs on stdout (tests/bench/drum_fill_methods.sh
// collects them).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"
#include "exp_drum.h"

typedef struct phase_clock {
    const char *phase; // the phase the time since `last` belongs to
    double last, pour_s, settle_s;
} phase_clock;

static void tick(const char *phase, double t, size_t granules, void *ctx)
{
    (void)t, (void)granules;
    phase_clock *c = ctx;
    double now = exp_wall_seconds();
    if (strcmp(phase, "pour") == 0) c->pour_s += now - c->last;
    else c->settle_s += now - c->last;
    c->last = now;
}

static double bed_solid_fraction(const dem_world *w, const exp_drum_def *d)
{
    dem_granules_view g = dem_world_granules(w);
    double solid = 0, r = 0.5 * d->diameter;
    for (size_t i = 0; i < g.count; ++i) solid += 4.0 / 3.0 * DEM_PI * g.radius[i] * g.radius[i] * g.radius[i];
    return solid / (d->fill * DEM_PI * r * r * d->depth); // the bed is cut to the fill degree
}

int main(int argc, char **argv)
{
    if (argc != 5 && argc != 7)
        return fprintf(stderr, "usage: %s LAMBDA SLICE_DEPTH_M pour|pack SEED [RPM MAX_TIME_S]\n", argv[0]), 2;
    exp_drum_def d = exp_default_drum_def();
    d.lambda = atof(argv[1]), d.periodic = 1, d.depth = atof(argv[2]), d.seed = strtoull(argv[4], NULL, 10);
    if (exp_drum_fill_method_from_name(argv[3], &d.fill_method)) return fprintf(stderr, "pour or pack\n"), 2;
    char err[1024];
    phase_clock clock = {NULL, exp_wall_seconds(), 0, 0};
    double t0 = clock.last;
    dem_world *w = exp_drum_fill(&d, tick, &clock, err, sizeof err);
    if (!w) return fprintf(stderr, "%s\n", err), 1;
    double fill_wall = exp_wall_seconds() - t0;
    dem_diagnostics diag = dem_world_diagnose(w);
    printf("fill_method=%s lambda=%g slice_m=%g seed=%s granules=%zu fill_sim_s=%.3f fill_wall_s=%.2f "
           "pour_wall_s=%.2f settle_wall_s=%.2f fill_dt_s=%.4g solid_fraction=%.4f coordination=%.3f",
           argv[3], d.lambda, d.depth, argv[4], dem_world_granules(w).count, dem_world_time(w), fill_wall,
           clock.pour_s, clock.settle_s, dem_world_dt(w), bed_solid_fraction(w, &d), diag.coordination);
    if (argc == 7) {
        exp_drum_run_opts o = exp_default_drum_run_opts();
        o.rpm = atof(argv[5]), o.max_time = atof(argv[6]);
        exp_drum_result r;
        double t1 = exp_wall_seconds();
        dem_status st = exp_drum_rotate(w, &d, &o, NULL, NULL, &r);
        double turn_wall = exp_wall_seconds() - t1;
        printf(" rpm=%g status=%s steady=%d turn_sim_s=%.2f turn_wall_s=%.2f turn_dt_s=%.4g "
               "turn_particle_steps_per_s=%.4g angle_deg=%.3f angle_sd_deg=%.3f csa_percent=%.3f csa_sd_percent=%.3f",
               o.rpm, st == DEM_OK ? "ok" : dem_world_error(w), r.steady, r.simulated_time_s, turn_wall, dem_world_dt(w),
               (double)r.particle_steps / turn_wall, r.angle_deg, r.angle_sd_deg, r.csa_percent, r.csa_sd_percent);
    }
    printf("\n");
    dem_world_destroy(w);
    return 0;
}
