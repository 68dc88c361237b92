// SPDX-License-Identifier: MIT
// Benchmark of issue 7 (not a test): the 40 rpm drum slice at Table 3's
// granule–granule parameters, in granucal, for a side-by-side comparison with
// LIGGGHTS 3.8 and LAMMPS (tests/bench/vs_peers.sh drives all three).
//
//   bench_drum_peers build N OUTDIR
//       Builds a settled bed of N granules in a periodic slice (axis z) of the
//       100 mm drum, with λ and slice depth chosen for N (see pick_scale), and
//       writes OUTDIR/drum_N.data (LAMMPS/LIGGGHTS read_data, atom style
//       sphere/granular: id type diameter density x y z), the peers' contact
//       coefficients (OUTDIR/drum_N.liggghts.coeffs, OUTDIR/drum_N.lammps.coeffs)
//       and OUTDIR/drum_N.vars (shell: λ, depth, dt_crit, granucal's steps).
//   bench_drum_peers tile DATA OUTDIR TILES...
//       The bed of DATA repeated TILES times along the axis, written like build.
//   bench_drum_peers run DATA STEPS THREADS VARIANT DT [RPM [allow]]   (DT 0: the engine's network step)
//       Reads DATA, builds the drum at the real parameters (VARIANT: all,
//       norolling, notangential: granules sorted by dem_world_sort_spatially;
//       unsorted: all, in the file's order), turns it at RPM (40) and times STEPS steps
//       of DT s on THREADS OpenMP threads; prints one CSV line (see HEADER)
//       with the angle and CSA before and after (the accuracy guard) and a
//       checksum of the final positions (bitwise equal for 1 and 2 threads).
//       `allow` accepts a DT above the engine's limit (stability study only).
//
// The bed: granules drawn from the scaled GSD, placed by random sequential
// addition (largest first) into the bottom of the drum, then dropped under
// gravity with springs κ = 20 times softer (fewer, longer steps; the
// implicit dashpot), and relaxed at the real stiffness. Only the geometry is
// kept: every code starts from the same positions at rest, with no history.
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "dem_gsd.h"
#include "dem_scaling.h"
#include "dem_world.h"
#include "exp_drum.h"
#include "exp_pour.h"

#define HEADER                                                                                                     \
    "code,N,threads,variant,steps,dt,loop_s,psps,maxrss_kib,angle0_deg,csa0_pct,angle1_deg,csa1_pct,ke_ratio0,"   \
    "ke_ratio1,contacts_per_granule,checksum,status"
#define DRUM_R 0.05
#define SOFT 20.0     // stiffness divisor while the bed drops
#define MASS_BINS 8   // atom types of the peers: granules binned by mass (damping per type pair)

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// λ and slice depth for a granule count: λ = 512, 216, 64 (λ^(1/3) = 8, 6, 4)
// keep the slice between ~4 largest diameters and the real drum's 44 mm;
// the depth then gives N at an apparent solid fraction of 0.53 in the 43 %
// segment (measured: the dropped bed's CSA then comes out near 43 %).
static void pick_scale(int n, double *lambda, double *depth)
{
    *lambda = n <= 8000 ? 512 : n <= 40000 ? 216 : 64;
    dem_gsd real = dem_default_gsd();
    double vmean = dem_gsd_mean_volume(&real) * *lambda;
    double bed_area = 0.43 * DEM_PI * DRUM_R * DRUM_R;
    *depth = n * vmean / (0.53 * bed_area);
}

// Area of the disc of radius a below height c (a circular segment).
static double segment_area(double a, double c)
{
    if (c <= -a) return 0;
    if (c >= a) return DEM_PI * a * a;
    return a * a * acos(-c / a) + c * sqrt(a * a - c * c);
}

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void) // splitmix64 → [0, 1)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

static int cmp_desc(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x < y) - (x > y);
}

