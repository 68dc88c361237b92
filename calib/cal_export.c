// SPDX-License-Identifier: MIT
// The calibrated table as input for LIGGGHTS and LAMMPS (see cal_export.h).
#include "cal_export.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cal_status.h"
#include "cal_util.h"
#include "dem_gsd.h"
#include "exp_common.h"
#include "exp_contact_rules.h"

// What each export leaves out of the paper's model: written into its file's
// header and into report.md.
static const char *const liggghts_differences[] = {
    "hooke/stiffness damps with gamman*m_eff per type pair; the paper's 2*xi*sqrt(m* k) depends on each\n"
    "pair's m*. Its gamman is exact for two median granules (and for wall contacts of one).",
    "the dashpot acts while the granules part too; the paper's eq. 4 switch has no counterpart.",
    "rolling_friction epsd2 never turns its rolling spring onto the new tangent plane, and sets its\n"
    "rolling stiffness from kt; the paper (and granucal) carry it and use k_r = k_n.",
    "LIGGGHTS 3.8 needs dt <= ~0.35 dt_crit to keep a dense bed at rest with xi = 0.7.",
    NULL};
static const char *const lammps_differences[] = {
    "damping mass_velocity takes one rate per type pair (gamma/m*, exact for two median granules and\n"
    "for a wall and one).",
    "the dashpot acts while the granules part too (the paper's eq. 4 switch has no counterpart).",
    "rolling sds has its own spring history (carried like the paper's).",
    "no tangential damping (xgammat = 0), as in the paper's model.",
    NULL};

// The list as "- item" lines, each continuation line under `indent`.
static void write_differences(FILE *f, const char *const *items, const char *bullet, const char *indent)
{
    for (; *items; ++items) {
        fputs(bullet, f);
        for (const char *c = *items; *c; ++c) {
            fputc(*c, f);
            if (*c == '\n') fputs(indent, f);
        }
        fputc('\n', f);
    }
}

// What the table is and which of its values the data did not choose, as
// comment lines: the export is what a user copies, so it must say it.
static void write_status(FILE *f, const cal_outcome *o)
{
    cal_run_status rs = cal_run_status_of(o);
    cal_run_status_banner(f, &rs, "# ");
    long before = ftell(f);
    cal_table_caveats(f, o, "# NOT CALIBRATED: ");
    if (ftell(f) == before) fputs("# Every friction below was chosen by the data.\n", f);
}

// The paper's dashpot is γ_n = 2ξ sqrt(m* k) (eq. 5); LIGGGHTS' hooke/stiffness
// (absolute_damping off) and LAMMPS' mass_velocity damping take one rate per
// type pair, γ/m* = 2ξ sqrt(k/m*), and multiply it by the contact's own m*.
// Both codes, like granucal, give a wall contact m* = m_i, so the rate is
// exact for two median granules (m* = m/2) and for a wall and one (m* = m).
static double damping_rate(const cal_config *c, double k, int wall)
{
    double m = c->density * DEM_PI / 6 * pow(c->median_diameter, 3);
    return 2 * c->xi * sqrt(k / (wall ? m : 0.5 * m));
}

// The table is the real powder's; a scene of coarse granules sets `lambda`
// (`-var lambda L` on the command line, or `variable lambda index L` before
// the include: an index variable already defined is kept) and every value
// below follows eq. 15-18: stiffness × λ^(-1/3) (eq. 18); the granule mass is
// unchanged (eq. 16), so the damping rate × λ^(-1/6); friction unchanged.
// The diameters × λ^(1/3) and the density / λ are the scene's (its atoms).
static void write_scaling(FILE *f, const cal_table *t)
{
    fprintf(f, "# Coarse graining (eq. 15-18): the values are the real powder's (lambda = 1); a scene of coarse granules\n"
               "# sets lambda (-var lambda L) and gets stiffness x L^(-1/3) and damping rate x L^(-1/6) (the granule\n"
               "# mass is unchanged); its atoms take diameter x L^(1/3) and density %g / L.\n"
               "variable lambda index 1\n"
               "variable gc_k equal v_lambda^(-1.0/3.0)\n"
               "variable gc_g equal v_lambda^(-1.0/6.0)\n",
            t->density);
}

// One entry of the LIGGGHTS type-pair matrices, as an immediate expression
// in the scaling variables where it scales.
static void liggghts_entry(FILE *f, const cal_outcome *o, int p, int i, int j)
{
    const cal_table *t = &o->table;
    int wall = (i == 0) != (j == 0), gg = i == 0 && j == 0, w = (i ? i : j) - 1;
    double k = wall ? exp_boundary_stiffness(t->k_n) : t->k_n; // wall-wall pairs never touch: any value
    if (p < 2) fprintf(f, " $(%.6g*v_gc_k)", k);
    else if (p == 2) fprintf(f, " $(%.6g*v_gc_g)", damping_rate(o->config, k, wall));
    else if (p == 3) fputs(" 0", f); // no tangential damping in the paper's model
    else if (p == 4) fprintf(f, " %.6g", gg ? t->gg_mu_s : wall ? t->wall_mu_s[w] : 0);
    else fprintf(f, " %.6g", gg ? t->gg_mu_r : wall ? t->wall_mu_r[w] : 0);
}

