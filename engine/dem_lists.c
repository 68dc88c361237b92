// SPDX-License-Identifier: MIT
// A world's neighbour and wall lists; see dem_lists_internal.h.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_lists_internal.h"

// With DEM_POISON_SCRATCH (CMake GRANUCAL_POISON_SCRATCH, on in the
// sanitizer build CI runs), fresh per-pair scratch starts as NaN, not as
// whatever the allocator returned: every evaluation must write a pair's
// entries before anything reads them, and a path that does not (an open
// pair's normal was once left unwritten under the implicit dashpot, and
// 0 × a stale NaN made a granule non-finite only when the heap happened to
// hold one) then fails at once, named by the engine's non-finite check,
// instead of by chance. Off otherwise: the fill touches every page of
// scratch the explicit integration never uses.
static void poison_pair_scratch(dem_world *w, size_t from, size_t to)
{
#ifdef DEM_POISON_SCRATCH
    const double nan = NAN;
    const dem_vec3 nan3 = dem_v3(nan, nan, nan);
    for (size_t k = from; k < to; ++k) {
        w->pair_f[k] = w->pair_ti[k] = w->pair_tj[k] = w->pair_n[k] = nan3;
        w->pair_g[k] = nan;
    }
#else
    (void)w, (void)from, (void)to;
#endif
}

// The pair loops' per-pair scratch and the reverse index, as many pairs as
// the neighbour list has room for.
static int ensure_pair_scratch(dem_world *w)
{
    if (w->nl.count <= w->pair_cap) return 0;
    size_t cap = w->nl.cap;
    dem_vec3 *f = realloc(w->pair_f, cap * sizeof *f), *ti = NULL, *tj = NULL;
    if (f) w->pair_f = f;
    if (f) ti = realloc(w->pair_ti, cap * sizeof *ti);
    if (ti) w->pair_ti = ti;
    if (ti) tj = realloc(w->pair_tj, cap * sizeof *tj);
    if (tj) w->pair_tj = tj;
    size_t *rp = tj ? realloc(w->rev_pair, cap * sizeof *rp) : NULL;
    if (rp) w->rev_pair = rp;
    dem_vec3 *pn = rp ? realloc(w->pair_n, cap * sizeof *pn) : NULL;
    if (pn) w->pair_n = pn;
    double *pg = pn ? realloc(w->pair_g, cap * sizeof *pg) : NULL;
    if (pg) w->pair_g = pg;
    if (!pg) return 1;
    poison_pair_scratch(w, w->pair_cap, cap);
    w->pair_cap = cap;
    return 0;
}

// The current list becomes the source of carried history.
static void swap_lists(dem_world *w)
{
    dem_neighbor_list t = w->nl;
    w->nl = w->nl_old;
    w->nl_old = t;
    w->nl.hist_len = dem_history_len(w->features); // the old list keeps its own layout
}

static int build_wall_lists(dem_world *w)
{
    for (int k = 0; k < w->n_walls; ++k)
        if (dem_wall_near_rebuild(&w->walls[k], w->n, w->pos, w->rad, w->skin)) return 1;
    return 0;
}

int dem_lists_rebuild(dem_world *w)
{
    const size_t n = w->n, old_rows = w->list_valid ? n : 0;
    swap_lists(w);
    const dem_nl_granules g = {n, w->pos, w->rad, w->inv_mass};
    const dem_domain dom = dem_world_domain(w);
    const int nl = dem_nl_rebuild(&w->nl, &w->nl_old, old_rows, &g, &dom, w->skin, dem_world_team(w));
    if (nl == DEM_NL_NOMEM_GRID) return dem_world_set_error(w, "out of memory building the cell grid");
    if (nl != DEM_NL_OK || ensure_pair_scratch(w) || dem_nl_reverse(&w->nl, n, &w->rev_start, w->rev_pair) ||
        build_wall_lists(w))
        return dem_world_set_error(w, "out of memory building the neighbour list");
    memcpy(w->pos_at_build, w->pos, n * sizeof *w->pos);
    w->list_valid = 1;
    w->rebuilds++;
    return 0;
}

int dem_lists_walls_moved(const dem_world *w)
{
    const double half_skin = 0.5 * w->skin;
    for (int k = 0; k < w->n_walls; ++k)
        if (dem_wall_travel2(&w->walls[k]) > half_skin * half_skin) return 1;
    return 0;
}

int dem_lists_refresh(dem_world *w)
{
    const double half_skin = 0.5 * w->skin;
    const dem_domain dom = dem_world_domain(w);
    if (w->list_valid && !dem_lists_walls_moved(w) &&
        dem_nl_max_displacement2(&dom, w->pos, w->pos_at_build, w->n, dem_world_team(w)) <= half_skin * half_skin)
        return 0;
    return dem_lists_rebuild(w); // also the walls' near lists (a wall added since unprepares the world)
}
