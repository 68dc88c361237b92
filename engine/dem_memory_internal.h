// SPDX-License-Identifier: MIT
// Copying the engine's arrays (a world's clone, its neighbour list's): at the
// bottom of the layers, below everything that owns an array.
#ifndef DEM_MEMORY_INTERNAL_H
#define DEM_MEMORY_INTERNAL_H

#include <stdlib.h>
#include <string.h>

// A copy of `bytes` bytes of src; NULL for no array, and *fail set when the
// allocation failed (the caller frees what it got and reports once).
static inline void *dem_dup_bytes(const void *src, size_t bytes, int *fail)
{
    if (!src || bytes == 0) return NULL;
    void *d = malloc(bytes);
    if (!d) *fail = 1;
    else memcpy(d, src, bytes);
    return d;
}

#endif
