// SPDX-License-Identifier: MIT
// The peers' side of tests/peers/drum_peers.sh: the dumped positions of a
// LIGGGHTS or LAMMPS run of an exported deck (liggghts_drum.in,
// lammps_drum.in) measured with granucal's own raster (exp_face_measure.h), pixel
// and closing exactly as exp_drum_measure_now does.
//
//   drum_peers measure DRUM.yaml DUMP [--set KEY=VALUE ...]
//     every frame of a `dump custom` file with x, y and radius among its
//     columns measured on the drum DRUM.yaml describes; prints frames, angle
//     and CSA means and sample SDs (0 for one frame), and the signed angle's mean.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_drum.h"
#include "exp_drum_config.h"
#include "exp_face_measure.h"

static int load(const char *cfg, int n_sets, char **sets, exp_drum_def *d, exp_drum_run_opts *run)
{
    char err[512];
    exp_drum_yaml *y = exp_drum_config_load(cfg, n_sets, sets, err, sizeof err);
    int bad = !y || exp_drum_config_defs(y, d, run, err, sizeof err);
    exp_drum_config_free(y);
    if (bad) fprintf(stderr, "drum_peers: %s\n", err);
    return bad;
}

// The `--set KEY=VALUE` pairs after the positional arguments.
static int collect_sets(int argc, char **argv, int from, char **sets)
{
    int n = 0;
    for (int i = from; i + 1 < argc; i += 2)
        if (strcmp(argv[i], "--set") == 0) sets[n++] = argv[i + 1];
    return n;
}

typedef struct frame {
    size_t n, cap;
    double *x, *y, *r;
} frame;

// The columns of x, y and radius in a dump's "ITEM: ATOMS ..." line; 0, or 1
// when one is missing.
static int atom_columns(const char *line, int col[3])
{
    static const char *const names[3] = {"x", "y", "radius"};
    col[0] = col[1] = col[2] = -1;
    char copy[512], *save = NULL;
    snprintf(copy, sizeof copy, "%s", line + strlen("ITEM: ATOMS"));
    int i = 0;
    for (char *w = strtok_r(copy, " \t\r\n", &save); w; w = strtok_r(NULL, " \t\r\n", &save), ++i)
        for (int k = 0; k < 3; ++k)
            if (strcmp(w, names[k]) == 0) col[k] = i;
    return col[0] < 0 || col[1] < 0 || col[2] < 0;
}

// One value per column of a dump line into v (at most n); how many.
static int split_values(char *line, double *v, int n)
{
    int m = 0;
    for (char *p = line, *end; m < n; p = end) {
        v[m] = strtod(p, &end);
        if (end == p) break;
        m++;
    }
    return m;
}

// One frame of a `dump custom` file with x, y and radius among its columns
// (any order); 0 at its end or on a malformed frame.
static int read_frame(FILE *f, frame *fr)
{
    char line[512];
    size_t n = 0;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "ITEM: NUMBER OF ATOMS", 21) == 0) {
            if (!fgets(line, sizeof line, f)) return 0;
            n = strtoul(line, NULL, 10);
            break;
        }
    if (n == 0) return 0;
    int col[3];
    while (fgets(line, sizeof line, f) && strncmp(line, "ITEM: ATOMS", 11) != 0) continue;
    if (atom_columns(line, col)) return fprintf(stderr, "drum_peers: the dump has no x, y or radius column\n"), 0;
    if (n > fr->cap) {
        fr->cap = n;
        fr->x = realloc(fr->x, n * sizeof *fr->x), fr->y = realloc(fr->y, n * sizeof *fr->y);
        fr->r = realloc(fr->r, n * sizeof *fr->r);
        if (!fr->x || !fr->y || !fr->r) return 0;
    }
    for (fr->n = 0; fr->n < n && fgets(line, sizeof line, f); ++fr->n) {
        double v[32];
        int m = split_values(line, v, 32);
        if (m <= col[0] || m <= col[1] || m <= col[2]) return 0;
        fr->x[fr->n] = v[col[0]], fr->y[fr->n] = v[col[1]], fr->r[fr->n] = v[col[2]];
    }
    return fr->n == n;
}

// exp_drum_measure_now on positions instead of a world: same raster, pixel,
// closing and central fraction.
static int measure(const frame *fr, const exp_drum_def *d, exp_drum_measure *m)
{
    double rd = 0.5 * d->diameter, pixel = d->pixel > 0 ? d->pixel : 0.25 * d->gsd.median_diameter * cbrt(d->lambda);
    exp_raster *img = exp_raster_create(rd, pixel);
    if (!img) return 1;
    exp_raster_paint_discs(img, fr->n, fr->x, fr->y, fr->r);
    exp_angle a;
    int bad = exp_raster_close(img, d->closing_px) || exp_raster_surface_angle(img, rd, 0.6, &a);
    m->csa_percent = exp_raster_csa_percent(img, rd);
    m->angle_deg = fabs(a.angle_deg), m->angle_signed_deg = a.angle_deg;
    exp_raster_free(img);
    return bad;
}

static int cmd_measure(int argc, char **argv)
{
    char *sets[64];
    exp_drum_def d;
    exp_drum_run_opts run;
    if (load(argv[2], collect_sets(argc, argv, 4, sets), sets, &d, &run)) return 2;
    FILE *f = fopen(argv[3], "r");
    if (!f) return perror(argv[3]), 2;
    frame fr = {0};
    double s[5] = {0}, q[2] = {0}; // sums: angle, csa, signed angle; squares: angle, csa
    int n = 0, failed = 0;
    for (exp_drum_measure m; read_frame(f, &fr);) {
        if (measure(&fr, &d, &m)) {
            failed++;
            continue;
        }
        s[0] += m.angle_deg, s[1] += m.csa_percent, s[2] += m.angle_signed_deg, n++;
        q[0] += m.angle_deg * m.angle_deg, q[1] += m.csa_percent * m.csa_percent;
    }
    fclose(f);
    free(fr.x), free(fr.y), free(fr.r);
    if (n < 1) return fprintf(stderr, "drum_peers: %s: no frame measured\n", argv[3]), 2;
    double ma = s[0] / n, mc = s[1] / n, dof = n > 1 ? n - 1 : 1; // one frame: no spread
    double sa = sqrt(fmax(0, (q[0] - n * ma * ma) / dof)), sc = sqrt(fmax(0, (q[1] - n * mc * mc) / dof));
    printf("frames=%d\nunmeasured=%d\nangle=%.3f\nangle_sd=%.3f\ncsa=%.3f\ncsa_sd=%.3f\nangle_signed=%.3f\n", n, failed,
           ma, sa, mc, sc, s[2] / n);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 4 && strcmp(argv[1], "measure") == 0) return cmd_measure(argc, argv);
    fprintf(stderr, "usage: drum_peers measure DRUM.yaml DUMP [--set K=V ...]\n");
    return 2;
}
