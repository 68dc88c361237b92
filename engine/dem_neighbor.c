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

#include "dem_memory_internal.h"
#include "dem_neighbor_internal.h"
#include "dem_threads_internal.h"

// Upper bound on cells so a granule flung far away cannot make the grid huge.
#define MAX_CELLS_PER_GRANULE 4

typedef struct cell_grid {
    int nc[3];
    double lo[3], size[3];
    size_t *head;  // ncells + 1 offsets into `order`
    uint32_t *order;
} cell_grid;

static void grid_dims(size_t n, const dem_domain *dom, double cutoff, cell_grid *g)
{
    size_t budget = (n + 1) * MAX_CELLS_PER_GRANULE;
    double span[3];
    for (int a = 0; a < 3; ++a) {
        g->lo[a] = dem_v3_comp(dom->lo, a);
        span[a] = dem_v3_comp(dom->hi, a) - g->lo[a];
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
static int grid_fill(const dem_nl_granules *gr, cell_grid *g)
{
    size_t ncell = (size_t)g->nc[0] * g->nc[1] * g->nc[2];
    g->head = calloc(ncell + 1, sizeof *g->head);
    g->order = malloc((gr->n + 1) * sizeof *g->order);
    size_t *slot = malloc((gr->n + 1) * sizeof *slot);
    if (!g->head || !g->order || !slot) {
        free(slot);
        return 1;
    }
    for (size_t i = 0; i < gr->n; ++i) g->head[(slot[i] = cell_of(g, gr->pos[i])) + 1]++;
    for (size_t c = 0; c < ncell; ++c) g->head[c + 1] += g->head[c];
    size_t *fill = malloc((ncell + 1) * sizeof *fill);
    if (!fill) {
        free(slot);
        return 1;
    }
    memcpy(fill, g->head, (ncell + 1) * sizeof *fill);
    for (size_t i = 0; i < gr->n; ++i) g->order[fill[slot[i]]++] = (uint32_t)i;
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
static size_t scan_row(const dem_nl_granules *gr, const dem_domain *dom, double skin, const cell_grid *g, size_t i,
                       uint32_t *out)
{
    dem_vec3 p = gr->pos[i];
    int c[3] = {cell_coord(g, p.x, 0), cell_coord(g, p.y, 1), cell_coord(g, p.z, 2)};
    size_t cells[27];
    int nc = neighbor_cells(g, dom->axis, c, cells);
    size_t count = 0;
    for (int k = 0; k < nc; ++k)
        for (size_t s = g->head[cells[k]]; s < g->head[cells[k] + 1]; ++s) {
            uint32_t j = g->order[s];
            if (j <= i) continue;
            double reach = gr->rad[i] + gr->rad[j] + skin;
            dem_vec3 d = dem_domain_min_image(dom, dem_v3_sub(gr->pos[j], p));
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
static dem_pair_constants pair_constants(const dem_nl_granules *g, size_t i, size_t j)
{
    const double ri = g->rad[i], rj = g->rad[j];
    return (dem_pair_constants){sqrt(1.0 / (g->inv_mass[i] + g->inv_mass[j])), ri * rj / (ri + rj)};
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

// Room for `pairs` pairs and their history.
static int ensure_pairs(dem_neighbor_list *nl, size_t pairs)
{
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
    return 0;
}

int dem_nl_reverse(const dem_neighbor_list *nl, size_t n, size_t **rev_start, size_t *rev_pair)
{
    size_t *start = realloc(*rev_start, (n + 1) * sizeof *start);
    if (!start) return 1;
    *rev_start = start;
    memset(start, 0, (n + 1) * sizeof *start);
    for (size_t k = 0; k < nl->count; ++k) start[nl->j[k] + 1]++;
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    size_t *fill = malloc((n + 1) * sizeof *fill);
    if (!fill) return 1;
    memcpy(fill, start, (n + 1) * sizeof *fill);
    for (size_t i = 0; i < n; ++i)
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; ++k) rev_pair[fill[nl->j[k]]++] = k;
    free(fill);
    return 0;
}

static double max_radius(const dem_nl_granules *g)
{
    double r = 0.0;
    for (size_t i = 0; i < g->n; ++i) r = g->rad[i] > r ? g->rad[i] : r;
    return r;
}

int dem_nl_rebuild(dem_neighbor_list *nl, const dem_neighbor_list *old, size_t old_rows, const dem_nl_granules *gr,
                   const dem_domain *dom, double skin, int threads)
{
    const size_t n = gr->n;
    size_t *start = realloc(nl->start, (n + 1) * sizeof *start);
    if (!start) return DEM_NL_NOMEM;
    nl->start = start;
    nl->rows = n;
    cell_grid g = {0};
    double cutoff = 2.0 * max_radius(gr) + skin;
    grid_dims(n, dom, cutoff, &g);
    if (grid_fill(gr, &g)) {
        free(g.head);
        free(g.order);
        return DEM_NL_NOMEM_GRID;
    }
    start[0] = 0;
#pragma omp parallel for schedule(static) if (n >= DEM_OMP_MIN_GRANULES) num_threads(threads)
    for (size_t i = 0; i < n; ++i) start[i + 1] = scan_row(gr, dom, skin, &g, i, NULL);
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    nl->count = start[n];
    int fail = ensure_pairs(nl, nl->count);
    if (!fail) {
#pragma omp parallel for schedule(static) if (n >= DEM_OMP_MIN_GRANULES) num_threads(threads)
        for (size_t i = 0; i < n; ++i) {
            scan_row(gr, dom, skin, &g, i, nl->j + start[i]);
            sort_row(nl->j + start[i], start[i + 1] - start[i]);
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                nl->row[k] = (uint32_t)i;
                nl->constants[k] = pair_constants(gr, i, nl->j[k]);
            }
            carry_history(nl, old, old_rows, i);
        }
    }
    free(g.head);
    free(g.order);
    return fail ? DEM_NL_NOMEM : DEM_NL_OK;
}

double dem_nl_max_displacement2_range(const dem_domain *dom, const dem_vec3 *pos, const dem_vec3 *pos_at_build,
                                      size_t lo, size_t hi)
{
    double m = 0;
    for (size_t i = lo; i < hi; ++i) {
        const double d2 = dem_v3_norm2(dem_domain_min_image(dom, dem_v3_sub(pos[i], pos_at_build[i])));
        m = d2 > m ? d2 : m;
    }
    return m;
}

double dem_nl_max_displacement2(const dem_domain *dom, const dem_vec3 *pos, const dem_vec3 *pos_at_build, size_t n,
                                int threads)
{
    double m = 0;
#pragma omp parallel reduction(max : m) if (n >= DEM_OMP_MIN_GRANULES) num_threads(threads)
    {
        size_t lo, hi;
        dem_thread_block(n, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        m = dem_nl_max_displacement2_range(dom, pos, pos_at_build, lo, hi);
    }
    return m;
}

void dem_nl_clone(dem_neighbor_list *dst, const dem_neighbor_list *src, int *fail)
{
    *dst = *src;
    dst->start = dem_dup_bytes(src->start, src->start ? (src->rows + 1) * sizeof *src->start : 0, fail);
    dst->j = dem_dup_bytes(src->j, src->cap * sizeof *src->j, fail);
    dst->row = dem_dup_bytes(src->row, src->cap * sizeof *src->row, fail);
    dst->constants = dem_dup_bytes(src->constants, src->cap * sizeof *src->constants, fail);
    dst->hist = dem_dup_bytes(src->hist, src->hist_cap * sizeof *src->hist, fail);
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
