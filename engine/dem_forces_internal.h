// SPDX-License-Identifier: MIT
// Forces and torques of a world's current state: the granule–granule pair
// loops (dem_pairs.c) and the granule–wall contacts (dem_wall_contacts.c).
#ifndef DEM_FORCES_INTERNAL_H
#define DEM_FORCES_INTERNAL_H

#include "dem_state_internal.h"

// Every force and torque of the state (pairs and walls); with implicit
// springs the loops also hand each contact to the solve (dem_implicit.c).
void dem_forces_compute(dem_world *w);
// Whether the force evaluation and the step run on several threads.
int dem_forces_threaded(const dem_world *w);
// The force evaluation split by thread blocks, for the step loop that runs
// on a team of threads in one parallel region (dem_step.c): whether this
// world can be evaluated that way (the explicit integration); the rows of
// block [lo, hi) with a pair reaching past hi, into `rows` (their count); on
// any threads, dem_forces_crossing for such rows of a block ending at `end`
// (each row on one thread), computing those pairs into their slots; then a
// barrier, and on each thread dem_forces_block (the block's other pairs and
// its walls). Bitwise the same forces as dem_forces_compute. Before the
// first such evaluation, on one thread, dem_forces_blocks_begin.
int dem_forces_blockwise(const dem_world *w);
size_t dem_forces_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows);
void dem_forces_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end);
void dem_forces_block(dem_world *w, size_t lo, size_t hi);
void dem_forces_blocks_begin(dem_world *w);
// The lowest and highest centre of granules [lo, hi) along the periodic
// axis (+inf and −inf for none, or without the axis), and whether centres
// spanning [lowest, highest] there are near enough for one wrap to give
// every pair's minimum image.
// dem_forces_crossing and dem_forces_block take that as given: their caller
// checks it after each drift (dem_forces_compute checks it itself).
void dem_forces_axis_extent(const dem_world *w, size_t lo, size_t hi, double *lowest, double *highest);
int dem_forces_one_wrap(const dem_world *w, double lowest, double highest);

#endif
