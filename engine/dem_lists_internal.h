// SPDX-License-Identifier: MIT
// A world's lists kept up to date: its neighbour list (with the history
// carried over and the per-pair scratch of the pair loops sized to it) and
// its walls' near lists, rebuilt together when a granule has moved half a
// skin.
#ifndef DEM_LISTS_INTERNAL_H
#define DEM_LISTS_INTERNAL_H

#include "dem_state_internal.h"

// Rebuild every list now; 0, or 1 out of memory (message set).
int dem_lists_rebuild(dem_world *w);
// Rebuild if the lists are not valid or a granule or a wall moved more than
// half the skin since they were built; 0, or 1 out of memory.
int dem_lists_refresh(dem_world *w);
// Whether a wall has moved more than half the skin since the last rebuild.
int dem_lists_walls_moved(const dem_world *w);

// The largest squared displacement since the last rebuild over granules
// [lo, hi), for a caller already on a thread.
static inline double dem_lists_displacement2_range(const dem_world *w, size_t lo, size_t hi)
{
    const dem_domain dom = dem_world_domain(w);
    return dem_nl_max_displacement2_range(&dom, w->pos, w->pos_at_build, lo, hi);
}

#endif
