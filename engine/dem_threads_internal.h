// SPDX-License-Identifier: MIT
// How the engine shares its granules among OpenMP threads: contiguous blocks
// (with the granules sorted along a space-filling curve few pairs cross a
// block's edge), and no threads at all for a small world. Every parallel
// region names its team size (num_threads): a world's thread count is its
// own, never OpenMP's process-wide setting.
#ifndef DEM_THREADS_INTERNAL_H
#define DEM_THREADS_INTERNAL_H

#include <stddef.h>

// Below this many granules a step is a few microseconds of work and starting
// OpenMP threads would cost more than it saves.
#define DEM_OMP_MIN_GRANULES 512

// Whether loops over n granules run on a team of nt threads.
static inline int dem_threads_split(size_t n, int nt) { return n >= DEM_OMP_MIN_GRANULES && nt > 1; }

// Granules [lo, hi) of thread t of nt.
static inline void dem_thread_block(size_t n, int t, int nt, size_t *lo, size_t *hi)
{
    *lo = n * (size_t)t / (size_t)nt;
    *hi = n * (size_t)(t + 1) / (size_t)nt;
}

#endif
