// SPDX-License-Identifier: MIT
// Restitution of a granule bouncing on a wall at the engine's DEFAULT step (not a
// test): explicit vs implicit dashpot, each reading of eq. 4. Analytic at xi = 0.7:
// approaching 0.459, always 0.046, separating 0.100, no_tension 0.210.
// Usage: build/tests/bench_restitution_default_step
#include <stdio.h>
#include <stdlib.h>
#include "dem_world.h"
#include "dem_stability.h"

int main(void){
  for (int imp=0; imp<2; ++imp) for (int mode=0; mode<4; ++mode){
    dem_world_def d = dem_default_world_def();
    d.implicit_damping = imp; d.granule.damping = mode; d.granule.mu_s = 0; d.granule.mu_r=0;
    d.gravity = dem_v3(0,0,0);
    d.domain_lo = dem_v3(-1,-1,-1); d.domain_hi = dem_v3(1,1,1);
    dem_world *w = dem_world_create(&d,NULL,0);
    dem_contact_params wc = d.granule; wc.k_n = wc.k_s = wc.k_r = 400;
    dem_wall_def fl = {.kind=DEM_WALL_PLANE,.point={0,0,0},.normal={0,1,0},.contact=wc};
    dem_world_add_wall(w,&fl);
    double R=1e-3; dem_world_add_granule(w, dem_v3(0,1.05*R,0), dem_v3(0,-0.1,0), dem_v3(0,0,0), R, 1800);
    dem_world_prepare(w);
    double dt = dem_world_dt(w);
    dem_world_step(w, (uint64_t)(0.05/dt));
    dem_granules_view g = dem_world_granules(w);
    dem_stability st = dem_stability_apriori(w);
    printf("implicit %d damping %d: dt = %.3f dt_crit, e = %.4f\n", imp, mode, dt/st.dt_crit, g.velocity[0].y/0.1);
    dem_world_destroy(w);
  }
}
