// SPDX-License-Identifier: MIT
// Command-line front end of the independent Table A.1 reference: writes the
// frames as CSV (t,id,x,y,z,vx,vy,vz,wx,wy,wz; id 1 and 2, two rows per frame).
//
//   cc -std=c11 -O2 -Itests/support -o ref_two_particles
//      tests/support/ref_two_particles_main.c tests/support/ref_two_particles.c -lm
//   ./ref_two_particles [--damping approaching|always|separating|no_tension]
//                       [--lever contact|radius] [--dt X] [--duration X] > ref.csv
#include "ref_two_particles.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int usage(const char *prog)
{
    fprintf(stderr,
            "usage: %s [--damping approaching|always|separating|no_tension]\n"
            "          [--lever contact|radius] [--dt SECONDS] [--duration SECONDS]\n",
            prog);
    return 2;
}

static int parse_positive(const char *s, double *out)
{
    char *end = NULL;
    double x = strtod(s, &end);
    if (end == s || *end != '\0' || !(x > 0.0))
        return -1;
    *out = x;
    return 0;
}

int main(int argc, char **argv)
{
    ref_options opt = ref_default_options();
    for (int a = 1; a < argc; a += 2) { // options come as NAME VALUE pairs
        const char *arg = argv[a];
        const char *val = a + 1 < argc ? argv[a + 1] : NULL;
        if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0)
            return usage(argv[0]), 0;
        if (val == NULL)
            return usage(argv[0]);
        if (strcmp(arg, "--damping") == 0) {
            opt.damping = ref_damping_from_name(val);
            if (opt.damping < 0) {
                fprintf(stderr, "%s: unknown damping reading '%s'\n", argv[0], val);
                return 2;
            }
        } else if (strcmp(arg, "--lever") == 0) {
            if (strcmp(val, "contact") == 0 || strcmp(val, "contact_point") == 0)
                opt.lever = REF_LEVER_CONTACT_POINT;
            else if (strcmp(val, "radius") == 0)
                opt.lever = REF_LEVER_RADIUS;
            else {
                fprintf(stderr, "%s: unknown lever arm '%s'\n", argv[0], val);
                return 2;
            }
        } else if (strcmp(arg, "--dt") == 0) {
            if (parse_positive(val, &opt.dt) != 0) {
                fprintf(stderr, "%s: bad --dt '%s'\n", argv[0], val);
                return 2;
            }
        } else if (strcmp(arg, "--duration") == 0) {
            if (parse_positive(val, &opt.duration) != 0) {
                fprintf(stderr, "%s: bad --duration '%s'\n", argv[0], val);
                return 2;
            }
        } else {
            return usage(argv[0]);
        }
    }

    int n = ref_frame_count(opt.duration);
    ref_frame *frames = malloc((size_t)n * sizeof *frames);
    if (frames == NULL) {
        fprintf(stderr, "%s: out of memory\n", argv[0]);
        return 1;
    }
    int got = ref_two_particles_run(&opt, frames, n);
    if (got < 0) {
        fprintf(stderr, "%s: bad options\n", argv[0]);
        free(frames);
        return 2;
    }
    printf("t,id,x,y,z,vx,vy,vz,wx,wy,wz\n");
    for (int k = 0; k < got; ++k) {
        const ref_frame *f = &frames[k];
        for (int i = 0; i < 2; ++i)
            printf("%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", f->t, i + 1,
                   f->x[i][0], f->x[i][1], f->x[i][2], f->v[i][0], f->v[i][1], f->v[i][2],
                   f->w[i][0], f->w[i][1], f->w[i][2]);
    }
    free(frames);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "%s: write error\n", argv[0]);
        return 1;
    }
    return 0;
}
