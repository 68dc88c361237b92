// SPDX-License-Identifier: MIT
// Does the start tilt move where the drum's bed ends up? (not a test)
// Fills the default drum (Table 3's pair, granule lining) as a periodic slice,
// turns the settled bed rigidly by TILT_DEG (exp_drum_tilt; 0: a level start),
// turns the drum at RPM on the settled bed's network step, and prints
// "t angle_signed_deg csa_percent" every 0.05 s for SECONDS, then the mean
// angle over the last FROM..SECONDS s.
//
//   bench_drum_tilt LAMBDA SLICE_DEPTH_M RPM TILT_DEG SECONDS FROM SEED
//   (results/drum_tilt/: 32768 0.03 4 {0,20} 9 5 1)
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "exp_drum.h"

int main(int argc, char **argv)
{
    if (argc != 8)
        return fprintf(stderr, "usage: %s LAMBDA SLICE_DEPTH_M RPM TILT_DEG SECONDS FROM SEED\n", argv[0]), 2;
    exp_drum_def d = exp_default_drum_def();
    d.lambda = atof(argv[1]), d.periodic = 1, d.depth = atof(argv[2]), d.seed = (uint64_t)atoll(argv[7]);
    const double rpm = atof(argv[3]), tilt = atof(argv[4]), seconds = atof(argv[5]), from = atof(argv[6]);
    char err[512];
    dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!w) return fprintf(stderr, "fill: %s\n", err), 1;
    if ((tilt != 0 && exp_drum_tilt(w, tilt) != DEM_OK) || dem_world_adopt_network_dt(w) != DEM_OK)
        return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
    dem_world_set_wall_spin(w, 0, rpm * 2 * DEM_PI / 60);
    const double pixel = 0.25 * d.gsd.median_diameter * cbrt(d.lambda), t0 = dem_world_time(w);
    const uint64_t chunk = (uint64_t)(0.05 / dem_world_dt(w) + 0.5);
    double sum = 0;
    int n = 0;
    while (dem_world_time(w) - t0 < seconds - 1e-9) {
        if (dem_world_step(w, chunk) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
        exp_drum_measure m;
        if (exp_drum_measure_now(w, &d, pixel, d.closing_px, &m)) return fprintf(stderr, "measure failed\n"), 1;
        const double t = dem_world_time(w) - t0;
        printf("%.3f %.3f %.3f\n", t, m.angle_signed_deg, m.csa_percent);
        if (t > from) sum += m.angle_signed_deg, n++;
    }
    printf("# mean angle over t = %g-%g s: %.2f deg (%d samples), %zu granules\n", from, seconds, n ? sum / n : NAN, n,
           dem_world_granules(w).count);
    dem_world_destroy(w);
    return 0;
}
