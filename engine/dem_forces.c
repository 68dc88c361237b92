// SPDX-License-Identifier: MIT
// Forces and torques of a world's state: the pair loops (dem_pairs.c), then
// the walls (dem_wall_contacts.c); and the same split by thread blocks for
// the step team. See dem_forces_internal.h.
#include <math.h>

#include "dem_forces_internal.h"
#include "dem_implicit_internal.h"
#include "dem_pair_contact_internal.h"
#include "dem_pairs_internal.h"
#include "dem_threads_internal.h"
#include "dem_wall_contacts_internal.h"

int dem_forces_threaded(const dem_world *w) { return dem_threads_split(w->n, dem_world_team(w)); }

int dem_forces_blockwise(const dem_world *w)
{
    return contacts_batched(w->def.implicit_damping, w->implicit_springs);
}

size_t dem_forces_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows)
{
    return dem_pairs_crossing_rows(w, lo, hi, rows);
}

void dem_forces_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end)
{
    dem_pairs_crossing(w, rows, count, end);
}

void dem_forces_blocks_begin(dem_world *w) { dem_wall_contacts_begin(w); }

void dem_forces_block(dem_world *w, size_t lo, size_t hi)
{
    dem_pairs_block(w, lo, hi);
    dem_wall_contacts_block(w, lo, hi);
}

// One wrap gives a pair's minimum image if its separation along the
// periodic axis is shorter than one and a half periods; centres spanning at
// most 1.25 periods leave a margin no rounding can take away. A drift wraps
// every centre into the domain, one period.
#define DEM_ONE_WRAP_SPAN 1.25

void dem_forces_axis_extent(const dem_world *w, size_t lo, size_t hi, double *lowest, double *highest)
{
    const int a = w->def.periodic_axis;
    double low = INFINITY, high = -INFINITY; // no centre: spans nothing
    if (a >= 0)
        for (size_t i = lo; i < hi; ++i) {
            const double x = dem_v3_comp(w->pos[i], a);
            low = x < low ? x : low;
            high = x > high ? x : high;
        }
    *lowest = low;
    *highest = high;
}

int dem_forces_one_wrap(const dem_world *w, double lowest, double highest)
{
    return highest - lowest <= DEM_ONE_WRAP_SPAN * dem_world_period(w);
}

void dem_forces_compute(dem_world *w)
{
    double lowest, highest;
    dem_forces_axis_extent(w, 0, w->n, &lowest, &highest);
    dem_implicit_begin(w);
    dem_pairs_compute(w, (w->features & DEM_FEAT_PERIODIC) && !dem_forces_one_wrap(w, lowest, highest));
    dem_wall_contacts_compute(w);
}