// Random sequential addition into the drum's bottom segment, periodic in z.
// Writes centres (3 per granule); returns 0, or 1 if it ran out of room.
static int rsa_place(int n, const double *rad, double depth, double y_fill, double *pos)
{
    const double cs = 2.0 * rad[0]; // largest diameter (sorted descending)
    const int nx = (int)ceil(2 * DRUM_R / cs) + 1, nz = (int)floor(depth / cs) > 0 ? (int)floor(depth / cs) : 1;
    const double czs = depth / nz;
    int *head = malloc((size_t)nx * nx * nz * sizeof *head), *next = malloc((size_t)n * sizeof *next);
    if (!head || !next) return free(head), free(next), 1;
    for (int c = 0; c < nx * nx * nz; ++c) head[c] = -1;
    double y_top = y_fill;
    for (int i = 0; i < n; ++i) {
        const double r = rad[i], a = DRUM_R - r * 1.001;
        int placed = 0;
        for (int attempt = 0; !placed; ++attempt) {
            if (attempt > 0 && attempt % 400 == 0) y_top += 0.1 * cs; // saturated: let the segment grow
            if (y_top > a) break;
            double x = (2 * urand() - 1) * a, y = -a + urand() * (y_top + a), z = urand() * depth;
            if (x * x + y * y > a * a) continue;
            int ix = (int)((x + DRUM_R) / cs), iy = (int)((y + DRUM_R) / cs), iz = (int)(z / czs) % nz;
            int ok = 1;
            for (int dx = -1; dx <= 1 && ok; ++dx)
                for (int dy = -1; dy <= 1 && ok; ++dy)
                    for (int dzi = 0; dzi < (nz >= 3 ? 3 : nz) && ok; ++dzi) {
                        int jx = ix + dx, jy = iy + dy, jz = nz >= 3 ? (iz + dzi - 1 + nz) % nz : dzi;
                        if (jx < 0 || jy < 0 || jx >= nx || jy >= nx) continue;
                        for (int j = head[(jx * nx + jy) * nz + jz]; j >= 0 && ok; j = next[j]) {
                            double ddx = pos[3 * j] - x, ddy = pos[3 * j + 1] - y, ddz = pos[3 * j + 2] - z;
                            ddz -= depth * round(ddz / depth);
                            double s = r + rad[j];
                            ok = ddx * ddx + ddy * ddy + ddz * ddz >= s * s;
                        }
                    }
            if (!ok) continue;
            pos[3 * i] = x, pos[3 * i + 1] = y, pos[3 * i + 2] = z;
            int c = (ix * nx + iy) * nz + iz;
            next[i] = head[c], head[c] = i;
            placed = 1;
        }
        if (!placed) return free(head), free(next), 1;
    }
    free(head), free(next);
    return 0;
}

typedef struct scene {
    double lambda, depth;
    exp_drum_def drum;
    dem_contact_params gg, gw; // scaled granule–granule and granule–wall contacts
} scene;

static scene make_scene(double lambda, double depth)
{
    scene s;
    s.lambda = lambda, s.depth = depth;
    s.drum = exp_default_drum_def(); // Table 3: granule k = 200 N/m real, wall 2k
    s.drum.lambda = lambda, s.drum.depth = depth, s.drum.periodic = 1;
    s.gg = dem_scale_contact(&s.drum.granule, lambda);
    s.gw = dem_scale_contact(&s.drum.wall, lambda);
    return s;
}

static dem_world *create_world(const scene *s, const dem_contact_params *gg, const dem_contact_params *gw, double dt,
                               int threads, int implicit, int allow)
{
    dem_world_def def = dem_default_world_def();
    def.granule = *gg;
    def.domain_lo = dem_v3(-1.2 * DRUM_R, -1.2 * DRUM_R, 0);
    def.domain_hi = dem_v3(1.2 * DRUM_R, 1.2 * DRUM_R, s->depth);
    def.periodic_axis = 2;
    def.dt = dt;
    def.threads = threads;
    def.implicit_damping = implicit;
    def.allow_unstable_dt = allow;
    char err[512];
    dem_world *w = dem_world_create(&def, err, sizeof err);
    if (!w) {
        fprintf(stderr, "world: %s\n", err);
        exit(1);
    }
    dem_wall_def cyl = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 0, 1}, .radius = DRUM_R,
                        .contact = *gw, .name = "drum"};
    if (dem_world_add_wall(w, &cyl) < 0) {
        fprintf(stderr, "wall: %s\n", dem_world_error(w));
        exit(1);
    }
    return w;
}

