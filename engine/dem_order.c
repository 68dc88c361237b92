// SPDX-License-Identifier: MIT
// Spatial ordering of the granules: sorted along a Morton (Z-order) curve of
// cells one granule-neighbourhood wide, granules that touch sit close in
// memory, so the force loop reads its partners from cache at any N instead of
// from main memory (a bed built by pouring or by repeating a slab is in
// placement order, random in space at the scale of a cache line).
#include <stdlib.h>
#include <string.h>

#include "dem_lists_internal.h"

#define MORTON_BITS 21 // per axis: 63 bits of key

typedef struct order_key {
    uint64_t key;
    uint32_t index;
} order_key;

// Spread the low 21 bits of x to every third bit.
static uint64_t spread3(uint64_t x)
{
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}

static uint64_t cell_coordinate(double x, double lo, double cell)
{
    double c = floor((x - lo) / cell);
    const double top = (double)((1u << MORTON_BITS) - 1);
    return (uint64_t)(c < 0 ? 0 : c > top ? top : c);
}

static int compare_keys(const void *a, const void *b)
{
    const order_key *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index; // ties in index order: deterministic
}

// a[new] = a[perm[new]] for n elements of `size` bytes, through tmp.
static void permute(void *a, size_t size, const uint32_t *perm, size_t n, unsigned char *tmp)
{
    if (!a) return;
    unsigned char *base = a;
    for (size_t i = 0; i < n; ++i) memcpy(tmp + i * size, base + (size_t)perm[i] * size, size);
    memcpy(base, tmp, n * size);
}

static void permute_granules(dem_world *w, const uint32_t *perm, unsigned char *tmp)
{
    const size_t n = w->n, v3 = sizeof(dem_vec3), d = sizeof(double);
    dem_vec3 *vec[] = {w->pos, w->vel, w->omg, w->frc, w->trq, w->pos_at_build};
    double *scalar[] = {w->rad, w->mass, w->inertia, w->inv_mass, w->inv_inertia};
    for (size_t k = 0; k < sizeof vec / sizeof *vec; ++k) permute(vec[k], v3, perm, n, tmp);
    for (size_t k = 0; k < sizeof scalar / sizeof *scalar; ++k) permute(scalar[k], d, perm, n, tmp);
    permute(w->id, sizeof *w->id, perm, n, tmp);
    permute(w->fixed, sizeof *w->fixed, perm, n, tmp);
    permute(w->acc, 6 * d, perm, n, tmp);
    permute(w->damp, 6 * d, perm, n, tmp);
    for (int k = 0; k < w->n_walls; ++k)
        if (w->walls[k].hist_len) permute(w->walls[k].hist, (size_t)w->walls[k].hist_len * d, perm, n, tmp);
}

// Rewrite the current neighbour list in the new indices (each pair as
// (min, max), rows sorted by partner) so the rebuild that follows carries
// every spring's history by its usual merge. 1 on out-of-memory.
static int renumber_list(dem_world *w, const uint32_t *inv)
{
    dem_neighbor_list *nl = &w->nl;
    const size_t n = w->n, count = nl->count, hl = (size_t)nl->hist_len, doubles = count * hl;
    size_t *start = calloc(n + 2, sizeof *start), *fill = malloc((n + 1) * sizeof *fill);
    uint32_t *j = malloc((count ? count : 1) * sizeof *j);
    double *hist = malloc((doubles ? doubles : 1) * sizeof *hist);
    if (!start || !fill || !j || !hist) return free(start), free(fill), free(j), free(hist), 1;
    for (size_t i = 0; i < n; ++i)
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; ++k) {
            uint32_t a = inv[i], b = inv[nl->j[k]];
            start[(a < b ? a : b) + 1]++;
        }
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    memcpy(fill, start, (n + 1) * sizeof *fill);
    for (size_t i = 0; i < n; ++i)
        for (size_t k = nl->start[i]; k < nl->start[i + 1]; ++k) {
            uint32_t a = inv[i], b = inv[nl->j[k]], lo = a < b ? a : b, hi = a < b ? b : a;
            size_t slot = fill[lo]++;
            size_t at = slot; // insertion into the row, kept sorted by partner
            while (at > start[lo] && j[at - 1] > hi) {
                j[at] = j[at - 1];
                memcpy(hist + at * hl, hist + (at - 1) * hl, hl * sizeof *hist);
                --at;
            }
            j[at] = hi;
            memcpy(hist + at * hl, nl->hist + k * hl, hl * sizeof *hist);
            // A pair whose roles swap sees the contact from the other side: the
            // tangential spring (on v_i − v_j, eq. 7) changes sign; the rolling
            // one (on (ω_i − ω_j) × n, eq. 12, both factors flip) does not.
            if (a > b && (w->features & DEM_FEAT_TANGENTIAL))
                for (int c = 0; c < 3; ++c) hist[at * hl + (size_t)c] = -hist[at * hl + (size_t)c];
        }
    free(fill);
    free(nl->start), free(nl->j), free(nl->hist);
    nl->start = start, nl->j = j, nl->hist = hist;
    nl->rows = n, nl->cap = count ? count : 1, nl->hist_cap = doubles ? doubles : 1;
    return 0;
}

dem_status dem_world_sort_spatially(dem_world *w)
{
    const size_t n = w->n;
    if (n < 2) return DEM_OK;
    const double cell = 2.0 * dem_world_max_radius(w);
    order_key *keys = malloc(n * sizeof *keys);
    uint32_t *perm = malloc(n * sizeof *perm), *inv = malloc(n * sizeof *inv);
    unsigned char *tmp = malloc(n * 6 * sizeof(double)); // the widest per-granule record
    int fail = !keys || !perm || !inv || !tmp;
    if (!fail) {
        const dem_vec3 lo = w->def.domain_lo;
        for (size_t i = 0; i < n; ++i) {
            const dem_vec3 p = w->pos[i];
            keys[i].key = spread3(cell_coordinate(p.x, lo.x, cell)) | spread3(cell_coordinate(p.y, lo.y, cell)) << 1 |
                          spread3(cell_coordinate(p.z, lo.z, cell)) << 2;
            keys[i].index = (uint32_t)i;
        }
        qsort(keys, n, sizeof *keys, compare_keys);
        for (size_t i = 0; i < n; ++i) perm[i] = keys[i].index, inv[keys[i].index] = (uint32_t)i;
        permute_granules(w, perm, tmp);
        // History travels with the list; without a valid list there is none to keep.
        if (w->list_valid && w->nl.hist_len > 0) fail = renumber_list(w, inv);
        else w->list_valid = 0;
    }
    free(keys), free(perm), free(inv), free(tmp);
    if (fail) {
        w->list_valid = 0; // granules may be permuted already: never index the old list with them
        dem_world_set_error(w, "out of memory sorting the granules");
        return DEM_ERR_NOMEM;
    }
    if (w->prepared && dem_lists_rebuild(w)) return DEM_ERR_NOMEM;
    return DEM_OK;
}
