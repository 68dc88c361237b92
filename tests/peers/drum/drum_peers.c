// SPDX-License-Identifier: MIT
// The drum slice for the peers (tests/peers/drum_peers.sh): granucal builds
// the bed, LIGGGHTS and LAMMPS turn it with the exported parameters, and the
// peers' dumped positions are measured here with granucal's own raster
// (exp_measure.h), pixel and closing exactly as exp_drum_measure_now does.
//
//   drum_peers export CALIBRATION.yaml TIER TABLE.csv OUTDIR
//     the calibration's outputs (cal_report_write: liggghts_parameters.in and
//     lammps_parameters.in among them) for a table already calibrated, read
//     from its calibrated_parameters.csv: the export exactly as a calibration
//     at that tier writes it, without rerunning the calibration.
//   drum_peers bed DRUM.yaml TYPES OUT.data [--set KEY=VALUE ...]
//     fill the drum as `granucal simulate` does (same seed, same bed), turn it
//     by start_tilt_deg as a turn starts, write it as a read_data file
//     (atom_style granular / sphere: id type diameter density x y z; every
//     granule type 1, TYPES atom types declared) and print shell assignments
//     rdrum, depth, dt (the network step granucal turns with), granules.
//   drum_peers measure DRUM.yaml DUMP [--set KEY=VALUE ...]
//     every frame of a `dump custom ... id x y z radius` file measured; prints
//     frames, angle and CSA means and sample SDs, and the signed angle's mean.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_config.h"
#include "cal_report.h"
#include "dem_world.h"
#include "exp_drum.h"
#include "exp_drum_config.h"
#include "exp_measure.h"

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

static const cal_range no_range = CAL_NO_RANGE_INIT;

// One row of calibrated_parameters.csv into the table (the ranges are the
// report's business, not the export's: left out).
static void table_row(cal_table *t, const char *contact, const char *material, const char *parameter, double v)
{
    int gg = strcmp(contact, "granule-granule") == 0;
    if (gg && strcmp(parameter, "density") == 0) t->density = v;
    else if (gg && strcmp(parameter, "k_n") == 0) t->k_n = v;
    else if (gg && strcmp(parameter, "xi") == 0) t->xi = v;
    else if (gg && strcmp(parameter, "mu_s") == 0) t->gg_mu_s = v;
    else if (gg && strcmp(parameter, "mu_r") == 0) t->gg_mu_r = v;
    else if (!gg && material[0] && t->n_walls < 16) {
        int w = 0;
        while (w < t->n_walls && strcmp(t->wall_name[w], material) != 0) w++;
        if (w == t->n_walls) {
            snprintf(t->wall_name[w], sizeof t->wall_name[w], "%s", material);
            t->wall_mu_s_range[w] = t->wall_mu_r_range[w] = no_range;
            snprintf(t->wall_source[w], sizeof t->wall_source[w], "calibrated_parameters.csv");
            t->n_walls++;
        }
        if (strcmp(parameter, "mu_s") == 0) t->wall_mu_s[w] = v;
        else if (strcmp(parameter, "mu_r") == 0) t->wall_mu_r[w] = v;
    }
}

static int read_table(const char *path, cal_table *t)
{
    FILE *f = fopen(path, "r");
    if (!f) return perror(path), 1;
    *t = (cal_table){.k_source = "calibrated_parameters.csv", .gg_source = "calibrated_parameters.csv",
                     .gg_mu_s_range = no_range, .gg_mu_r_range = no_range};
    char line[512];
    while (fgets(line, sizeof line, f)) {
        char contact[64], material[64] = "", parameter[64];
        double v;
        // contact,material,parameter,value,...; the material may be empty.
        if (sscanf(line, "%63[^,],%63[^,],%63[^,],%lf", contact, material, parameter, &v) == 4 ||
            (material[0] = '\0', sscanf(line, "%63[^,],,%63[^,],%lf", contact, parameter, &v) == 3))
            table_row(t, contact, material, parameter, v);
    }
    fclose(f);
    return 0;
}

static int cmd_export(char **argv)
{
    char err[512];
    cal_config *c = cal_config_load(argv[2], argv[3], err, sizeof err);
    if (!c) return fprintf(stderr, "drum_peers: %s\n", err), 2;
    cal_outcome o = {.config = c, .tier = cal_config_tier(c), .command = "drum_peers export", .ranks = 1, .workers = 1};
    int bad = read_table(argv[4], &o.table) || cal_report_write(argv[5], &o, err, sizeof err);
    if (bad) fprintf(stderr, "drum_peers: %s\n", err);
    cal_config_free(c);
    return bad ? 2 : 0;
}

static int write_data(const char *path, const dem_world *w, const exp_drum_def *d, int types)
{
    FILE *f = fopen(path, "w");
    if (!f) return perror(path), 1;
    dem_granules_view g = dem_world_granules(w);
    double box = 0.6 * d->diameter; // the world's own domain: 1.2 r either side
    fprintf(f, "granucal drum bed for the peers (seed %llu, lambda %g)\n\n%zu atoms\n%d atom types\n\n",
            (unsigned long long)d->seed, d->lambda, g.count, types);
    fprintf(f, "%.9g %.9g xlo xhi\n%.9g %.9g ylo yhi\n0 %.9g zlo zhi\n\nAtoms\n\n", -box, box, -box, box, d->depth);
    for (size_t i = 0; i < g.count; ++i) {
        double r = g.radius[i], rho = g.mass[i] / (4.0 / 3.0 * DEM_PI * r * r * r);
        fprintf(f, "%zu 1 %.9g %.9g %.12g %.12g %.12g\n", i + 1, 2 * r, rho, g.position[i].x, g.position[i].y,
                g.position[i].z);
    }
    return fclose(f) != 0;
}

static int cmd_bed(int argc, char **argv)
{
    char *sets[64];
    exp_drum_def d;
    exp_drum_run_opts run;
    if (load(argv[2], collect_sets(argc, argv, 5, sets), sets, &d, &run)) return 2;
    char err[512];
    dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!w) return fprintf(stderr, "drum_peers: %s\n", err), 2;
    // The turn starts from the bed tilted as exp_drum_rotate tilts it, at the
    // step it adopts: the peers start where granucal's turn starts.
    int bad = exp_drum_tilt(w, run.start_tilt_deg) != DEM_OK || dem_world_adopt_network_dt(w) != DEM_OK ||
              write_data(argv[4], w, &d, atoi(argv[3]));
    if (!bad)
        printf("rdrum=%.9g\ndepth=%.9g\ndt=%.6g\ngranules=%zu\n", 0.5 * d.diameter, d.depth, dem_world_dt(w),
               dem_world_granules(w).count);
    dem_world_destroy(w);
    return bad ? 2 : 0;
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
    if (argc == 6 && strcmp(argv[1], "export") == 0) return cmd_export(argv);
    if (argc >= 5 && strcmp(argv[1], "bed") == 0) return cmd_bed(argc, argv);
    if (argc >= 4 && strcmp(argv[1], "measure") == 0) return cmd_measure(argc, argv);
    fprintf(stderr, "usage: drum_peers export CALIBRATION.yaml TIER TABLE.csv OUTDIR\n"
                    "       drum_peers bed DRUM.yaml TYPES OUT.data [--set K=V ...]\n"
                    "       drum_peers measure DRUM.yaml DUMP [--set K=V ...]\n");
    return 2;
}