static double d50_scaled(const scene *s) { return s->drum.gsd.median_diameter * cbrt(s->lambda); }

static void measure(const dem_world *w, const scene *s, exp_drum_measure *m)
{
    if (exp_drum_measure_now(w, &s->drum, 0.25 * d50_scaled(s), s->drum.closing_px, m))
        m->angle_deg = NAN; // too few surface columns
}

// ---------------------------------------------------------------- data file

static int write_data(const char *path, const dem_world *w, const scene *s, const double *bin_edges)
{
    FILE *f = fopen(path, "w");
    if (!f) return 1;
    dem_granules_view g = dem_world_granules(w);
    fprintf(f, "granucal bench_drum_peers lambda=%.17g depth=%.17g\n\n", s->lambda, s->depth);
    fprintf(f, "%zu atoms\n%d atom types\n\n", g.count, MASS_BINS + 1);
    fprintf(f, "%.17g %.17g xlo xhi\n%.17g %.17g ylo yhi\n0 %.17g zlo zhi\n\nAtoms\n\n", -1.2 * DRUM_R,
            1.2 * DRUM_R, -1.2 * DRUM_R, 1.2 * DRUM_R, s->depth);
    double rho = dem_scale_density(s->drum.density, s->lambda);
    for (size_t i = 0; i < g.count; ++i) {
        int t = 1;
        while (t < MASS_BINS && g.mass[i] > bin_edges[t]) ++t;
        fprintf(f, "%zu %d %.17g %.17g %.17g %.17g %.17g\n", i + 1, t, 2 * g.radius[i], rho, g.position[i].x,
                g.position[i].y, g.position[i].z);
    }
    return fclose(f);
}

typedef struct atom_rec {
    double d, rho, x, y, z;
} atom_rec;

// Reads a data file written above into a new world, granules in the file's
// order (placement order, random in space); returns NULL on error.
static dem_world *read_data(const char *path, scene *s, double dt, int threads, const dem_contact_params *gg,
                            int allow)
{
    FILE *f = fopen(path, "r");
    if (!f) return fprintf(stderr, "cannot open %s\n", path), NULL;
    char line[512];
    double lambda = 0, depth = 0;
    if (!fgets(line, sizeof line, f) || sscanf(line, "granucal bench_drum_peers lambda=%lf depth=%lf", &lambda, &depth) != 2)
        return fclose(f), fprintf(stderr, "%s: not a bench_drum_peers data file\n", path), NULL;
    *s = make_scene(lambda, depth);
    size_t n = 0, cap = 1024;
    atom_rec *a = malloc(cap * sizeof *a);
    int in_atoms = 0;
    while (a && fgets(line, sizeof line, f)) {
        if (!in_atoms) {
            in_atoms = strncmp(line, "Atoms", 5) == 0;
            continue;
        }
        long id;
        int t;
        atom_rec r = {0};
        if (sscanf(line, "%ld %d %lf %lf %lf %lf %lf", &id, &t, &r.d, &r.rho, &r.x, &r.y, &r.z) != 7) continue;
        if (n == cap) {
            atom_rec *b = realloc(a, 2 * cap * sizeof *a);
            if (!b) free(a);
            a = b, cap *= 2;
            if (!a) break;
        }
        a[n++] = r;
    }
    fclose(f);
    if (!a) return fprintf(stderr, "out of memory\n"), NULL;
    dem_contact_params p = gg ? *gg : s->gg;
    dem_world *w = create_world(s, &p, &s->gw, dt, threads, 0, allow);
    for (size_t i = 0; i < n; ++i)
        if (dem_world_add_granule(w, dem_v3(a[i].x, a[i].y, a[i].z), dem_v3(0, 0, 0), dem_v3(0, 0, 0), 0.5 * a[i].d,
                                  a[i].rho) < 0)
            return free(a), fprintf(stderr, "%s\n", dem_world_error(w)), dem_world_destroy(w), NULL;
    free(a);
    return w;
}

