// SPDX-License-Identifier: MIT
// Linked-cell Verlet neighbour list over plain arrays of granules: it knows
// positions, radii and masses, a periodic domain and a skin, not the world.
#ifndef DEM_NEIGHBOR_INTERNAL_H
#define DEM_NEIGHBOR_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "dem_domain_internal.h"

// What a pair's contact law needs of its two granules' sizes and masses:
// sqrt(m*) for the dashpot of eq. 4, and R* for the rolling spring of eq. 12
// and the torque of eq. 10. They change only with the granules, so they are
// computed when the list is built, not at every contact and step: two
// divisions and a square root fewer per contact, in a batch kernel whose
// time goes mostly to waiting on its divider (measured, 1.034x the step at
// N = 20 000, median of 10 interleaved rounds, 16 bytes per listed pair).
typedef struct dem_pair_constants {
    double root_reduced_mass, reduced_radius;
} dem_pair_constants;

// Half neighbour list in CSR form: row i holds the j > i within
// R_i + R_j + skin, sorted by j, with each pair's history next to it.
typedef struct dem_neighbor_list {
    size_t *start;   // n + 1 row offsets
    uint32_t *j;     // partner of each pair
    uint32_t *row;   // row of each pair (its granule i): pair loops walk pieces of pairs across rows
    dem_pair_constants *constants; // of each pair
    double *hist;    // hist_len doubles per pair
    size_t count, cap;
    size_t hist_cap; // doubles allocated in hist
    size_t rows;     // granules the list was built for (start has rows + 1)
    int hist_len;
} dem_neighbor_list;

// The granules a list is built for.
typedef struct dem_nl_granules {
    size_t n;
    const dem_vec3 *pos;
    const double *rad, *inv_mass;
} dem_nl_granules;

// What can stop a rebuild.
enum { DEM_NL_OK = 0, DEM_NL_NOMEM = 1, DEM_NL_NOMEM_GRID = 2 };

// Rebuild `nl` (its hist_len set by the caller) for granules g in domain dom
// with the given skin, on a team of `threads`, carrying each surviving pair's history from `old`
// (built for old_rows granules; 0: nothing to carry). Its capacity grows as
// needed (nl->cap pairs). DEM_NL_OK or a DEM_NL_NOMEM*.
int dem_nl_rebuild(dem_neighbor_list *nl, const dem_neighbor_list *old, size_t old_rows, const dem_nl_granules *g,
                   const dem_domain *dom, double skin, int threads);
// The reverse index of the list over n granules: for each granule, the pairs
// in which it is j, ascending (rev_start: n + 1 offsets, reallocated;
// rev_pair: nl->count entries, of the caller's). 0, or 1 out of memory.
int dem_nl_reverse(const dem_neighbor_list *nl, size_t n, size_t **rev_start, size_t *rev_pair);
// The largest squared displacement of pos from pos_at_build over granules
// [lo, hi) (minimum image), for a caller already on a thread; and over all n
// on a team of `threads`.
double dem_nl_max_displacement2_range(const dem_domain *dom, const dem_vec3 *pos, const dem_vec3 *pos_at_build,
                                      size_t lo, size_t hi);
double dem_nl_max_displacement2(const dem_domain *dom, const dem_vec3 *pos, const dem_vec3 *pos_at_build, size_t n,
                                int threads);
// A deep copy of src into dst (*fail set on out of memory).
void dem_nl_clone(dem_neighbor_list *dst, const dem_neighbor_list *src, int *fail);
void dem_nl_free(dem_neighbor_list *nl);

#endif
