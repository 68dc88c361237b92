// SPDX-License-Identifier: MIT
// The granule–granule pair loops. Each pair adds its force and
// two torques to both granules, rows in ascending order (the explicit
// integration computes the touching pairs 32 at a time in a vectorised
// batch, then adds them in that same order: "contact batches"); with threads, each
// owns a block of granules and only the pairs that cross a block's edge go
// through per-pair slots (pair_loop_threaded; the step team of dem_step.c
// runs the same block pieces, dem_pairs_crossing and dem_pairs_block, inside
// its one parallel region). No two threads write the same memory, and every
// granule sums its terms in the serial order, so results are bitwise
// identical for any thread count.
//
// The pair loops are instantiated once per feature mask (DEM_PAIR_LOOP
// below): with the mask a constant, the inline kernel of dem_contact.h drops
// every effect the scene does not use.
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "dem_contact_batch_internal.h"
#include "dem_pairs_internal.h"
#include "dem_prefetch_internal.h"
#include "dem_threads_internal.h"

// A loop-level bit above the feature masks: the pair loop for a periodic
// scene whose centres one wrap may not do for (pair_separation_general).
#define DEM_GENERAL_IMAGE DEM_FEAT_COUNT_MASKS

// How a pair hands its forces on. DIRECT adds them straight to both granules;
// SLOTS writes them into the pair's slots, for a pair crossing a thread's
// block (pair_loop_threaded adds them in the serial order).
enum { DEM_SLOTS = 0, DEM_DIRECT = 1 };

// Add the slot of pair k, which crosses a thread's block, to its granule i.
static DEM_ALWAYS_INLINE void add_slot(const pair_ctx *restrict c, size_t i, size_t k)
{
    c->frc[i] = dem_v3_add(c->frc[i], c->slot_f[k]);
    c->trq[i] = dem_v3_add(c->trq[i], c->slot_ti[k]);
}

// Minimum image of one component along a period of length len, for a
// separation shorter than one and a half periods. Branches, not a select:
// they are nearly always not taken and predicted so (measured, computing
// c − len·s with s = 1, −1 or 0 made the step 6 % slower at N = 20 000,
// 12 interleaved rounds).
static DEM_ALWAYS_INLINE double wrap_component(double c, double len)
{
    return c > 0.5 * len ? c - len : c < -0.5 * len ? c + len : c;
}

// Minimum image along the periodic axis by one wrap: right for every pair
// while all centres span less than DEM_ONE_WRAP_SPAN periods. A switch on
// named components, not a pointer to one, keeps the separation in registers.
static DEM_ALWAYS_INLINE dem_vec3 wrap_separation(dem_vec3 d, int axis, double len)
{
    dem_vec3 s = d;
    switch (axis) {
    case 0: s.x = wrap_component(d.x, len); break;
    case 1: s.y = wrap_component(d.y, len); break;
    default: s.z = wrap_component(d.z, len); break;
    }
    return s;
}

// Separation r_j − r_i of a listed pair while centres may lie more than
// DEM_ONE_WRAP_SPAN periods apart (a granule placed outside the domain,
// before its first drift): one wrap where it brings the pair within half a
// period, the general minimum image where not. Those evaluations have loops
// of their own (DEM_GENERAL_IMAGE): with this check and its call in the
// loops of every step, the compiler kept the loops' values on the stack
// around the call, and every pair paid (measured, the step 1.035x faster
// at N = 20 000 without it, median of 10 interleaved rounds).
static dem_vec3 pair_separation_general(const dem_world *w, const pair_ctx *restrict c, size_t i, uint32_t j)
{
    const dem_vec3 d = dem_v3_sub(c->pos[j], c->pos[i]), s = wrap_separation(d, c->axis, c->period);
    return fabs(dem_v3_comp(s, c->axis)) <= 0.5 * c->period ? s : dem_world_min_image(w, d);
}

// Separation r_j − r_i of a listed pair (minimum image).
static DEM_ALWAYS_INLINE dem_vec3 pair_separation(const dem_world *w, const pair_ctx *restrict c, size_t i,
                                                  uint32_t j, const unsigned mask)
{
    if (!(mask & DEM_FEAT_PERIODIC)) return dem_v3_sub(c->pos[j], c->pos[i]);
    if (mask & DEM_GENERAL_IMAGE) return pair_separation_general(w, c, i, j);
    return wrap_separation(dem_v3_sub(c->pos[j], c->pos[i]), c->axis, c->period);
}

