// SPDX-License-Identifier: MIT
// A drum run phase by phase (a benchmark, not a test): build the bed (pour or
// random packing), settle it, report the settled bed (granules, solid
// fraction, coordination); time the kernel alone on a copy of that bed (the
// same N, walls still, no measuring: what the engine does per second); then,
// if asked, turn the bed as a calibration does (exp_drum_rotate, Table 3's
// pair) and report the angle, the CSA, the turn's particle-steps per second
// with and without its measuring, and the whole run's against the kernel's.
// K_N (N/m, default Table 3's 200) is the granule stiffness, the boundaries
// twice it (Table 3): what a stiffness chosen by stage 1 costs in steps.
//   usage: bench_drum_phases LAMBDA SLICE_DEPTH_M pour|pack SEED [RPM MAX_TIME_S [K_N]]
// One line of key=value pairs on stdout (tests/bench/drum_fill_methods.sh and
// drum_end_to_end.sh collect them).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_drum.h"

// The fill's phases as its progress reports them, every 0.01 s simulated:
// wall time, and granules × simulated seconds (over the fill's step, its
// particle-steps: the step of an a-priori bound set by the lightest granule,
// the same for every layer once the bed holds a few of the GSD's smallest).
typedef struct phase_clock {
    double last_wall, last_t;
    double pour_s, settle_s, granule_seconds;
} phase_clock;

static void tick(const char *phase, double t, size_t granules, void *ctx)
{
    phase_clock *c = ctx;
    double now = exp_wall_seconds();
    if (strcmp(phase, "pour") == 0) c->pour_s += now - c->last_wall;
    else c->settle_s += now - c->last_wall;
    c->granule_seconds += (double)granules * (t - c->last_t);
    c->last_wall = now, c->last_t = t;
}

static double bed_solid_fraction(const dem_world *w, const exp_drum_def *d)
{
    dem_granules_view g = dem_world_granules(w);
    double solid = 0, r = 0.5 * d->diameter;
    for (size_t i = 0; i < g.count; ++i) solid += 4.0 / 3.0 * DEM_PI * g.radius[i] * g.radius[i] * g.radius[i];
    return solid / (d->fill * DEM_PI * r * r * d->depth); // the bed is cut to the fill degree
}

// The kernel alone on a copy of the settled bed at the turn's step: 0.1 s
// simulated, walls still, nothing measured. Particle-steps per second.
static double kernel_rate(const dem_world *bed)
{
    dem_world *w = dem_world_clone(bed);
    if (!w || dem_world_adopt_network_dt(w) != DEM_OK) return dem_world_destroy(w), 0;
    uint64_t steps = (uint64_t)(0.1 / dem_world_dt(w)) + 1;
    double t0 = exp_wall_seconds();
    dem_status st = dem_world_step(w, steps);
    double wall = exp_wall_seconds() - t0, rate = (double)steps * (double)dem_world_granules(w).count / wall;
    dem_world_destroy(w);
    return st == DEM_OK ? rate : 0;
}

int main(int argc, char **argv)
{
    if (argc != 5 && argc != 7 && argc != 8)
        return fprintf(stderr, "usage: %s LAMBDA SLICE_DEPTH_M pour|pack SEED [RPM MAX_TIME_S [K_N]]\n", argv[0]), 2;
    exp_drum_def d = exp_default_drum_def();
    d.lambda = atof(argv[1]), d.periodic = 1, d.depth = atof(argv[2]), d.seed = strtoull(argv[4], NULL, 10);
    if (argc == 8) {
        d.granule = exp_granule_pair(atof(argv[7]), d.granule.xi, d.granule.mu_s, d.granule.mu_r, d.granule.damping);
        d.wall = d.end_plate = exp_boundary_pair(&d.granule, d.granule.mu_s, d.granule.mu_r);
    }
    if (exp_drum_fill_method_from_name(argv[3], &d.fill_method)) return fprintf(stderr, "pour or pack\n"), 2;
    char err[1024];
    phase_clock clock = {.last_wall = exp_wall_seconds()};
    double t0 = clock.last_wall;
    dem_world *w = exp_drum_fill(&d, tick, &clock, err, sizeof err);
    if (!w) return fprintf(stderr, "%s\n", err), 1;
    double fill_wall = exp_wall_seconds() - t0;
    dem_diagnostics diag = dem_world_diagnose(w);
    size_t n = dem_world_granules(w).count;
    double fill_steps = clock.granule_seconds / dem_world_dt(w), kernel = kernel_rate(w);
    printf("fill_method=%s lambda=%g slice_m=%g k_n=%g seed=%s granules=%zu fill_sim_s=%.3f fill_wall_s=%.2f "
           "pour_wall_s=%.2f settle_wall_s=%.2f fill_dt_s=%.4g fill_particle_steps_per_s=%.4g solid_fraction=%.4f "
           "coordination=%.3f kernel_particle_steps_per_s=%.4g",
           argv[3], d.lambda, d.depth, d.granule.k_n, argv[4], n, dem_world_time(w), fill_wall, clock.pour_s, clock.settle_s,
           dem_world_dt(w), fill_steps / fill_wall, bed_solid_fraction(w, &d), diag.coordination, kernel);
    if (argc >= 7) {
        exp_drum_run_opts o = exp_default_drum_run_opts();
        o.rpm = atof(argv[5]), o.max_time = atof(argv[6]);
        exp_drum_result r;
        double t1 = exp_wall_seconds();
        dem_status st = exp_drum_rotate(w, &d, &o, NULL, NULL, &r);
        double turn_wall = exp_wall_seconds() - t1, steps = (double)r.particle_steps;
        printf(" rpm=%g status=%s steady=%d turn_sim_s=%.2f turn_wall_s=%.2f measure_wall_s=%.2f measure_share=%.3f "
               "turn_dt_s=%.4g turn_particle_steps_per_s=%.4g turn_stepping_particle_steps_per_s=%.4g "
               "end_to_end_particle_steps_per_s=%.4g end_to_end_over_kernel=%.3f "
               "angle_deg=%.3f angle_sd_deg=%.3f csa_percent=%.3f csa_sd_percent=%.3f "
               "network_check_wall_s=%.2f network_check_share=%.4f dt_margin_min=%.3f dt_lowered=%d",
               o.rpm, st == DEM_OK ? "ok" : dem_world_error(w), r.steady, r.simulated_time_s, turn_wall,
               r.measure_wall_s, r.measure_wall_s / turn_wall, dem_world_dt(w), steps / turn_wall,
               steps / (turn_wall - r.measure_wall_s), (steps + fill_steps) / (turn_wall + fill_wall),
               (steps + fill_steps) / (turn_wall + fill_wall) / kernel, r.angle_deg, r.angle_sd_deg,
               r.csa_percent, r.csa_sd_percent, r.network_check_wall_s, r.network_check_wall_s / turn_wall,
               r.dt_margin_min, r.dt_lowered);
    }
    printf("\n");
    dem_world_destroy(w);
    return 0;
}