// ---------------------------------------------------------------- build

static dem_world *build_base(int n, scene *sp)
{
    double lambda, depth;
    pick_scale(n, &lambda, &depth);
    scene s = make_scene(lambda, depth);
    *sp = s;
    dem_gsd gsd = dem_scale_gsd(&s.drum.gsd, lambda);
    double *diam = malloc((size_t)n * sizeof *diam), *pos = malloc(3 * (size_t)n * sizeof *pos);
    if (!diam || !pos || dem_gsd_sample(&gsd, 1, (size_t)n, diam)) return fprintf(stderr, "sampling failed\n"), NULL;
    qsort(diam, (size_t)n, sizeof *diam, cmp_desc);
    for (int i = 0; i < n; ++i) diam[i] *= 0.5; // radii
    // Fill height: the segment (inset by half a median diameter) holding the
    // solid volume at a solid fraction of 0.32.
    double vol = 0;
    for (int i = 0; i < n; ++i) vol += 4.0 / 3.0 * DEM_PI * diam[i] * diam[i] * diam[i];
    double a = DRUM_R - 0.5 * gsd.median_diameter, lo = -a, hi = a, target = vol / (0.32 * depth);
    for (int it = 0; it < 60; ++it) {
        double mid = 0.5 * (lo + hi);
        if (segment_area(a, mid) < target) lo = mid;
        else hi = mid;
    }
    double t0 = now();
    if (rsa_place(n, diam, depth, hi, pos)) return fprintf(stderr, "no room for %d granules\n", n), NULL;
    fprintf(stderr, "build N=%d lambda=%g depth=%.4g m: placed in %.1f s\n", n, lambda, depth, now() - t0);
    // Drop with soft springs and the implicit dashpot: κ = 20 softer springs
    // allow a √20 longer step; the bed is only geometry for the benchmark.
    dem_contact_params soft = s.gg, softw = s.gw;
    soft.k_n /= SOFT, soft.k_s /= SOFT, soft.k_r /= SOFT;
    softw.k_n /= SOFT, softw.k_s /= SOFT, softw.k_r /= SOFT;
    soft.damping = softw.damping = DEM_DAMPING_ALWAYS;
    dem_world *w = create_world(&s, &soft, &softw, 0, 1, 1, 0);
    double rho = dem_scale_density(s.drum.density, lambda);
    for (int i = 0; i < n; ++i)
        dem_world_add_granule(w, dem_v3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]), dem_v3(0, 0, 0), dem_v3(0, 0, 0),
                              diam[i], rho);
    free(diam), free(pos);
    if (dem_world_prepare(w) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), NULL;
    fprintf(stderr, "drop: %s\n", dem_world_dt_report(w));
    const double d50 = gsd.median_diameter;
    double t = 0, ratio = 1;
    for (; t < 0.25; t += 0.01) {
        if (dem_world_step(w, (uint64_t)(0.01 / dem_world_dt(w)) + 1) != DEM_OK)
            return fprintf(stderr, "drop: %s\n", dem_world_error(w)), NULL;
        ratio = exp_ke_ratio(w, d50);
        fprintf(stderr, "  drop t=%.2f s KE ratio %.2e (wall %.0f s)\n", t + 0.01, ratio, now() - t0);
        if (t > 0.03 && ratio < 3e-4) break;
    }
    // Relax at the real stiffness until at rest again: the soft overlaps
    // spring open (the bed hops), and the dashpot (both phases) calms it.
    dem_contact_params real = s.gg, realw = s.gw;
    real.damping = realw.damping = DEM_DAMPING_ALWAYS;
    dem_world_set_granule_contact(w, &real);
    dem_world_set_wall_contact(w, 0, &realw);
    if (dem_world_adopt_network_dt(w) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), NULL;
    for (double tr = 0; tr < 0.1; tr += 0.005) {
        if (dem_world_step(w, (uint64_t)(0.005 / dem_world_dt(w))) != DEM_OK)
            return fprintf(stderr, "relax: %s\n", dem_world_error(w)), NULL;
        ratio = exp_ke_ratio(w, d50);
        fprintf(stderr, "  relax t=%.3f s KE ratio %.2e (wall %.0f s)\n", tr + 0.005, ratio, now() - t0);
        if (tr > 0.01 && ratio < 1e-4) break;
    }
    return w;
}

