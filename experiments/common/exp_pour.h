// SPDX-License-Identifier: MIT
/// @file exp_pour.h
/// Pouring granules into a container, shared by the drum and the poured
/// cylinder: layers of granules on a lattice in the empty space above the
/// bed, each layer landing before the next; and running until at rest.
#ifndef EXP_POUR_H
#define EXP_POUR_H

#include <stddef.h>

#include "dem_gsd.h"
#include "dem_world.h"
#include "exp_common.h"

/// Where a poured layer may go: the lattice spans [lo, hi] (y up), and a
/// lattice point is used if `inside` says it lies in the container.
typedef struct exp_pour_region {
    dem_vec3 lo, hi;
    int (*inside)(dem_vec3 p, const void *ctx);
    const void *ctx;
} exp_pour_region;

/// Height below which 98 % of the granule tops lie (the bed surface,
/// ignoring a few bouncing granules); `floor_y` for an empty world.
double exp_bed_surface(const dem_world *w, double floor_y);

/// Place granules next.. of `diam` (diameters) on a lattice of `pitch` from
/// half a pitch above the bed surface up to region->hi.y, skipping points
/// outside the region or overlapping a granule already there. Returns how
/// many were placed (0: no room).
size_t exp_pour_layer(dem_world *w, const exp_pour_region *region, double floor_y, const double *diam, size_t next,
                      size_t n, double pitch, double density);

/// Place granules next.. of `diam` one by one at uniformly random points of
/// the region between the bed surface and height `top`, each where it
/// overlaps no granule (random sequential addition, in the order given, at
/// rest): a loose random packing (solid fraction about 0.3) that settles by
/// falling a fraction of its height, instead of layer after layer falling
/// from a lattice. A granule that finds no room in `tries` random points
/// ends the band. `seed` makes the points reproducible. Returns how many were
/// placed (0: no room).
size_t exp_pack_band(dem_world *w, const exp_pour_region *region, double floor_y, double top, const double *diam,
                     size_t next, size_t n, double density, unsigned long long seed, int tries);

/// Remove the granules whose centres lie above height y (a bed cut level).
void exp_remove_above(dem_world *w, double y);

/// Kinetic energy over (bed mass)·g·d50: the bed is at rest when small.
double exp_ke_ratio(const dem_world *w, double d50);

/// Run `seconds`, reporting progress every 0.01 s; non-zero on a fault.
int exp_run_for(dem_world *w, double seconds, exp_progress_fn progress, void *ctx, const char *phase);

/// Run until exp_ke_ratio < ratio, checked every `check_every` s, or
/// max_time; non-zero on an engine fault. A pour under a stronger gravity
/// lands a layer in milliseconds and checks more often than a drum's 0.05 s.
int exp_run_until_rest(dem_world *w, double d50, double ratio, double max_time, double check_every,
                       exp_progress_fn progress, void *ctx, const char *phase);

/// Pouring into an upright cylindrical container (axis y, floor y = 0) up to
/// its rim, as the lab fills the compression die and the poured cylinder.
typedef struct exp_rim_pour {
    const char *what;          ///< the experiment, for messages
    double radius, depth;      ///< container; the rim is at y = depth
    double headroom;           ///< the lattice reaches headroom × depth
    const dem_gsd *gsd;        ///< scaled GSD
    unsigned long long seed;
    double density;            ///< scaled density
    double layer_ke_ratio, layer_max_time, check_every; ///< when a layer has landed
} exp_rim_pour;

/// Pour layers until the bed surface passes the rim, then keep the granules
/// whose centres lie below it (the lab strikes the powder off at the rim).
/// 0, else 1 with a message.
int exp_pour_to_rim(dem_world *w, const exp_rim_pour *p, exp_progress_fn progress, void *ctx, char *err, size_t len);

#endif
