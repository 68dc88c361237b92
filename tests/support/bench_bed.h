// SPDX-License-Identifier: MIT
/// @file bench_bed.h
/// The benchmarks' dense bed: n granules of the paper's GSD (median diameter
/// d50) on a lattice in a slab periodic along z, on a floor between two side
/// walls (k = 400 N/m, the granules' other contact parameters), then settled
/// for settle_s of simulated time. Exits on a world the engine refuses.
#ifndef BENCH_BED_H
#define BENCH_BED_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "dem_gsd.h"
#include "dem_world.h"

static inline dem_world *bench_settled_bed(dem_world_def def, int n, double width, double depth, double height,
                                           double d50, double settle_s)
{
    def.domain_lo = dem_v3(-width, -0.01, 0);
    def.domain_hi = dem_v3(width, height, depth);
    def.periodic_axis = 2;
    dem_world *w = dem_world_create(&def, NULL, 0);
    dem_contact_params wall = def.granule;
    wall.k_n = wall.k_s = wall.k_r = 400;
    dem_wall_def planes[3] = {{.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .contact = wall},
                              {.kind = DEM_WALL_PLANE, .point = {-width / 2, 0, 0}, .normal = {1, 0, 0}, .contact = wall},
                              {.kind = DEM_WALL_PLANE, .point = {width / 2, 0, 0}, .normal = {-1, 0, 0}, .contact = wall}};
    for (int k = 0; k < 3; ++k) dem_world_add_wall(w, &planes[k]);
    dem_gsd g = dem_default_gsd();
    g.median_diameter = d50;
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
    dem_world_step(w, (uint64_t)(settle_s / dem_world_dt(w)));
    return w;
}

#endif
