// SPDX-License-Identifier: MIT
// What a transient-and-precision rule would have seen during one drum run
// (issue 37.1; a measurement, not a test). Reads the samples a run wrote
// (bench_drum_averaging with SERIES_CSV: seconds turned, angle, CSA) and, at
// every EVERY seconds of turning, prints for the angle and the CSA what the
// run knew then: MSER-m's start of the steady part (experiments/common/
// exp_series.h; "limit": still in its transient), the mean from there and
// its batch-means standard error over BATCHES batches.
//   usage: bench_series_rule SERIES.csv [EVERY_S=2] [M=5] [BATCHES=10]
#include <stdio.h>
#include <stdlib.h>

#include "exp_series.h"

enum { MAX_SAMPLES = 100000 };

static int read_series(const char *path, double *t, double *angle, double *csa)
{
    FILE *f = fopen(path, "r");
    if (!f) return fprintf(stderr, "%s: cannot read\n", path), -1;
    char line[256];
    int n = 0;
    if (!fgets(line, sizeof line, f)) n = -1; // the header
    while (n >= 0 && n < MAX_SAMPLES && fgets(line, sizeof line, f))
        if (sscanf(line, "%lf,%lf,%lf", &t[n], &angle[n], &csa[n]) == 3) n++;
    fclose(f);
    return n;
}

// One observable over its first n samples: "start_s mean se [limit]".
static void report(const char *name, const double *x, int n, int m, int batches, double dt)
{
    int at_limit;
    const int start = exp_series_mser_start(x, n, m, &at_limit);
    if (start < 0) return (void)printf(" %s: too short", name);
    printf(" %s: steady from %.2f s%s, mean %.3f ± %.3f", name, start * dt, at_limit ? " (limit)" : "",
           exp_series_mean(x, start, n), exp_series_batch_se(x + start, n - start, batches));
}

int main(int argc, char **argv)
{
    if (argc < 2) return fprintf(stderr, "usage: %s SERIES.csv [EVERY_S] [M] [BATCHES]\n", argv[0]), 2;
    static double t[MAX_SAMPLES], angle[MAX_SAMPLES], csa[MAX_SAMPLES];
    const int n = read_series(argv[1], t, angle, csa);
    if (n < 2) return fprintf(stderr, "%s: fewer than two samples\n", argv[1]), 1;
    const double every = argc > 2 ? atof(argv[2]) : 2.0, dt = t[1] - t[0];
    const int m = argc > 3 ? atoi(argv[3]) : 5, batches = argc > 4 ? atoi(argv[4]) : 10;
    printf("%s: %d samples every %.3f s; MSER-%d, %d batches\n", argv[1], n, dt, m, batches);
    for (int upto = (int)(every / dt + 0.5); upto <= n; upto += (int)(every / dt + 0.5)) {
        printf("turned %.2f s:", upto * dt);
        report("angle", angle, upto, m, batches, dt);
        report("CSA", csa, upto, m, batches, dt);
        printf("\n");
    }
    return 0;
}
