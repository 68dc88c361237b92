// SPDX-License-Identifier: MIT
// Software prefetching of the data the force loops are about to touch: the
// partners of the pairs DEM_PREFETCH_AHEAD on, their springs and constants.
#ifndef DEM_PREFETCH_INTERNAL_H
#define DEM_PREFETCH_INTERNAL_H

#include "dem_pair_contact_internal.h"

// The partner data a pair reads and adds to, asked for DEM_PREFETCH_AHEAD
// pairs before the loop reaches it. Rows run in spatial order, so their own
// granules stream in sequence and the hardware prefetcher has them; a
// partner j > i lies ahead of that stream, often far ahead (a granule's
// neighbours in the next layer are a layer's worth of granules further on in
// Morton order), and its lines (pos, vel, omg, rad, frc, trq) came in one
// demand miss after another, each stalling the pair's chain of loads. Into
// L2 (locality 2), not L1: 96 pairs' partners would crowd L1 out.
// Read intent also for frc and trq: a line no other core holds comes in
// exclusive and takes the writes as well; write intent would take the lines
// of pairs crossing into another thread's block from that thread.
// Measured, interleaved A/B against no prefetch, 1 thread (commit d0b7a77):
// 1.28x at N = 1 000 000, 1.24x at 100 000, 0.97-1.09x at 20 000, none at
// 5 000 (in cache); 24, 48, 64 and 128 pairs ahead did less.
#define DEM_PREFETCH_AHEAD 96

// Both lines a 24-byte vector may lie on. Its start falls at a line offset
// of 0, 24, 48, 8, 32, 56, 16 or 40 bytes, and from 48 and 56 it runs into
// the next line: a prefetch of its first byte alone left a quarter of the
// partners' vectors to miss on their y or z. perf at N = 10^6 put the
// stalls of the pair loop on exactly those loads (pos[j].z, vel[j].z,
// omg[j].z, frc[j].z). Measured with the second line asked for as well,
// interleaved A/B, 1 thread, 4 rounds: 1.07x (1.04-1.10) at 10^6.
static DEM_ALWAYS_INLINE void prefetch_vec3(const dem_vec3 *v)
{
    __builtin_prefetch(v, 0, 2);
    __builtin_prefetch((const char *)(v + 1) - 1, 0, 2);
}

static DEM_ALWAYS_INLINE void prefetch_partner(const pair_ctx *restrict c, size_t k, size_t end)
{
    if (k + DEM_PREFETCH_AHEAD >= end) return;
    const uint32_t j = c->nbr[k + DEM_PREFETCH_AHEAD];
    prefetch_vec3(c->pos + j);
    prefetch_vec3(c->vel + j);
    prefetch_vec3(c->omg + j);
    __builtin_prefetch(c->rad + j, 0, 2);
    prefetch_vec3(c->frc + j);
    prefetch_vec3(c->trq + j);
}

// The hl doubles of springs at h, both their lines, for writing; none
// without springs (hl = 0, where the history array may not exist).
static DEM_ALWAYS_INLINE void prefetch_springs_at(const double *h, int hl)
{
    if (hl == 0) return;
    __builtin_prefetch(h, 1, 2);
    __builtin_prefetch(h + hl - 1, 1, 2);
}

// The springs (both their lines, for writing) and the constants of the pair
// DEM_PREFETCH_AHEAD on. Every listed pair writes its springs (a contact
// advances them, an open pair resets them), and stores to lines not yet held
// stalled the loop (perf at 10^6: the open pairs' reset and the batch's
// loads of the springs). The hardware prefetcher follows the stream, but not
// far enough ahead of a loop that only stores to most of it. Measured on top
// of the partners' second lines, interleaved A/B against neither, 1 thread:
// 1.16x (1.07-1.27, 4 rounds) at 10^6 against 1.07x for the second lines
// alone, 1.10x at 10^5, 1.04x at 20 000, 1.01x at 5 000; 2 threads at 10^5
// 1.21x (1.05-1.28, 6 rounds). The constants, read by touching pairs only,
// then still stalled the batch's gather at 10^6; asked for as well: 1.03x
// (1.02-1.03, 3 rounds) at 10^6, 1.04x (1.01-1.07, 6 rounds) at 10^5,
// 1.01x at 20 000 and 5 000 (8 rounds each). Bitwise the same results.
static DEM_ALWAYS_INLINE void prefetch_pair_state(const pair_ctx *restrict c, size_t k, size_t end, int hl)
{
    if (k + DEM_PREFETCH_AHEAD >= end) return;
    prefetch_springs_at(c->hist + (k + DEM_PREFETCH_AHEAD) * (size_t)hl, hl);
    __builtin_prefetch(c->constants + k + DEM_PREFETCH_AHEAD, 0, 2);
}

#endif
