// SPDX-License-Identifier: MIT
// The periodic domain: the box granules must stay in, and at most one axis
// along which it wraps. Below the neighbour list and the pair loops, which
// both need a pair's minimum image.
#ifndef DEM_DOMAIN_INTERNAL_H
#define DEM_DOMAIN_INTERNAL_H

#include <math.h>

#include "dem_vec.h"

typedef struct dem_domain {
    dem_vec3 lo, hi;
    int axis;      // periodic axis, or −1
    double period; // length along the periodic axis (0 if none)
} dem_domain;

static inline dem_domain dem_domain_make(dem_vec3 lo, dem_vec3 hi, int axis)
{
    return (dem_domain){lo, hi, axis, axis < 0 ? 0.0 : dem_v3_comp(hi, axis) - dem_v3_comp(lo, axis)};
}

// Minimum image of a separation d: the general rule, for any distance.
static inline dem_vec3 dem_domain_min_image(const dem_domain *dom, dem_vec3 d)
{
    const int a = dom->axis;
    if (a < 0) return d;
    const double len = dom->period;
    double *c = a == 0 ? &d.x : a == 1 ? &d.y : &d.z;
    *c -= len * nearbyint(*c / len);
    return d;
}

#endif
