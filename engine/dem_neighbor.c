// SPDX-License-Identifier: MIT
// Linked-cell Verlet neighbour list with a skin: O(N) per rebuild, rebuilt
// only when some granule has moved more than half the skin. Rows are sorted
// by partner index so forces never depend on the order cells are visited,
// and contact history is carried from the old list to the new by merging
// sorted rows.
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "dem_world_internal.h"

// Upper bound on cells so a granule flung far away cannot make the grid huge.
#define MAX_CELLS_PER_GRANULE 4

typedef struct cell_grid {
    int nc[3];
    double lo[3], size[3];
    size_t *head;  // ncells + 1 offsets into `order`
    uint32_t *order;
} cell_grid;

dem_vec3 dem_world_min_image(const dem_world *w, dem_vec3 d)
{
    int a = w->def.periodic_axis;
    if (a < 0) return d;
    double len = dem_world_period(w);
    double *c = a == 0 ? &d.x : a == 1 ? &d.y : &d.z;
    *c -= len * nearbyint(*c / len);
    return d;
}

static void grid_dims(const dem_world *w, double cutoff, cell_grid *g)
{
    size_t budget = (w->n + 1) * MAX_CELLS_PER_GRANULE;
    double span[3];
    for (int a = 0; a < 3; ++a) {
        g->lo[a] = dem_v3_comp(w->def.domain_lo, a);
        span[a] = dem_v3_comp(w->def.domain_hi, a) - g->lo[a];
    }
    double cs = cutoff;
    for (;;) {
        size_t total = 1;
        for (int a = 0; a < 3; ++a) {
            double m = floor(span[a] / cs);
            g->nc[a] = m < 1 ? 1 : (int)(m > 1e6 ? 1e6 : m);
            total *= (size_t)g->nc[a];
        }
        if (total <= budget || total < 64) break;
        cs *= 1.26; // coarser cells: still correct, only more candidates
    }
    for (int a = 0; a < 3; ++a) g->size[a] = span[a] / g->nc[a];
}

static int cell_coord(const cell_grid *g, double x, int a)
{
    int c = (int)floor((x - g->lo[a]) / g->size[a]);
    return c < 0 ? 0 : c >= g->nc[a] ? g->nc[a] - 1 : c; // escaped granules go to edge cells
}

static size_t cell_of(const cell_grid *g, dem_vec3 p)
{
    int cx = cell_coord(g, p.x, 0), cy = cell_coord(g, p.y, 1), cz = cell_coord(g, p.z, 2);
    return ((size_t)cz * g->nc[1] + cy) * g->nc[0] + cx;
}

// Counting sort of granules into cells, in index order: deterministic.
static int grid_fill(const dem_world *w, cell_grid *g)
{
    size_t ncell = (size_t)g->nc[0] * g->nc[1] * g->nc[2];
    g->head = calloc(ncell + 1, sizeof *g->head);
    g->order = malloc((w->n + 1) * sizeof *g->order);
    size_t *slot = malloc((w->n + 1) * sizeof *slot);
    if (!g->head || !g->order || !slot) {
        free(slot);
        return 1;
    }
    for (size_t i = 0; i < w->n; ++i) g->head[(slot[i] = cell_of(g, w->pos[i])) + 1]++;
    for (size_t c = 0; c < ncell; ++c) g->head[c + 1] += g->head[c];
    size_t *fill = malloc((ncell + 1) * sizeof *fill);
    if (!fill) {
        free(slot);
        return 1;
    }
    memcpy(fill, g->head, (ncell + 1) * sizeof *fill);
    for (size_t i = 0; i < w->n; ++i) g->order[fill[slot[i]]++] = (uint32_t)i;
    free(fill);
    free(slot);
    return 0;
}

// Distinct neighbour cells of cell (cx,cy,cz), wrapping the periodic axis;
// returns their count (≤ 27). Duplicates arise when a periodic axis has
// fewer than three cells and must not be visited twice.
static int neighbor_cells(const cell_grid *g, int periodic_axis, const int c[3], size_t out[27])
{
    int count = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int d[3] = {dx, dy, dz}, q[3];
                int ok = 1;
                for (int a = 0; a < 3 && ok; ++a) {
                    q[a] = c[a] + d[a];
                    if (a == periodic_axis) q[a] = (q[a] + g->nc[a]) % g->nc[a];
                    else if (q[a] < 0 || q[a] >= g->nc[a]) ok = 0;
                }
                if (!ok) continue;
                size_t idx = ((size_t)q[2] * g->nc[1] + q[1]) * g->nc[0] + q[0];
                int dup = 0;
                for (int k = 0; k < count; ++k) dup |= out[k] == idx;
                if (!dup) out[count++] = idx;
            }
    return count;
}

