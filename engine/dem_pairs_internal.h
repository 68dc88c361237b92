// SPDX-License-Identifier: MIT
// The granule–granule pair loops (dem_pairs.c): every listed pair's contact,
// added to both granules in the serial order on any number of threads.
#ifndef DEM_PAIRS_INTERNAL_H
#define DEM_PAIRS_INTERNAL_H

#include "dem_state_internal.h"

// Every pair, forces and torques zeroed first; general_image: some centres
// may lie more than one wrap apart along the periodic axis. With the implicit
// dashpot, each granule's Σγ n nᵀ too.
void dem_pairs_compute(dem_world *w, int general_image);
// The step team's pieces (see dem_forces_blockwise): the rows of block
// [lo, hi) with a pair reaching past hi; such rows' pairs into their slots;
// the block's own pairs, with the slots added in the serial order.
size_t dem_pairs_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows);
void dem_pairs_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end);
void dem_pairs_block(dem_world *w, size_t lo, size_t hi);

#endif
