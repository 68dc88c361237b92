// SPDX-License-Identifier: MIT
// Drum run at Table 3's granule-granule parameters (not a test): fill a periodic
// slice by bed volume, turn it, and print angle and CSA every 0.1 s with the
// wall time. Usage: build/tests/bench_drum_4rpm LAMBDA SLICE_DEPTH_M RPM [live]
// (a 5th argument: turn at the step of the settled bed's contact network)
// (docs/experiments.md's 4 rpm figures: bench_drum_4rpm 4096 0.015 4).
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "exp_drum.h"
static double now(void){struct timespec t; clock_gettime(CLOCK_MONOTONIC,&t); return t.tv_sec+1e-9*t.tv_nsec;}
int main(int argc, char **argv)
{
    if (argc < 4) return fprintf(stderr, "usage: %s LAMBDA SLICE_DEPTH_M RPM\n", argv[0]), 2;
  exp_drum_def d = exp_default_drum_def();
  d.lambda = atof(argv[1]); d.periodic = 1; d.depth = atof(argv[2]); double rpm = atof(argv[3]);
  char err[512]; double t0=now();
  dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
  if(!w){printf("fail: %s\n",err); return 1;}
  double px = 0.25*d.gsd.median_diameter*cbrt(d.lambda);
  exp_drum_measure m; exp_drum_measure_now(w,&d,px,2,&m);
  printf("filled %zu granules, wall %.0f s; at rest angle %.2f csa %.2f; %s\n", dem_world_granules(w).count, now()-t0, m.angle_deg, m.csa_percent, dem_world_dt_report(w));
  if (argc > 4 && dem_world_adopt_network_dt(w) != DEM_OK) { printf("%s\n", dem_world_error(w)); return 1; }
  if (argc > 4) printf("adopted: %s\n", dem_world_dt_report(w));
  dem_world_set_wall_spin(w, 0, rpm*2*DEM_PI/60);
  double t_start = dem_world_time(w);
  while (dem_world_time(w) - t_start < 6.0) {
    if (dem_world_step(w,(uint64_t)(0.1/dem_world_dt(w))) != DEM_OK) { printf("fault: %s\n", dem_world_error(w)); return 1; }
    exp_drum_measure_now(w,&d,px,2,&m); dem_diagnostics dg = dem_world_diagnose(w);
    printf("t=%.1f angle %.2f (fit sd %.2e m) csa %.2f KE %.2e (wall %.0f s)\n", dem_world_time(w)-t_start, m.angle_deg, m.angle_fit_sd_m, m.csa_percent, dg.ke_translational, now()-t0); fflush(stdout);
  }
}