// Visit the candidate partners j > i of granule i; with `out` NULL only count.
static size_t scan_row(const dem_world *w, const cell_grid *g, size_t i, uint32_t *out)
{
    dem_vec3 p = w->pos[i];
    int c[3] = {cell_coord(g, p.x, 0), cell_coord(g, p.y, 1), cell_coord(g, p.z, 2)};
    size_t cells[27];
    int nc = neighbor_cells(g, w->def.periodic_axis, c, cells);
    size_t count = 0;
    for (int k = 0; k < nc; ++k)
        for (size_t s = g->head[cells[k]]; s < g->head[cells[k] + 1]; ++s) {
            uint32_t j = g->order[s];
            if (j <= i) continue;
            double reach = w->rad[i] + w->rad[j] + w->skin;
            dem_vec3 d = dem_world_min_image(w, dem_v3_sub(w->pos[j], p));
            if (dem_v3_norm2(d) < reach * reach) {
                if (out) out[count] = j;
                count++;
            }
        }
    return count;
}

// The constants of pair (i, j), in the arithmetic the contact law had
// (m* = 1 / (1/m_i + 1/m_j), R* = R_i R_j / (R_i + R_j)): symmetric in i and j
// bit for bit, so a pair's roles may swap.
static dem_pair_constants pair_constants(const dem_world *w, size_t i, size_t j)
{
    const double ri = w->rad[i], rj = w->rad[j];
    return (dem_pair_constants){sqrt(1.0 / (w->inv_mass[i] + w->inv_mass[j])), ri * rj / (ri + rj)};
}

static void sort_row(uint32_t *a, size_t n)
{
    for (size_t i = 1; i < n; ++i) { // rows are short: insertion sort
        uint32_t v = a[i];
        size_t k = i;
        for (; k > 0 && a[k - 1] > v; --k) a[k] = a[k - 1];
        a[k] = v;
    }
}

// Copy each surviving pair's history from the old list (rows sorted: merge).
static void carry_history(dem_neighbor_list *nw, const dem_neighbor_list *old, size_t n_old_rows, size_t i)
{
    int hl = nw->hist_len;
    size_t k = nw->start[i], kend = nw->start[i + 1];
    if (kend == k || hl == 0) return; // no pairs or no history: nothing to carry (hist may be NULL)
    memset(nw->hist + k * hl, 0, (kend - k) * hl * sizeof(double));
    if (!old->start || i >= n_old_rows || old->hist_len != hl || hl == 0) return;
    size_t o = old->start[i], oend = old->start[i + 1];
    while (k < kend && o < oend) {
        if (old->j[o] < nw->j[k]) o++;
        else if (old->j[o] > nw->j[k]) k++;
        else memcpy(nw->hist + k++ * hl, old->hist + o++ * hl, hl * sizeof(double));
    }
}

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

static int ensure_pairs(dem_world *w, size_t pairs)
{
    dem_neighbor_list *nl = &w->nl;
    size_t hl = (size_t)(nl->hist_len ? nl->hist_len : 1);
    if (pairs > nl->cap || pairs * hl > nl->hist_cap) {
        size_t cap = pairs + pairs / 4 + 16;
        uint32_t *j = realloc(nl->j, cap * sizeof *j);
        if (j) nl->j = j;
        uint32_t *row = j ? realloc(nl->row, cap * sizeof *row) : NULL;
        if (row) nl->row = row;
        dem_pair_constants *pc = row ? realloc(nl->constants, cap * sizeof *pc) : NULL;
        if (pc) nl->constants = pc;
        double *h = pc ? realloc(nl->hist, cap * hl * sizeof *h) : NULL;
        if (h) nl->hist = h;
        if (!h) return 1;
        nl->cap = cap;
        nl->hist_cap = cap * hl;
    }
    if (pairs > w->pair_cap) {
        size_t cap = nl->cap;
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
    }
    return 0;
}

static int build_reverse(dem_world *w)
{
    size_t n = w->n;
    size_t *start = realloc(w->rev_start, (n + 1) * sizeof *start);
    if (!start) return 1;
    w->rev_start = start;
    memset(start, 0, (n + 1) * sizeof *start);
    for (size_t k = 0; k < w->nl.count; ++k) start[w->nl.j[k] + 1]++;
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    size_t *fill = malloc((n + 1) * sizeof *fill);
    if (!fill) return 1;
    memcpy(fill, start, (n + 1) * sizeof *fill);
    for (size_t i = 0; i < n; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) w->rev_pair[fill[w->nl.j[k]]++] = k;
    free(fill);
    return 0;
}

