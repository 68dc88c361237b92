// SPDX-License-Identifier: MIT
// Granule–wall contacts (dem_wall_contacts.c), added to the forces and
// torques the pair loops left.
#ifndef DEM_WALL_CONTACTS_INTERNAL_H
#define DEM_WALL_CONTACTS_INTERNAL_H

#include "dem_state_internal.h"

// Every wall against the granules near it.
void dem_wall_contacts_compute(dem_world *w);
// The same for the near granules in [lo, hi) only (one thread's block).
// The blocks of one evaluation follow one dem_wall_contacts_begin, on one
// thread before them: the walls' kept forces (dem_wall.force) are then the
// evaluation's alone.
void dem_wall_contacts_block(dem_world *w, size_t lo, size_t hi);
void dem_wall_contacts_begin(dem_world *w);

#endif