// Separation r_j − r_i of a listed pair, and whether the granules touch.
static DEM_ALWAYS_INLINE int pair_touches(const dem_world *w, const pair_ctx *restrict c, size_t i, uint32_t j,
                                          const unsigned mask, dem_vec3 *d)
{
    *d = pair_separation(w, c, i, j, mask);
    const double rsum = c->rad[i] + c->rad[j];
    return dem_v3_norm2(*d) < rsum * rsum;
}

static DEM_ALWAYS_INLINE void add_to_pair(const pair_ctx *restrict c, size_t i, size_t j, dem_vec3 f, dem_vec3 ti,
                                          dem_vec3 tj)
{
    dem_vec3 *restrict frc = c->frc, *restrict trq = c->trq;
    frc[i] = dem_v3_add(frc[i], f);
    frc[j] = dem_v3_sub(frc[j], f); // Newton's third law
    trq[i] = dem_v3_add(trq[i], ti);
    trq[j] = dem_v3_add(trq[j], tj);
}

// One pair, scalar: the implicit integrations (which keep per-pair data) and
// the pairs crossing a thread's block (SLOTS) come this way.
static DEM_ALWAYS_INLINE void pair_force(dem_world *restrict w, const pair_ctx *restrict c, size_t i, size_t k,
                                         const unsigned mask, const int direct)
{
    const uint32_t j = c->nbr[k];
    const int hl = dem_history_len(mask);
    double *restrict hist = c->hist + k * (size_t)hl;
    dem_vec3 d;
    if (!pair_touches(w, c, i, j, mask, &d)) {
        // Open contact: springs forget (a new contact starts unloaded).
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        if (!direct) w->pair_f[k] = w->pair_ti[k] = w->pair_tj[k] = dem_v3(0, 0, 0);
        if (c->implicit_damping) w->pair_g[k] = 0.0, w->pair_n[k] = dem_v3(0, 0, 0); // gather_damping reads both
        if (c->implicit_springs) w->imp->pair[k] = (dem_imp_contact){{0, 0, 0}, 0, 0, 0, 0, 0, 0};
        return;
    }
    const pair_side si = side_of(c, i), sj = side_of(c, j);
    const pair_result r = pair_contact(c, d, &si, &sj, &c->constants[k], hist, mask);
    if (c->implicit_damping) { // read only by gather_damping
        w->pair_g[k] = r.damping_coeff;
        w->pair_n[k] = r.normal;
    }
    if (c->implicit_springs)
        w->imp->pair[k] = (dem_imp_contact){r.normal, r.damping_coeff, r.k_tangential, r.k_rolling,
                                           r.lever_i,  r.lever_j,     r.reduced_radius};
    if (direct) {
        add_to_pair(c, i, j, r.force, r.torque_i, r.torque_j);
    } else {
        w->pair_f[k] = r.force;
        w->pair_ti[k] = r.torque_i;
        w->pair_tj[k] = r.torque_j;
    }
}

// The batch kernels, one per kernel mask (see DEM_BATCH_KERNEL): the
// periodic bit is the loop's, not the law's.
DEM_FOR_MASKS_16(DEM_BATCH_KERNEL)
typedef void (*batch_kernel_fn)(const pair_ctx *restrict, contact_batch *restrict);
static const batch_kernel_fn batch_kernels[DEM_FEAT_KERNEL_MASKS] = DEM_BY_MASK_16(batch_compute_);

// Run the batch and add its results in the pairs' order; empties it.
static DEM_ALWAYS_INLINE void batch_flush(const pair_ctx *restrict c, contact_batch *restrict b, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    batch_kernels[mask & (DEM_FEAT_KERNEL_MASKS - 1)](c, b);
    for (int e = 0; e < b->count; ++e) {
        if (b->slot[e]) {
            add_slot(c, b->i[e], b->k[e]);
            continue;
        }
        batch_hist_out(b, e, c->hist + b->k[e] * (size_t)hl, hl);
        add_to_pair(c, b->i[e], b->j[e], dem_v3(b->f[0][e], b->f[1][e], b->f[2][e]),
                    dem_v3(b->ti[0][e], b->ti[1][e], b->ti[2][e]), dem_v3(b->tj[0][e], b->tj[1][e], b->tj[2][e]));
    }
    b->count = 0;
}