// Writes drum_<N>.data, the peers' coefficients and drum_<N>.vars for a bed.
static int emit(dem_world *w, const scene *sp, const char *outdir, double t0)
{
    const scene s = *sp;
    const double lambda = s.lambda, depth = s.depth, d50 = d50_scaled(&s);
    const int n = (int)dem_world_granules(w).count;
    if (dem_world_prepare(w) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1; // contact list
    // Mass bins of the peers' atom types (log-spaced between lightest and heaviest).
    dem_granules_view g = dem_world_granules(w);
    double mmin = INFINITY, mmax = 0, mtot = 0;
    for (size_t i = 0; i < g.count; ++i) {
        mmin = fmin(mmin, g.mass[i]), mmax = fmax(mmax, g.mass[i]), mtot += g.mass[i];
    }
    double edges[MASS_BINS + 1], rep[MASS_BINS + 1]; // edges[t-1]..edges[t] is type t; rep: geometric centre
    for (int b = 0; b <= MASS_BINS; ++b) edges[b] = mmin * pow(mmax / mmin, (double)b / MASS_BINS) * (b == MASS_BINS ? 1.000001 : 1);
    for (int b = 1; b <= MASS_BINS; ++b) rep[b] = sqrt(edges[b - 1] * edges[b]);
    char path[1024];
    snprintf(path, sizeof path, "%s/drum_%d.data", outdir, n);
    if (write_data(path, w, &s, edges)) return fprintf(stderr, "cannot write %s\n", path), 1;
    exp_drum_measure m;
    measure(w, &s, &m);
    dem_diagnostics dg = dem_world_diagnose(w);
    double median_mass = 0;
    {
        double *ms = malloc(g.count * sizeof *ms);
        for (size_t i = 0; i < g.count; ++i) ms[i] = g.mass[i];
        qsort(ms, g.count, sizeof *ms, cmp_desc);
        median_mass = ms[g.count / 2];
        free(ms);
    }

    // Granucal's own steps on the data as read back (explicit dashpot, the default).
    scene s2;
    dem_world *r = read_data(path, &s2, 0, 2, NULL, 0);
    if (!r || dem_world_prepare(r) != DEM_OK) return fprintf(stderr, "read back failed\n"), 1;
    double dt_apriori = dem_world_dt(r), dt_crit = sqrt(dem_world_min_mass(r) / s.gg.k_n);
    char rep_apriori[1024], rep_net[1024];
    snprintf(rep_apriori, sizeof rep_apriori, "%s", dem_world_dt_report(r));
    if (dem_world_adopt_network_dt(r) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(r)), 1;
    double dt_net = dem_world_dt(r);
    snprintf(rep_net, sizeof rep_net, "%s", dem_world_dt_report(r));
    dem_world_destroy(r);

    // Peers' coefficients. LIGGGHTS hooke/stiffness (absolute_damping off):
    // F_d = gamman·m*·v_n, so gamman = 2ξ sqrt(k/m*) per type pair, m* from
    // the bins' representative masses; the wall (type MASS_BINS+1) has m* = m_i.
    const int nt = MASS_BINS + 1;
    double kn[MASS_BINS + 2][MASS_BINS + 2], gam[MASS_BINS + 2][MASS_BINS + 2], mu[MASS_BINS + 2][MASS_BINS + 2],
        mur[MASS_BINS + 2][MASS_BINS + 2];
    for (int i = 1; i <= nt; ++i)
        for (int j = 1; j <= nt; ++j) {
            int wall = i == nt || j == nt;
            const dem_contact_params *p = wall ? &s.gw : &s.gg;
            // A wall side takes its partner's bin; wall–wall (never in contact) takes bin 1.
            const int bi = i < nt ? i : j < nt ? j : 1, bj = j < nt ? j : i < nt ? i : 1;
            double mi = rep[bi], mj = rep[bj];
            double mstar = wall ? (i == nt ? mj : mi) : mi * mj / (mi + mj);
            kn[i][j] = p->k_n, gam[i][j] = 2 * p->xi * sqrt(p->k_n / mstar), mu[i][j] = p->mu_s, mur[i][j] = p->mu_r;
        }
    snprintf(path, sizeof path, "%s/drum_%d.liggghts.coeffs", outdir, n);
    FILE *f = fopen(path, "w");
    if (!f) return 1;
    fprintf(f, "# generated by bench_drum_peers build %d: %d mass bins + wall type %d\n", n, MASS_BINS, nt);
    const char *names[] = {"kn", "kt", "gamman", "gammat", "coefficientFriction", "coefficientRollingFriction"};
    for (int q = 0; q < 6; ++q) {
        fprintf(f, "fix m%d all property/global %s peratomtypepair %d", q + 1, names[q], nt);
        for (int i = 1; i <= nt; ++i)
            for (int j = 1; j <= nt; ++j)
                fprintf(f, " %.10g", q < 2 ? kn[i][j] : q == 2 ? gam[i][j] : q == 3 ? 0.0 : q == 4 ? mu[i][j] : mur[i][j]);
        fprintf(f, "\n");
    }
    fclose(f);
    // LAMMPS granular: hooke with damping mass_velocity (F_d = η_n0·m*·v_n),
    // linear_history without tangential damping, rolling sds without damping.
    snprintf(path, sizeof path, "%s/drum_%d.lammps.coeffs", outdir, n);
    f = fopen(path, "w");
    if (!f) return 1;
    fprintf(f, "# generated by bench_drum_peers build %d: %d mass bins\n", n, MASS_BINS);
    for (int i = 1; i <= MASS_BINS; ++i)
        for (int j = i; j <= MASS_BINS; ++j)
            fprintf(f,
                    "pair_coeff %d %d hooke %.10g %.10g tangential linear_history %.10g 0.0 %.10g rolling sds %.10g "
                    "0.0 %.10g damping mass_velocity\n",
                    i, j, s.gg.k_n, gam[i][j], s.gg.k_s, s.gg.mu_s, s.gg.k_r, s.gg.mu_r);
    fprintf(f, "pair_coeff %d %d hooke %.10g %.10g tangential linear_history %.10g 0.0 %.10g rolling sds %.10g 0.0 "
               "%.10g damping mass_velocity\n",
            nt, nt, s.gg.k_n, gam[1][1], s.gg.k_s, s.gg.mu_s, s.gg.k_r, s.gg.mu_r);
    for (int i = 1; i <= MASS_BINS; ++i) // the wall type holds no atoms
        fprintf(f, "pair_coeff %d %d hooke %.10g %.10g tangential linear_history %.10g 0.0 %.10g rolling sds %.10g 0.0 "
                   "%.10g damping mass_velocity\n",
                i, nt, s.gg.k_n, gam[i][i], s.gg.k_s, s.gg.mu_s, s.gg.k_r, s.gg.mu_r);
    fclose(f);
    snprintf(path, sizeof path, "%s/drum_%d.vars", outdir, n);
    f = fopen(path, "w");
    if (!f) return 1;
    fprintf(f, "# generated by bench_drum_peers build %d\n", n);
    fprintf(f, "N=%zu\nLAMBDA=%g\nDEPTH=%.17g\nRDRUM=%g\nKN=%.10g\nKW=%.10g\nXI=%g\nMU=%g\nMUR=%g\n", g.count, lambda,
            depth, DRUM_R, s.gg.k_n, s.gw.k_n, s.gg.xi, s.gg.mu_s, s.gg.mu_r);
    // LAMMPS' wall takes one coefficient set: damping at the median mass.
    fprintf(f, "ETA_WALL=%.10g\nMEDIAN_MASS=%.10g\nBED_MASS=%.10g\nD50=%.10g\n", 2 * s.gw.xi * sqrt(s.gw.k_n / median_mass),
            median_mass, mtot, d50);
    fprintf(f, "DT_CRIT=%.10g\nDT_APRIORI=%.10g\nDT_NETWORK=%.10g\n", dt_crit, dt_apriori, dt_net);
    fprintf(f, "OMEGA=%.10g\n", 40 * 2 * DEM_PI / 60);
    fprintf(f, "SKIN=%.10g\n", 0.4 * dem_world_min_radius(w));
    fprintf(f, "BED_ANGLE=%.3f\nBED_CSA=%.3f\nBED_COORD=%.3f\n", m.angle_deg, m.csa_percent, dg.coordination);
    fprintf(f, "# a priori: %s\n# network: %s\n", rep_apriori, rep_net);
    fclose(f);
    fprintf(stderr, "bed: %zu granules, angle %.2f deg, CSA %.2f %%, coordination %.2f; dt_crit %.4g s, a priori %.4g "
                    "(%.3f), network %.4g (%.3f); total %.0f s\n",
            g.count, m.angle_deg, m.csa_percent, dg.coordination, dt_crit, dt_apriori, dt_apriori / dt_crit, dt_net,
            dt_net / dt_crit, now() - t0);
    return 0;
}

// The bed replicated `tiles` times along the periodic axis: the slab was
// settled periodic in z, so the copies fit seam to seam and the long slice is
// as settled as the short one (same λ, same step: cost per particle-step
// comparable across N).
static dem_world *tile_bed(const dem_world *base, const scene *sb, int tiles, scene *st)
{
    *st = make_scene(sb->lambda, sb->depth * tiles);
    dem_world *w = create_world(st, &st->gg, &st->gw, 0, 2, 0, 0);
    dem_granules_view g = dem_world_granules(base);
    double rho = dem_scale_density(sb->drum.density, sb->lambda);
    for (int k = 0; k < tiles; ++k)
        for (size_t i = 0; i < g.count; ++i)
            dem_world_add_granule(w, dem_v3(g.position[i].x, g.position[i].y, g.position[i].z + k * sb->depth),
                                  dem_v3(0, 0, 0), dem_v3(0, 0, 0), g.radius[i], rho);
    return w;
}

// Writes the bed repeated by each count in `tiles`; consumes `w`.
static int emit_tiles(dem_world *w, const scene *s, const char *outdir, int ntiles, char **tiles, double t0)
{
    int rc = 0;
    for (int k = 0; k < ntiles && rc == 0; ++k) {
        scene st;
        dem_world *big = tile_bed(w, s, atoi(tiles[k]), &st);
        rc = emit(big, &st, outdir, t0);
        dem_world_destroy(big);
    }
    dem_world_destroy(w);
    return rc;
}

static int cmd_build(int n, const char *outdir, int ntiles, char **tiles)
{
    double t0 = now();
    scene s;
    dem_world *w = build_base(n, &s);
    if (!w) return 1;
    if (emit(w, &s, outdir, t0)) return dem_world_destroy(w), 1;
    return emit_tiles(w, &s, outdir, ntiles, tiles, t0);
}

// Tiles of an existing bed's data file (the same settled slab, so a larger N
// is added without settling the base again).
static int cmd_tile(const char *data, const char *outdir, int ntiles, char **tiles)
{
    double t0 = now();
    scene s;
    dem_world *w = read_data(data, &s, 0, 2, NULL, 0);
    if (!w) return 1;
    return emit_tiles(w, &s, outdir, ntiles, tiles, t0);
}

// ---------------------------------------------------------------- run

static double checksum(const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    double c = 0;
    for (size_t i = 0; i < g.count; ++i)
        c += (double)(g.id[i] % 97 + 1) * (g.position[i].x + 3 * g.position[i].y + 7 * g.position[i].z);
    return c;
}

static int cmd_run(const char *data, long steps, int threads, const char *variant, double dt, double rpm, int allow)
{
    scene s;
    dem_contact_params p = dem_default_world_def().granule; // overwritten below from the scene
    FILE *probe = fopen(data, "r");
    if (!probe) return fprintf(stderr, "cannot open %s\n", data), 1;
    fclose(probe);
    // First read with the scene's own contact, then apply the variant.
    const int unsorted = strcmp(variant, "unsorted") == 0;
    dem_world *w = read_data(data, &s, dt, threads, NULL, allow);
    if (!w) return 1;
    p = s.gg;
    if (strcmp(variant, "norolling") == 0) p.mu_r = 0;
    else if (strcmp(variant, "notangential") == 0) p.mu_s = 0;
    else if (strcmp(variant, "all") != 0 && !unsorted)
        return fprintf(stderr, "variant: all, norolling, notangential or unsorted\n"), 1;
    // As exp_drum does with a settled bed; `unsorted` keeps the file's order.
    if (!unsorted && dem_world_sort_spatially(w) != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
    dem_world_set_granule_contact(w, &p);
    // DT 0: the step the engine picks for this settled bed (its network step,
    // as exp_drum_rotate turns a drum).
    dem_status st = dt > 0 ? dem_world_prepare(w) : dem_world_adopt_network_dt(w);
    if (st != DEM_OK) return fprintf(stderr, "%s\n", dem_world_error(w)), 1;
    fprintf(stderr, "%s\n", dem_world_dt_report(w));
    size_t n = dem_world_granules(w).count;
    const double d50 = d50_scaled(&s);
    exp_drum_measure m0, m1;
    measure(w, &s, &m0);
    double ke0 = exp_ke_ratio(w, d50);
    dem_world_set_wall_spin(w, 0, rpm * 2 * DEM_PI / 60);
    st = dem_world_step(w, 0); // the first force evaluation (and list) outside the timing
    double t0 = now();
    if (st == DEM_OK) st = dem_world_step(w, (uint64_t)steps);
    double loop = now() - t0;
    measure(w, &s, &m1);
    dem_diagnostics dg = dem_world_diagnose(w);
    fprintf(stderr, "list: %.2f pairs per granule (%.2f in contact), %llu rebuilds\n", (double)dg.list_pairs / (double)n,
            (double)dg.contacts / (double)n, (unsigned long long)dg.list_rebuilds);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("granucal,%zu,%d,%s,%ld,%.6g,%.4f,%.5g,%ld,%.2f,%.2f,%.2f,%.2f,%.3g,%.3g,%.3f,%a,%s\n", n, threads, variant,
           steps, dem_world_dt(w), loop, (double)n * (double)steps / loop, ru.ru_maxrss, m0.angle_deg, m0.csa_percent,
           m1.angle_deg, m1.csa_percent, ke0, exp_ke_ratio(w, d50), dg.coordination, checksum(w),
           st == DEM_OK ? "ok" : dem_world_error(w));
    dem_world_destroy(w);
    return st == DEM_OK ? 0 : 3;
}

int main(int argc, char **argv)
{
    if (argc >= 4 && strcmp(argv[1], "build") == 0) return cmd_build(atoi(argv[2]), argv[3], argc - 4, argv + 4);
    if (argc >= 5 && strcmp(argv[1], "tile") == 0) return cmd_tile(argv[2], argv[3], argc - 4, argv + 4);
    if (argc >= 7 && strcmp(argv[1], "run") == 0)
        return cmd_run(argv[2], atol(argv[3]), atoi(argv[4]), argv[5], atof(argv[6]), argc > 7 ? atof(argv[7]) : 40,
                       argc > 8 && strcmp(argv[8], "allow") == 0);
    if (argc >= 2 && strcmp(argv[1], "header") == 0) return puts(HEADER), 0;
    fprintf(stderr,
            "usage: %s build N OUTDIR [TILES...] | tile DATA OUTDIR TILES... | run DATA STEPS THREADS all|norolling|notangential|unsorted DT [RPM [allow]] | header\n",
            argv[0]);
    return 2;
}
