// SPDX-License-Identifier: MIT
// Benchmark (not a test): the machine's load-to-use latency against working-set
// size, by chasing pointers through a random cyclic permutation of 64-byte
// lines (every load depends on the one before, and no prefetcher can guess
// the next line). It tells where this machine's fast cache ends, which is
// what vs_peers.sh's cost-against-N pass runs into: a granule's hot data is
// about 400 bytes (counted from the arrays a step touches, not measured), so
// the bed outgrows a cache of C bytes near N = C / 400.
//
//   build/tests/bench_memory_latency [largest MiB (default 128)] [loads per size (default 2e7)]
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define LINE 64

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// xorshift64: a fixed, portable sequence, so every run shuffles alike.
static uint64_t next_random(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

// Nanoseconds per dependent load over `lines` cache lines, or a negative
// number if the memory could not be had.
static double chase(size_t lines, size_t loads)
{
    size_t *order = malloc(lines * sizeof *order);
    char *buf = aligned_alloc(LINE, lines * LINE);
    if (!order || !buf) {
        free(order);
        free(buf);
        return -1.0;
    }
    uint64_t seed = 0x9E3779B97F4A7C15u;
    for (size_t i = 0; i < lines; ++i) order[i] = i;
    for (size_t i = lines - 1; i > 0; --i) { // Fisher–Yates
        const size_t j = (size_t)(next_random(&seed) % (i + 1));
        const size_t t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
    for (size_t i = 0; i < lines; ++i) *(char **)(buf + order[i] * LINE) = buf + order[(i + 1) % lines] * LINE;
    char *p = buf + order[0] * LINE;
    for (size_t s = 0; s < lines; ++s) p = *(char **)p; // one lap to warm the caches and the TLB
    const double t0 = now();
    for (size_t s = 0; s < loads; ++s) p = *(char **)p;
    const double ns = 1e9 * (now() - t0) / (double)loads;
    char *volatile sink = p; // keep the chase from being optimised away
    (void)sink;
    free(order);
    free(buf);
    return ns;
}

int main(int argc, char **argv)
{
    const long largest = argc > 1 ? atol(argv[1]) : 128;
    const double loads = argc > 2 ? atof(argv[2]) : 2e7;
    if (largest < 1 || !(loads >= 1)) {
        fprintf(stderr, "usage: %s [largest MiB >= 1] [loads per size >= 1]\n", argv[0]);
        return 2;
    }
    printf("working set (KiB),ns per dependent load\n");
    for (long kib = 256; kib <= largest * 1024; kib *= 2) {
        const double ns = chase((size_t)kib * 1024 / LINE, (size_t)loads);
        if (ns < 0) return fprintf(stderr, "out of memory at %ld KiB\n", kib), 1;
        printf("%ld,%.1f\n", kib, ns);
    }
    return 0;
}