// Run a batch of pairs crossing a thread's block and put each result in its
// pair's slot, for the threads to add in their turn; empties it.
static DEM_ALWAYS_INLINE void batch_flush_to_slots(const pair_ctx *restrict c, contact_batch *restrict b,
                                                   const unsigned mask)
{
    const int hl = dem_history_len(mask);
    batch_kernels[mask & (DEM_FEAT_KERNEL_MASKS - 1)](c, b);
    for (int e = 0; e < b->count; ++e) {
        const size_t k = b->k[e];
        batch_hist_out(b, e, c->hist + k * (size_t)hl, hl);
        c->slot_f[k] = BATCH_V3(b->f, e);
        c->slot_ti[k] = BATCH_V3(b->ti, e);
        c->slot_tj[k] = BATCH_V3(b->tj, e);
    }
    b->count = 0;
}

// The slot of pair k, crossing the thread's block, added to row i in its
// turn. Not flushing the batch here keeps the batches full near a block's
// end, where most rows have such a pair.
static DEM_ALWAYS_INLINE void batch_slot(const pair_ctx *restrict c, contact_batch *restrict b, size_t i, size_t k,
                                         const unsigned mask)
{
    const int e = b->count++;
    b->slot[e] = 1;
    b->i[e] = b->j[e] = (uint32_t)i, b->k[e] = k;
    const pair_side neutral = {{0, 0, 0}, {0, 0, 0}, 1.0}; // any finite contact will do
    b->root_reduced_mass[e] = b->reduced_radius[e] = 1.0;
    b->d[0][e] = 1.0, b->d[1][e] = b->d[2][e] = 0.0;
    batch_put_side(b, e, 0, &neutral);
    batch_put_side(b, e, 1, &neutral);
    for (int q = 0; q < 6; ++q) b->hist[q][e] = 0.0;
    if (b->count == DEM_BATCH) batch_flush(c, b, mask);
}

// Touching pair k (i, j, separation d) into the batch, flushing it when full
// into the granules, or with `to_slots` into the pairs' slots.
static DEM_ALWAYS_INLINE void batch_contact(const pair_ctx *restrict c, contact_batch *restrict b, size_t i,
                                            uint32_t j, size_t k, dem_vec3 d, const unsigned mask, const int to_slots)
{
    const int hl = dem_history_len(mask);
    const double *restrict hist = c->hist + k * (size_t)hl;
    const int e = b->count++;
    b->slot[e] = 0;
    b->i[e] = (uint32_t)i, b->j[e] = j, b->k[e] = k;
    b->d[0][e] = d.x, b->d[1][e] = d.y, b->d[2][e] = d.z;
    b->root_reduced_mass[e] = c->constants[k].root_reduced_mass;
    b->reduced_radius[e] = c->constants[k].reduced_radius;
    const pair_side si = side_of(c, i), sj = side_of(c, j);
    batch_put_side(b, e, 0, &si);
    batch_put_side(b, e, 1, &sj);
    batch_hist_in(b, e, hist, hl);
    if (b->count < DEM_BATCH) return;
    if (to_slots) batch_flush_to_slots(c, b, mask);
    else batch_flush(c, b, mask);
}

// Pair k of row i into the batch if it touches (flushing a full batch);
// an open pair's springs are reset here. A branch on the touch test: the
// small lists' loop (see DEM_BRANCH_FREE_MIN_PAIRS).
static DEM_ALWAYS_INLINE void batch_pair(dem_world *restrict w, const pair_ctx *restrict c, contact_batch *restrict b,
                                         size_t i, size_t k, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    dem_vec3 d;
    if (pair_touches(w, c, i, c->nbr[k], mask, &d)) batch_contact(c, b, i, c->nbr[k], k, d, mask, 0);
    else
        for (int h = 0; h < hl; ++h) c->hist[k * (size_t)hl + h] = 0.0; // a new contact starts unloaded
}