static int write_liggghts(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    const cal_table *t = &o->table;
    char path[1200];
    snprintf(path, sizeof path, "%s/liggghts_parameters.in", dir);
    cal_atomic_file a;
    if (cal_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    int n = 1 + t->n_walls;
    fprintf(f, "# granucal %s: the table's parameters for LIGGGHTS 3.8.\n", exp_version());
    write_status(f, o);
    fputs("# atom type 1 = granules", f);
    for (int w = 0; w < t->n_walls; ++w) fprintf(f, ", %d = %s wall", w + 2, t->wall_name[w]);
    fputs(" (a wall: fix wall/gran ... primitive type N, same model keywords)\n# Differences from the paper's model:\n", f);
    write_differences(f, liggghts_differences, "#  - ", "#    ");
    write_scaling(f, t);
    fputs("pair_style gran model hooke/stiffness tangential history rolling_friction epsd2 absolute_damping off\n"
          "pair_coeff * *\n", f);
    const char *keys[] = {"kn", "kt", "gamman", "gammat", "coefficientFriction", "coefficientRollingFriction"};
    for (int p = 0; p < 6; ++p) {
        fprintf(f, "fix m%d all property/global %s peratomtypepair %d", p + 1, keys[p], n);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) liggghts_entry(f, o, p, i, j);
        fputc('\n', f);
    }
    return cal_atomic_commit(&a, err, len);
}

// The granular keywords of one contact for LAMMPS, stiffness and damping
// scaled by lambda.
static void lammps_keywords(FILE *f, const cal_config *c, double k, double mu_s, double mu_r, int wall)
{
    fprintf(f, "hooke $(%.6g*v_gc_k) $(%.6g*v_gc_g) tangential linear_history $(%.6g*v_gc_k) 0 %.6g "
               "rolling sds $(%.6g*v_gc_k) 0 %.6g damping mass_velocity",
            k, damping_rate(c, k, wall), k, mu_s, k, mu_r);
}

static int write_lammps(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    const cal_table *t = &o->table;
    char path[1200];
    snprintf(path, sizeof path, "%s/lammps_parameters.in", dir);
    cal_atomic_file a;
    if (cal_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    fprintf(f, "# granucal %s: the table's parameters for LAMMPS pair_style granular.\n", exp_version());
    write_status(f, o);
    fputs("# Differences from the paper's model:\n", f);
    write_differences(f, lammps_differences, "#  - ", "#    ");
    fputs("# Walls: fix ID all wall/gran/region granular ${wall_<material>} region R\n", f);
    write_scaling(f, t);
    fputs("pair_style granular\npair_coeff 1 1 ", f);
    lammps_keywords(f, o->config, t->k_n, t->gg_mu_s, t->gg_mu_r, 0);
    fputc('\n', f);
    for (int w = 0; w < t->n_walls; ++w) {
        // A variable name is letters, digits and underscores.
        char name[32];
        snprintf(name, sizeof name, "%s", t->wall_name[w]);
        for (char *p = name; *p; ++p)
            if (!isalnum((unsigned char)*p)) *p = '_';
        fprintf(f, "variable wall_%s string \"", name);
        lammps_keywords(f, o->config, exp_boundary_stiffness(t->k_n), t->wall_mu_s[w], t->wall_mu_r[w], 1);
        fputs("\"\n", f);
    }
    return cal_atomic_commit(&a, err, len);
}

int cal_export_write(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    return write_liggghts(dir, o, err, len) || write_lammps(dir, o, err, len);
}

// The exported tables: what they leave out, and the peers check of DIR/peers
// when one was run on this table (tests/peers/drum_peers.sh writes its summary.txt).
void cal_export_report(FILE *f, const char *dir)
{
    fputs("\n## The table in LIGGGHTS and LAMMPS\n\n`liggghts_parameters.in` (LIGGGHTS 3.8) leaves out of the paper's "
          "model:\n\n", f);
    write_differences(f, liggghts_differences, "- ", "  ");
    fputs("\n`lammps_parameters.in` (LAMMPS `pair_style granular`):\n\n", f);
    write_differences(f, lammps_differences, "- ", "  ");
    char path[1200], line[512];
    snprintf(path, sizeof path, "%s/peers/summary.txt", dir);
    FILE *s = fopen(path, "r");
    if (!s) {
        fprintf(f, "\nNo peers check was run on this table. `TABLE=%s/calibrated_parameters.csv bash "
                   "tests/peers/drum_peers.sh build/granucal build/tests/drum_peers %s/peers` runs both files as "
                   "written on the ci drum slice beside granucal and measures them alike; the report then shows its "
                   "numbers. At the ci table: `results/peers/README.md`.\n", dir, dir);
        return;
    }
    fputs("\nThe peers check run on this table (`tests/peers/drum_peers.sh`, its `peers/summary.txt`):\n\n```\n", f);
    while (fgets(line, sizeof line, s)) fputs(line, f);
    fputs("```\n", f);
    fclose(s);
}