static void swap_lists(dem_world *w)
{
    dem_neighbor_list t = w->nl;
    w->nl = w->nl_old;
    w->nl_old = t;
    w->nl.hist_len = dem_history_len(w->features); // the old list keeps its own layout
}

// A granule is near a wall if a sphere one skin larger would touch it (for a
// disc, one skin wider too: a granule may slide in over its rim). The others
// cannot reach the wall before the next rebuild; their springs are open, and
// are cleared here so the wall loop need not visit them.
static int build_wall_list(dem_world *w, dem_wall *wall)
{
    dem_wall_def grown = wall->def;
    if (grown.kind == DEM_WALL_DISC) grown.radius += w->skin;
    if (wall->near_cap < w->n) {
        uint32_t *p = realloc(wall->near, (w->n ? w->n : 1) * sizeof *p);
        if (!p) return 1;
        wall->near = p;
        wall->near_cap = w->n;
    }
    const size_t hl = (size_t)wall->hist_len;
    size_t count = 0;
    for (size_t i = 0; i < w->n; ++i) {
        if (dem_wall_geometry(&grown, w->pos[i], w->rad[i] + w->skin).overlap > 0.0) wall->near[count++] = (uint32_t)i;
        else if (hl) memset(wall->hist + i * hl, 0, hl * sizeof(double));
    }
    wall->near_count = count;
    return 0;
}

static int build_wall_lists(dem_world *w)
{
    for (int k = 0; k < w->n_walls; ++k)
        if (build_wall_list(w, &w->walls[k])) return 1;
    return 0;
}

int dem_nl_rebuild(dem_world *w)
{
    size_t n = w->n;
    size_t old_rows = w->list_valid ? n : 0;
    swap_lists(w); // the current list becomes the source of carried history
    dem_neighbor_list *nl = &w->nl;
    size_t *start = realloc(nl->start, (n + 1) * sizeof *start);
    if (!start) return dem_world_set_error(w, "out of memory building the neighbour list");
    nl->start = start;
    nl->rows = n;
    cell_grid g = {0};
    double cutoff = 2.0 * dem_world_max_radius(w) + w->skin;
    grid_dims(w, cutoff, &g);
    if (grid_fill(w, &g)) {
        free(g.head);
        free(g.order);
        return dem_world_set_error(w, "out of memory building the cell grid");
    }
    start[0] = 0;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
    for (size_t i = 0; i < n; ++i) start[i + 1] = scan_row(w, &g, i, NULL);
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    nl->count = start[n];
    int fail = ensure_pairs(w, nl->count);
    if (!fail) {
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
        for (size_t i = 0; i < n; ++i) {
            scan_row(w, &g, i, nl->j + start[i]);
            sort_row(nl->j + start[i], start[i + 1] - start[i]);
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                nl->row[k] = (uint32_t)i;
                nl->constants[k] = pair_constants(w, i, nl->j[k]);
            }
            carry_history(nl, &w->nl_old, old_rows, i);
        }
        fail = build_reverse(w);
    }
    free(g.head);
    free(g.order);
    if (fail || build_wall_lists(w)) return dem_world_set_error(w, "out of memory building the neighbour list");
    memcpy(w->pos_at_build, w->pos, n * sizeof *w->pos);
    w->list_valid = 1;
    w->rebuilds++;
    return 0;
}

double dem_nl_max_displacement2_range(const dem_world *w, size_t lo, size_t hi)
{
    double m = 0;
    for (size_t i = lo; i < hi; ++i) {
        const double d2 = dem_v3_norm2(dem_world_min_image(w, dem_v3_sub(w->pos[i], w->pos_at_build[i])));
        m = d2 > m ? d2 : m;
    }
    return m;
}

double dem_nl_max_displacement2(const dem_world *w)
{
    double m = 0;
#pragma omp parallel reduction(max : m) if (w->n >= DEM_OMP_MIN_GRANULES)
    {
        size_t lo, hi;
        dem_thread_block(w->n, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        m = dem_nl_max_displacement2_range(w, lo, hi);
    }
    return m;
}

void dem_nl_free(dem_neighbor_list *nl)
{
    free(nl->start);
    free(nl->j);
    free(nl->row);
    free(nl->constants);
    free(nl->hist);
    memset(nl, 0, sizeof *nl);
}