// Pairs k0 … k1−1 into the batch, in their order: the touching ones as
// contacts, those reaching past `hi` (the end of a thread's block) as slot
// entries; the others are open, and their springs are reset (a new contact
// starts unloaded). Contacts and near misses interleave in a bed, so a
// branch on the touch test is mispredicted about as often as not, and so is
// the end of a row's few pairs. Instead the pairs are walked in fixed pieces
// across rows (each pair knows its row), and each pair's index is written to
// both lists, of which only the one it belongs to advances.
// Below DEM_BRANCH_FREE_MIN_PAIRS listed pairs the loop with the branch is
// faster: the same few hundred granules' pattern of contacts and near misses
// comes round every step, and the branch predictor learns it. Measured, the
// branch-free loop's speed over the branching one's: 0.89x (median of 4
// rounds, 0.83-1.05) on the calibration's drum (279 granules, ~850 pairs),
// 0.91-0.94x at 1 148 granules; 1.08x and 1.27x at 2 233, 1.12x at 5 000
// (15 000 pairs). Both loops add the same pairs in the same order, so the
// choice changes no result.
#define DEM_BRANCH_FREE_MIN_PAIRS 4096
#define PAIR_PIECE 32
static DEM_ALWAYS_INLINE void batch_pairs(dem_world *restrict w, const pair_ctx *restrict c, contact_batch *restrict b,
                                          size_t k0, size_t k1, size_t hi, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    if (w->nl.count < DEM_BRANCH_FREE_MIN_PAIRS) {
        for (size_t k = k0; k < k1; ++k) {
            prefetch_partner(c, k, k1);
            if (c->nbr[k] >= hi) batch_slot(c, b, c->row[k], k, mask);
            else batch_pair(w, c, b, c->row[k], k, mask);
        }
        return;
    }
    const uint32_t *restrict row = c->row, *restrict nbr = c->nbr;
    for (size_t p0 = k0; p0 < k1; p0 += PAIR_PIECE) {
        const size_t p1 = p0 + PAIR_PIECE < k1 ? p0 + PAIR_PIECE : k1;
        size_t take[PAIR_PIECE], open[PAIR_PIECE];
        dem_vec3 sep[PAIR_PIECE];
        unsigned char crossing[PAIR_PIECE];
        int nt = 0, no = 0;
        for (size_t k = p0; k < p1; ++k) {
            prefetch_partner(c, k, k1);
            prefetch_pair_state(c, k, k1, hl);
            dem_vec3 d;
            const int x = nbr[k] >= hi, in = pair_touches(w, c, row[k], nbr[k], mask, &d) | x;
            take[nt] = k, sep[nt] = d, crossing[nt] = (unsigned char)x, open[no] = k;
            nt += in, no += !in;
        }
        for (int o = 0; o < no; ++o)
            for (int h = 0; h < hl; ++h) c->hist[open[o] * (size_t)hl + h] = 0.0;
        for (int t = 0; t < nt; ++t) {
            const size_t k = take[t];
            if (crossing[t]) batch_slot(c, b, row[k], k, mask);
            else batch_contact(c, b, row[k], nbr[k], k, sep[t], mask, 0);
        }
    }
}

// The serial order, the reference every thread count reproduces bit for bit:
// rows ascending, each pair added to i and to j as it comes.
static DEM_ALWAYS_INLINE void pair_loop_serial(dem_world *restrict w, const unsigned mask)
{
    const size_t n = w->n;
    const pair_ctx c = pair_ctx_make(w);
    const size_t *restrict start = w->nl.start;
    memset(w->frc, 0, n * sizeof *w->frc);
    memset(w->trq, 0, n * sizeof *w->trq);
    const size_t end = start[n];
    if (!uses_batch(&c)) {
        for (size_t i = 0; i < n; ++i)
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                prefetch_partner(&c, k, end);
                pair_force(w, &c, i, k, mask, DEM_DIRECT);
            }
        return;
    }
    contact_batch b;
    b.count = 0;
    batch_pairs(w, &c, &b, 0, end, n, mask);
    batch_flush(&c, &b, mask);
}

// Threads: each owns a block of granules and adds the pairs inside it
// directly. A pair reaching past the block's end (rows are sorted by
// partner, so these close each row) is computed first, into its slots
// (block_crossing_pairs); after a barrier each thread starts its granules
// from the slots of pairs coming in from lower blocks (the lowest pair
// indices, so first in the serial order), then walks its rows as the serial
// loop does, taking the outgoing crossing pairs' part from their slots at the
// end of each row (block_own_pairs). Every granule sums the same terms in the
// same order as pair_loop_serial.
//
// Each thread works from its own pair_ctx: read through the spawning
// thread's stack frame, which that thread keeps writing, every pair would
// share a cache line with those writes (measured: 2 threads 1.5x one at
// N = 100 000, against 1.95x for two separate processes).

// The pairs of row i (in a block ending at `end`) that reach past the
// block's end, into their slots: one at a time without a batch (the
// implicit integrations), or through the contact batch b, whose touching
// pairs are computed 32 at a time while an open pair's springs and slots are
// reset here. Each pair writes only its own slot and springs, so the order
// of the batch changes nothing. The crossing pairs are ~2 % of the pairs at
// N = 100 000 on 2 threads; one at a time they took 4.9 % of the samples,
// batched 3.6 % (commit fcd6044).
static DEM_ALWAYS_INLINE void row_crossing_pairs(dem_world *restrict w, const pair_ctx *restrict c,
                                                 contact_batch *b, size_t i, size_t end, const unsigned mask)
{
    const size_t *start = w->nl.start;
    const int hl = dem_history_len(mask);
    for (size_t k = start[i + 1]; k > start[i] && c->nbr[k - 1] >= end; --k) {
        const size_t p = k - 1;
        dem_vec3 d;
        if (!b) {
            pair_force(w, c, i, p, mask, DEM_SLOTS);
        } else if (pair_touches(w, c, i, c->nbr[p], mask, &d)) {
            batch_contact(c, b, i, c->nbr[p], p, d, mask, 1);
        } else {
            for (int h = 0; h < hl; ++h) c->hist[p * (size_t)hl + h] = 0.0; // a new contact starts unloaded
            c->slot_f[p] = c->slot_ti[p] = c->slot_tj[p] = dem_v3(0, 0, 0);
        }
    }
}

// Rows rows[0 … count−1] (or, without `rows`, every row of [first, end)) of
// a block ending at `end`: their pairs reaching past it, into their slots.
static DEM_ALWAYS_INLINE void crossing_pairs_of(dem_world *restrict w, const uint32_t *rows, size_t first,
                                                size_t count, size_t end, const unsigned mask)
{
    const pair_ctx c = pair_ctx_make(w);
    contact_batch b;
    b.count = 0;
    contact_batch *batch = uses_batch(&c) ? &b : NULL;
    for (size_t r = 0; r < count; ++r) row_crossing_pairs(w, &c, batch, rows ? rows[r] : first + r, end, mask);
    if (batch) batch_flush_to_slots(&c, batch, mask);
}

static DEM_ALWAYS_INLINE void block_crossing_pairs(dem_world *restrict w, size_t lo, size_t hi, const unsigned mask)
{
    crossing_pairs_of(w, NULL, lo, hi - lo, hi, mask);
}

static DEM_ALWAYS_INLINE void listed_crossing_pairs(dem_world *restrict w, const uint32_t *rows, size_t count,
                                                    size_t end, const unsigned mask)
{
    crossing_pairs_of(w, rows, 0, count, end, mask);
}

static DEM_ALWAYS_INLINE void block_own_pairs(dem_world *restrict w, size_t lo, size_t hi, const unsigned mask)
{
    const pair_ctx c = pair_ctx_make(w);
    const size_t *start = w->nl.start;
    const uint32_t *nbr = w->nl.j;
    const size_t first_own_pair = start[lo];
    for (size_t i = lo; i < hi; ++i) { // incoming crossing pairs: partner rows below lo
        dem_vec3 f = dem_v3(0, 0, 0), t = dem_v3(0, 0, 0);
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1] && w->rev_pair[r] < first_own_pair; ++r) {
            const size_t k = w->rev_pair[r];
            f = dem_v3_sub(f, w->pair_f[k]); // Newton's third law
            t = dem_v3_add(t, w->pair_tj[k]);
        }
        w->frc[i] = f;
        w->trq[i] = t;
    }
    const size_t end = start[hi];
    if (!uses_batch(&c)) {
        for (size_t i = lo; i < hi; ++i)
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                prefetch_partner(&c, k, end);
                if (nbr[k] < hi) pair_force(w, &c, i, k, mask, DEM_DIRECT);
                else add_slot(&c, i, k);
            }
        return;
    }
    contact_batch b;
    b.count = 0;
    batch_pairs(w, &c, &b, start[lo], end, hi, mask);
    batch_flush(&c, &b, mask);
}

static DEM_ALWAYS_INLINE void pair_loop_threaded(dem_world *restrict w, const unsigned mask)
{
#pragma omp parallel num_threads(dem_world_team(w))
    {
        size_t lo, hi;
        dem_thread_block(w->n, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        block_crossing_pairs(w, lo, hi, mask);
#pragma omp barrier
        block_own_pairs(w, lo, hi, mask);
    }
}

static DEM_ALWAYS_INLINE void pair_loop(dem_world *restrict w, const unsigned mask)
{
    if (dem_threads_split(w->n, dem_world_team(w))) pair_loop_threaded(w, mask);
    else pair_loop_serial(w, mask);
}

// One specialised function per feature mask; the table picks it per scene.
#define DEM_PAIR_LOOP(M)                                                                                \
    static void pair_loop_##M(dem_world *w) { pair_loop(w, M); }                                        \
    static void crossing_pairs_##M(dem_world *w, const uint32_t *rows, size_t count, size_t end)         \
    {                                                                                                   \
        listed_crossing_pairs(w, rows, count, end, M);                                                  \
    }                                                                                                   \
    static void own_pairs_##M(dem_world *w, size_t lo, size_t hi) { block_own_pairs(w, lo, hi, M); }
DEM_FOR_MASKS_32(DEM_PAIR_LOOP)
#define DEM_GENERAL_IMAGE_LOOP(M) \
    static void general_image_pair_loop_##M(dem_world *w) { pair_loop(w, DEM_FEAT_PERIODIC | DEM_GENERAL_IMAGE | M); }
DEM_FOR_MASKS_16(DEM_GENERAL_IMAGE_LOOP)

typedef void (*pair_loop_fn)(dem_world *);
typedef void (*crossing_pairs_fn)(dem_world *, const uint32_t *, size_t, size_t);
typedef void (*block_pairs_fn)(dem_world *, size_t, size_t);
static const pair_loop_fn pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_32(pair_loop_);
static const crossing_pairs_fn crossing_pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_32(crossing_pairs_);
static const block_pairs_fn own_pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_32(own_pairs_);
static const pair_loop_fn general_image_pair_loops[DEM_FEAT_KERNEL_MASKS] = DEM_BY_MASK_16(general_image_pair_loop_);

// Each granule's own dashpots, Σγ n nᵀ over its contacts (implicit dashpot).
static void gather_damping(dem_world *restrict w)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t i = 0; i < n; ++i) {
        double d[6] = {0, 0, 0, 0, 0, 0};
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) add_damping(d, w->pair_g[k], w->pair_n[k]);
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1]; ++r)
            add_damping(d, w->pair_g[w->rev_pair[r]], w->pair_n[w->rev_pair[r]]);
        for (int c = 0; c < 6; ++c) w->damp[6 * i + c] = d[c];
    }
}

void dem_pairs_compute(dem_world *w, int general_image)
{
    const unsigned mask = w->features & (DEM_FEAT_COUNT_MASKS - 1);
    if (general_image) general_image_pair_loops[mask & (DEM_FEAT_PERIODIC - 1)](w);
    else pair_loops[mask](w);
    if (w->def.implicit_damping) gather_damping(w);
}

size_t dem_pairs_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows)
{
    size_t count = 0;
    for (size_t i = lo; i < hi; ++i)
        if (w->nl.start[i + 1] > w->nl.start[i] && w->nl.j[w->nl.start[i + 1] - 1] >= hi) rows[count++] = (uint32_t)i;
    return count;
}

void dem_pairs_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end)
{
    crossing_pair_loops[w->features & (DEM_FEAT_COUNT_MASKS - 1)](w, rows, count, end);
}

void dem_pairs_block(dem_world *w, size_t lo, size_t hi)
{
    own_pair_loops[w->features & (DEM_FEAT_COUNT_MASKS - 1)](w, lo, hi);
}
