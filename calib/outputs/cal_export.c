// SPDX-License-Identifier: MIT
// The calibrated table as input for LIGGGHTS and LAMMPS (see cal_export.h).
#include "cal_export.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cal_case_runs.h"
#include "cal_files.h"
#include "cal_status.h"
#include "dem_gsd.h"
#include "dem_scaling.h"
#include "dem_world.h"
#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_cost.h"
#include "exp_drum.h"

// LIGGGHTS' contact model, the granules' and the walls' alike.
static const char liggghts_model[] =
    "model hooke/stiffness tangential history rolling_friction epsd2";

// LIGGGHTS' step for a bed at rest, as every export has stated it since the first (61f29cb).
#define LIGGGHTS_STEP_NOTE "LIGGGHTS 3.8 needs dt <= ~0.35 dt_crit to keep a dense bed at rest with xi = 0.7."

// What each export leaves out of the paper's model: written into its file's
// header and into report.md.
static const char *const liggghts_differences[] = {
    "hooke/stiffness damps with gamman*m_eff per type pair; the paper's 2*xi*sqrt(m* k) depends on each\n"
    "pair's m*. Its gamman is exact for two median granules (and for wall contacts of one).",
    "the dashpot acts while the granules part too; the paper's eq. 4 switch has no counterpart.",
    "rolling_friction epsd2 never turns its rolling spring onto the new tangent plane, and sets its\n"
    "rolling stiffness from kt; the paper (and granucal) carry it and use k_r = k_n.",
    LIGGGHTS_STEP_NOTE,
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
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    int n = 1 + t->n_walls;
    fprintf(f, "# granucal %s: the table's parameters for LIGGGHTS 3.8.\n", exp_version());
    write_status(f, o);
    fputs("# atom type 1 = granules", f);
    for (int w = 0; w < t->n_walls; ++w) fprintf(f, ", %d = %s wall", w + 2, t->wall_name[w]);
    fputs(" (a wall: fix wall/gran ... primitive type N, same model keywords)\n# Differences from the paper's model:\n", f);
    write_differences(f, liggghts_differences, "#  - ", "#    ");
    write_scaling(f, t);
    fprintf(f, "pair_style gran %s absolute_damping off\npair_coeff * *\n", liggghts_model);
    const char *keys[] = {"kn", "kt", "gamman", "gammat", "coefficientFriction", "coefficientRollingFriction"};
    for (int p = 0; p < 6; ++p) {
        fprintf(f, "fix m%d all property/global %s peratomtypepair %d", p + 1, keys[p], n);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) liggghts_entry(f, o, p, i, j);
        fputc('\n', f);
    }
    return exp_atomic_commit(&a, err, len);
}

// The granular keywords of one contact for LAMMPS, stiffness and damping
// scaled by lambda.
static void lammps_keywords(FILE *f, const cal_config *c, double k, double mu_s, double mu_r, int wall)
{
    fprintf(f, "hooke $(%.6g*v_gc_k) $(%.6g*v_gc_g) tangential linear_history $(%.6g*v_gc_k) 0 %.6g "
               "rolling sds $(%.6g*v_gc_k) 0 %.6g damping mass_velocity",
            k, damping_rate(c, k, wall), k, mu_s, k, mu_r);
}

// A material's name as a LAMMPS variable name: letters, digits and underscores.
static const char *lammps_name(char out[32], const char *material)
{
    snprintf(out, 32, "%s", material);
    for (char *p = out; *p; ++p)
        if (!isalnum((unsigned char)*p)) *p = '_';
    return out;
}

static int write_lammps(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    const cal_table *t = &o->table;
    char path[1200];
    snprintf(path, sizeof path, "%s/lammps_parameters.in", dir);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
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
        char name[32];
        fprintf(f, "variable wall_%s string \"", lammps_name(name, t->wall_name[w]));
        lammps_keywords(f, o->config, exp_boundary_stiffness(t->k_n), t->wall_mu_s[w], t->wall_mu_r[w], 1);
        fputs("\"\n", f);
    }
    return exp_atomic_commit(&a, err, len);
}

// ---------------------------------------------------------------------------
// The complete decks (liggghts_drum.in, lammps_drum.in): the calibration's own
// drum at its tier, filled, cut to its fill degree, turned and dumped, with
// the parameter files above included unchanged. Every length, density,
// stiffness and time step is written as an expression in `lambda`, so that
// `-var lambda L` gives the same drum at another coarse graining.

enum { DECK_BINS = 8 };

static void deck_path(char *out, size_t len, const char *dir, const char *code)
{
    snprintf(out, len, "%s/%s_drum.in", dir, code);
}

#define DECK_POUR_PASS_S 0.2   // s a pass of the pour falls and lands before the next
#define DECK_SETTLE_S 0.5      // s the bed settles after the pour, and again after the cut
#define DECK_SPINUP_S 1.0      // s turned before the first frame is dumped

// What the decks need of the drum the calibration simulated.
typedef struct deck_scene {
    exp_drum_def drum;                        // cal_drum_case_granule: the drum, the powder, lambda, contacts
    exp_drum_run_opts run;                    // the tier's turn: max_time, sample_interval
    double rpm[CAL_MAX_RPM];                  // the speeds the calibration turned
    int n_rpm;
    int bins;                                 // the GSD in classes (gsd_bins), real diameters
    double bin_d[DECK_BINS], bin_p[DECK_BINS];
    double dt_crit, dt;                       // s, at the tier's lambda (granucal_step)
    char dt_report[400];                      // the engine's own account of its step
    double level;                             // m above the axis: the fill level
} deck_scene;

static double normal_cdf(double z) { return 0.5 * erfc(-z / sqrt(2.0)); }

// The truncated log-normal in `DECK_BINS` classes equally wide in log d:
// each class's number fraction, and the diameter of its mean granule volume,
// so that N granules drawn from the classes carry the GSD's solid volume.
static int gsd_bins(const dem_gsd *g, double *d, double *p)
{
    const double s = log(g->geometric_sd), t = g->truncation_sigmas;
    if (!(s > 0)) return d[0] = g->median_diameter, p[0] = 1, 1;
    const double kept = normal_cdf(t) - normal_cdf(-t), width = 2 * t / DECK_BINS;
    for (int k = 0; k < DECK_BINS; ++k) {
        double z0 = -t + k * width, z1 = z0 + width, n = normal_cdf(z1) - normal_cdf(z0);
        // E[d^3 | class] = d50^3 e^(9 s^2 / 2) [Phi(z1 - 3s) - Phi(z0 - 3s)] / [Phi(z1) - Phi(z0)]
        double m3 = exp(4.5 * s * s) * (normal_cdf(z1 - 3 * s) - normal_cdf(z0 - 3 * s)) / n;
        d[k] = g->median_diameter * cbrt(m3), p[k] = n / kept;
    }
    return DECK_BINS;
}

// The step granucal chooses for this drum before it runs (dem_world_prepare's
// a-priori limit of the densest cluster of its lightest granules, at
// dt_safety of it): a world of the drum's wall and one lightest granule.
static int granucal_step(deck_scene *s, char *err, size_t len)
{
    const exp_drum_def *d = &s->drum;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    double r = 0.5 * d->diameter;
    dem_world_def def = dem_default_world_def();
    def.granule = dem_scale_contact(&d->granule, d->lambda);
    def.domain_lo = dem_v3(-1.2 * r, -1.2 * r, -1), def.domain_hi = dem_v3(1.2 * r, 1.2 * r, 1);
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return 1;
    dem_wall_def cyl = {.kind = DEM_WALL_CYLINDER, .axis = {0, 0, 1}, .radius = r,
                        .contact = dem_scale_contact(&d->wall, d->lambda), .name = "drum"};
    int bad = dem_world_add_wall(w, &cyl) < 0 ||
              dem_world_add_granule(w, dem_v3(0, 0, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0),
                                    0.5 * dem_gsd_min_diameter(&gsd), dem_scale_density(d->density, d->lambda)) < 0 ||
              dem_world_prepare(w) != DEM_OK;
    if (bad) snprintf(err, len, "export: the drum's time step: %s", dem_world_error(w));
    s->dt = dem_world_dt(w);
    snprintf(s->dt_report, sizeof s->dt_report, "%s", dem_world_dt_report(w));
    dem_world_destroy(w);
    s->dt_crit = exp_lightest_dt_crit(&d->gsd, d->density, d->granule.k_n, d->lambda);
    return bad;
}

// The speeds the calibration turned: its stages' (the granule stage's, else
// the first wall's), else the tier's list.
static void scene_speeds(deck_scene *s, const cal_outcome *o)
{
    const cal_friction_result *r = o->granule ? o->granule : o->n_walls > 0 ? o->walls[0] : NULL;
    s->n_rpm = 0;
    for (int k = 0; r && k < r->n_rpm && k < CAL_MAX_RPM; ++k) s->rpm[s->n_rpm++] = r->rpm[k];
    for (unsigned k = 0; r == NULL && k < o->tier->rpm_count && k < CAL_MAX_RPM; ++k) s->rpm[s->n_rpm++] = o->tier->rpm[k];
}

static int scene_of(const cal_outcome *o, deck_scene *s, char *err, size_t len)
{
    const cal_table *t = &o->table;
    memset(s, 0, sizeof *s);
    cal_drum_case c = cal_drum_case_granule(o->config, o->tier, t->k_n, t->gg_mu_s, t->gg_mu_r);
    s->drum = c.def, s->run = c.run;
    scene_speeds(s, o);
    s->bins = gsd_bins(&s->drum.gsd, s->bin_d, s->bin_p);
    double r = 0.5 * s->drum.diameter;
    s->level = exp_drum_fill_level(r, s->drum.fill);
    return granucal_step(s, err, len);
}

// The deck's opening: what it is, how to run it, and the run's status.
static void deck_title(FILE *f, const cal_outcome *o, const char *code, const char *exe, const char *name,
                       const char *params)
{
    fprintf(f, "# granucal %s: the calibrated drum as a complete %s deck. Run it as written, in this folder\n"
               "# (it includes %s):   %s -in %s [-var NAME VALUE ...]\n",
            exp_version(), code, params, exe, name);
    write_status(f, o);
}

// The drum, the powder and the coarse graining, in words.
static void deck_scene_text(FILE *f, const cal_outcome *o, const deck_scene *s)
{
    const exp_drum_def *d = &s->drum;
    fprintf(f, "#\n# The drum: the calibration's own at tier '%s': %g mm across, ", o->tier->name, 1e3 * d->diameter);
    if (d->periodic) fprintf(f, "a %g mm slice periodic along z (the drum axis), ", 1e3 * d->depth);
    else fprintf(f, "%g mm deep between its end plates, ", 1e3 * d->depth);
    fprintf(f, "%g %% full; gravity -y,\n# the drum turning counter-clockwise seen from +z (granucal's positive rpm). "
               "The calibration turned it at", 100 * d->fill);
    for (int k = 0; k < s->n_rpm; ++k) fprintf(f, "%s %g", k ? "," : "", s->rpm[k]);
    fprintf(f, "%s rpm.\n# The powder: log-normal by number, median %g um, sigma_g %g, truncated at +-%g sigma, "
               "density %g kg/m3,\n# poured as %d classes equally wide in log d (diameter of the class's mean "
               "volume, number fraction):\n#  ",
            s->n_rpm ? "" : " (no speed)", 1e6 * d->gsd.median_diameter, d->gsd.geometric_sd,
            d->gsd.truncation_sigmas, d->density, s->bins);
    for (int k = 0; k < s->bins; ++k) fprintf(f, " %.4g um %.4g%s", 1e6 * s->bin_d[k], s->bin_p[k], k + 1 < s->bins ? "," : "\n");
    fprintf(f, "# Coarse graining (eq. 15-18) at lambda (the tier's: %g): diameters x lambda^(1/3), density / lambda, "
               "stiffness\n# x lambda^(-1/3) (the parameter file); the lengths below are the real drum's.\n",
            d->lambda);
}

// Why the time step is what it is, with the numbers.
static void deck_step_text(FILE *f, const deck_scene *s)
{
    const exp_drum_def *d = &s->drum;
    dem_gsd g = dem_scale_gsd(&d->gsd, d->lambda);
    double dmin = dem_gsd_min_diameter(&g), m = dem_scale_density(d->density, d->lambda) * DEM_PI / 6 * pow(dmin, 3);
    fprintf(f, "# Time step (eq. 14): dt_crit = sqrt(m_min/k_n) = %.4g s at lambda %g: the lightest granule of the "
               "truncated GSD\n# (%.4g mm, %.4g kg) on k_n = %.4g N/m (scaled). granucal, for this drum before it runs: "
               "%s.\n# This deck steps at that fraction, dt_fraction = %.4g of dt_crit, throughout (granucal turns at "
               "its\n# settled bed's own network limit, which a deck cannot compute). " LIGGGHTS_STEP_NOTE "\n",
            s->dt_crit, d->lambda, 1e3 * dmin, m, dem_scale_stiffness(d->granule.k_n, d->lambda), s->dt_report,
            s->dt / s->dt_crit);
}

// How the deck makes the bed and turns it.
static void deck_steps_text(FILE *f, const char *pour)
{
    fprintf(f, "# What it does: pours %s,\n"
               "# in passes of pour_pass s, until the bed's top stands a largest diameter above the fill level (the level\n"
               "# below which the drum's cross-section holds the fill degree); settles settle s; removes the granules whose\n"
               "# centres lie above the fill level (granucal cuts where the bed's measured CSA is the fill degree, which a\n"
               "# deck cannot measure); settles settle s; turns at rpm for spinup s; then dumps every sample s for measure s\n"
               "# (id type x y z vx vy vz radius: the face's angle and CSA are measured from x, y and radius). bed.dump\n"
               "# holds the settled bed before it turns.\n",
            pour);
}

// Where the tier started some speeds from a turned bed, the deck (which turns
// from the level bed) says so, and what that asks of spinup.
static void deck_turned_text(FILE *f, const cal_outcome *o)
{
    const cal_tier *t = o->tier;
    if (t->turned_start_rpm_count == 0) return;
    fprintf(f, "# Not as granucal ran it at ");
    for (unsigned k = 0; k < t->turned_start_rpm_count; ++k) fprintf(f, "%s%g", k ? ", " : "", t->turned_start_rpm[k]);
    fprintf(f, " rpm: there each run went on from a bed already turned %g s at that speed (turned_start_rpm), and MSER\n"
               "# cut its transient. From a level bed a 4 rpm bed at lambda 1000 compacts for ~8 s, its angle ~1.4 deg high\n"
               "# meanwhile (results/steady_rule/turned_start/): give spinup at least that much there.\n",
            t->turned_start_time);
}

// The variables a user may set (-var NAME VALUE keeps its value: an index
// variable already defined is not redefined) and those derived from them.
static void deck_variables(FILE *f, const cal_outcome *o, const deck_scene *s, const char *dump)
{
    const exp_drum_def *d = &s->drum;
    const cal_table *t = &o->table;
    double sample = s->run.sample_interval, lam6 = pow(d->lambda, 1.0 / 6.0);
    fprintf(f, "\nvariable lambda index %g          # coarse-graining factor\n", d->lambda);
    fprintf(f, "variable rpm index %g              # drum speed, rpm\n", s->n_rpm ? s->rpm[0] : 0.0);
    fputs("variable lining index 1            # the drum's lining:", f);
    for (int w = 0; w < t->n_walls; ++w) fprintf(f, " %d = %s%s", w + 1, t->wall_name[w], w + 1 < t->n_walls ? "," : "\n");
    fprintf(f, "variable spinup index %g           # s turned before the first dumped frame\n", DECK_SPINUP_S);
    fprintf(f, "variable measure index %g          # s dumped (the tier turned %g s at most)\n",
            fmax(s->run.max_time - DECK_SPINUP_S, sample), s->run.max_time);
    fprintf(f, "variable sample index %g          # s between dumped frames\n", sample);
    fprintf(f, "variable dt_fraction index %.4g    # of dt_crit (see above)\n", s->dt / s->dt_crit);
    fprintf(f, "variable pour_pass index %g        # s a pass of the pour falls before the next\n", DECK_POUR_PASS_S);
    fputs("variable bed index 0               # which bed the pour makes: another whole number shifts its sizes and\n"
          "                                   # velocities (several beds of one scene, as granucal's seeds give)\n", f);
    fprintf(f, "variable settle index %g           # s of settling after the pour and after the cut\n", DECK_SETTLE_S);
    fprintf(f, "variable dump index %s\n", dump);
    fprintf(f, "variable rdrum equal %.9g\nvariable depth equal %.9g\n", 0.5 * d->diameter, d->depth);
    fprintf(f, "variable dt equal v_dt_fraction*%.6g*v_lambda^(1.0/6.0)\n", s->dt_crit / lam6);
    fprintf(f, "variable cg equal v_lambda^(1.0/3.0)\n");
    fprintf(f, "variable rho equal %.9g/v_lambda\n", d->density);
    fprintf(f, "variable dmin equal %.6g*v_cg\nvariable dmax equal %.6g*v_cg\n", dem_gsd_min_diameter(&d->gsd),
            dem_gsd_max_diameter(&d->gsd));
    fprintf(f, "variable cut equal %.9g       # the fill level\n", s->level);
    fprintf(f, "variable omega equal v_rpm*PI/30\n");
    fprintf(f, "variable every equal floor(v_sample/v_dt+0.5)\n");
}

// The box: the drum's cross-section with a margin, its depth along z.
static void deck_box(FILE *f, const deck_scene *s, int types)
{
    const exp_drum_def *d = &s->drum;
    fprintf(f, "\nunits si\nboundary f f %s\nnewton off\n", d->periodic ? "p" : "f");
    if (d->periodic) fputs("region domain block $(-1.2*v_rdrum) $(1.2*v_rdrum) $(-1.2*v_rdrum) $(1.2*v_rdrum) 0 ${depth} units box\n", f);
    else fputs("region domain block $(-1.2*v_rdrum) $(1.2*v_rdrum) $(-1.2*v_rdrum) $(1.2*v_rdrum) $(-0.1*v_depth) $(1.1*v_depth) units box\n", f);
    fprintf(f, "create_box %d domain\n", types);
    fputs("neighbor $(0.2*v_dmin) bin\nneigh_modify delay 0\n", f);
}

static void deck_thermo(FILE *f)
{
    fputs("\nthermo_style custom step time atoms ke\nthermo $(floor(0.1/v_dt+0.5))\nthermo_modify lost error norm no\n", f);
}

// The cut, the second settling, the bed's frame and the turn's dump.
static void deck_cut_and_dump(FILE *f)
{
    fputs("\n# The cut to the fill level.\nrun $(floor(v_settle/v_dt+0.5))\n"
          "region above block INF INF ${cut} INF INF INF units box\ndelete_atoms region above\n"
          "print \"granucal deck: $(count(all)) granules after the cut\"\n"
          "run $(floor(v_settle/v_dt+0.5))\n"
          "dump bed all custom 1 bed.dump id type x y z vx vy vz radius\nrun 0\nundump bed\n", f);
}

// The drum wall (and a full drum's end plates, which LIGGGHTS' primitive
// planes cannot turn), turning at `shear` ("" or "shear x ${omega}").
static void liggghts_walls(FILE *f, const deck_scene *s, const char *shear)
{
    fprintf(f, "fix drum all wall/gran %s primitive type ${wall_type} zcylinder ${rdrum} 0. 0. %s%sabsolute_damping off\n",
            liggghts_model, shear, *shear ? " " : "");
    if (!s->drum.periodic && !*shear)
        fprintf(f, "fix front all wall/gran %s primitive type ${wall_type} zplane 0. absolute_damping off\n"
                   "fix back all wall/gran %s primitive type ${wall_type} zplane ${depth} absolute_damping off\n",
                liggghts_model, liggghts_model);
}

// The pour's passes: each (written between these two) places granules above
// the bed and lets them land, until the bed's top stands a largest diameter
// above the cut (at most 50 passes): the bed reaches the cut also where its
// surface dips. `after` ends the pass; the next pass places granules above
// `floor` (the highest centre plus `clearance`).
static void deck_pass_begin(FILE *f) { fputs("variable pass loop 50\nlabel pour\n", f); }

static void deck_pass_end(FILE *f, const char *after, const char *clearance)
{
    fprintf(f, "run $(floor(v_pour_pass/v_dt+0.5))\n%svariable floor string $(bound(all,ymax)%s)\n"
               "if \"$(bound(all,ymax)) >= $(v_cut+v_dmax)\" then \"jump SELF poured\"\nnext pass\njump SELF pour\n"
               "label poured\nprint \"granucal deck: $(count(all)) granules poured\"\n",
            after, clearance);
}

// Both decks' pour, as granucal pours (exp_pour_layer): lattice sites one
// largest diameter apart filling the drum above the bed, each granule with
// granucal's small sideways velocity so that they do not land in columns. Each
// pass's sizes come from the GSD's classes by the golden-ratio sequence of the
// atom id (create_atoms has no size distribution, and an atom-style random()
// drawn twice in a formula draws twice): every pass holds each class at its
// number fraction to within a granule or two. The same commands run in LAMMPS
// 2021 and LIGGGHTS 3.8. LIGGGHTS' own pour (insert/pack, the classes at random
// without overlap) made beds whose 40 rpm angle read 2.2 deg steeper over three
// beds than granucal's; poured this way its angle agrees (results/peers/README.md).
// `bed` shifts the sequence by 7919 (a prime) ids a bed: bed 0 is the sequence
// of the atom id itself (id + 0 is id, bit for bit), another bed another pour.
static void lattice_pour(FILE *f, const deck_scene *s)
{
    fputs("\n# The pour, as granucal's: lattice sites one largest diameter apart above the bed, each granule with a small\n"
          "# sideways velocity (without it they land in columns), in passes.\n"
          "variable pitch equal 1.05*v_dmax\nlattice sc ${pitch} origin 0.5 0.5 0.5\n"
          "region inner cylinder z 0. 0. $(v_rdrum-0.55*v_pitch) $(0.5*v_pitch-1e-9) $(v_depth-0.5*v_pitch+1e-9) units box\n"
          "variable n atom id+v_bed*7919\n"
          "variable u atom 0.6180339887498949*v_n-floor(0.6180339887498949*v_n)\n", f);
    fprintf(f, "variable dnew atom (%.6g", s->bin_d[0]);
    double cum = 0;
    for (int k = 1; k < s->bins; ++k) cum += s->bin_p[k - 1], fprintf(f, "+(v_u>=%.6g)*%.6g", cum, s->bin_d[k] - s->bin_d[k - 1]);
    fputs(")*v_cg\nvariable vx atom 0.05*sin(1.3*v_n)\nvariable vy atom -0.1+0*id\nvariable vz atom 0.05*cos(1.7*v_n)\n"
          "variable floor string $(-v_rdrum)\n", f);
}

static const char lattice_pour_text[] = "the GSD's classes on lattice sites above the bed (create_atoms)";
static const char lattice_pass[] =
    "region above_bed block INF INF ${floor} INF INF INF units box\nregion sites intersect 2 inner above_bed\n"
    "variable before string $(count(all))\ncreate_atoms 1 region sites\ngroup new id > ${before}\n"
    "set group new diameter v_dnew\nset group new density ${rho}\nvelocity new set v_vx v_vy v_vz\n"
    "group new delete\n"
    "region sites delete\nregion above_bed delete\n";

// What one code's deck says its own way; the rest of a deck is the same text
// in both (write_deck).
typedef struct deck_code {
    const char *name;                    ///< deck_path's: "liggghts", "lammps"
    const char *title, *exe, *deck_file, *params_file, *dump_file;
    void (*before_variables)(FILE *f, const deck_scene *s); ///< may be NULL
    /// From the atom style to the still drum: box, parameters, step, gravity.
    void (*setup)(FILE *f, const cal_outcome *o, const deck_scene *s);
    void (*turn)(FILE *f, const deck_scene *s); ///< the drum set turning
} deck_code;

static void liggghts_before_variables(FILE *f, const deck_scene *s)
{
    if (!s->drum.periodic)
        fputs("# LIGGGHTS' primitive planes cannot turn: the end plates stand still while the drum turns (granucal "
              "turns\n# them with it).\n", f);
}

static void liggghts_setup(FILE *f, const cal_outcome *o, const deck_scene *s)
{
    fputs("variable wall_type equal v_lining+1\n\natom_style granular\natom_modify map array\ncommunicate single vel yes\n", f);
    deck_box(f, s, 1 + o->table.n_walls);
    fputs("include liggghts_parameters.in\ntimestep ${dt}\nfix gravi all gravity 9.81 vector 0. -1. 0.\n", f);
    liggghts_walls(f, s, "");
}

static void liggghts_turn(FILE *f, const deck_scene *s)
{
    fputs("\n# The turn: in LIGGGHTS 3.8 a zcylinder's `shear x W` turns it about its axis at W rad/s, counter-clockwise\n"
          "# seen from +z (`shear z` would slide it along the axis).\nunfix drum\n", f);
    liggghts_walls(f, s, "shear x ${omega}");
}

// The drum: a cylinder region (a full drum's closed at its ends), turning
// when `rotate` is given.
static void lammps_walls(FILE *f, const deck_scene *s, const char *name, const char *rotate)
{
    fprintf(f, "region %s cylinder z 0. 0. ${rdrum} %s side in %sunits box\n", name, s->drum.periodic ? "INF INF" : "0. ${depth}",
            rotate);
    fprintf(f, "fix drum all wall/gran/region granular ${wall_contact} region %s\n", name);
}

static void lammps_setup(FILE *f, const cal_outcome *o, const deck_scene *s)
{
    fputs("\natom_style sphere\natom_modify map array\ncomm_modify vel yes\n", f);
    deck_box(f, s, 1);
    fputs("include lammps_parameters.in\n", f);
    for (int w = 0; w < o->table.n_walls; ++w) {
        char name[32];
        fprintf(f, "if \"${lining} == %d\" then \"variable wall_contact string '${wall_%s}'\"\n", w + 1,
                lammps_name(name, o->table.wall_name[w]));
    }
    fputs("timestep ${dt}\nfix gravi all gravity 9.81 vector 0. -1. 0.\n", f);
    lammps_walls(f, s, "still", "");
}

static void lammps_turn(FILE *f, const deck_scene *s)
{
    fputs("\n# The turn: the region turns about z at omega rad/s (the wall takes its surface velocity from it).\n"
          "unfix drum\nvariable theta equal v_omega*(time-$(time))\n", f);
    lammps_walls(f, s, "turning", "rotate v_theta 0. 0. 0. 0. 0. 1. ");
}

static const deck_code liggghts_deck = {"liggghts", "LIGGGHTS 3.8", "liggghts", "liggghts_drum.in",
                                        "liggghts_parameters.in", "liggghts_drum.dump", liggghts_before_variables,
                                        liggghts_setup, liggghts_turn};
static const deck_code lammps_deck = {"lammps", "LAMMPS (pair_style granular)", "lmp", "lammps_drum.in",
                                      "lammps_parameters.in", "lammps_drum.dump", NULL, lammps_setup, lammps_turn};

// One code's complete deck: the same pour, cut, dumps and runs in both.
static int write_deck(const char *dir, const cal_outcome *o, const deck_scene *s, const deck_code *c, char *err,
                      size_t len)
{
    char path[1200];
    deck_path(path, sizeof path, dir, c->name);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    deck_title(f, o, c->title, c->exe, c->deck_file, c->params_file);
    deck_scene_text(f, o, s);
    deck_step_text(f, s);
    deck_steps_text(f, lattice_pour_text);
    deck_turned_text(f, o);
    if (c->before_variables) c->before_variables(f, s);
    deck_variables(f, o, s, c->dump_file);
    c->setup(f, o, s);
    fputs("fix integr all nve/sphere\n", f);
    lattice_pour(f, s);
    deck_thermo(f);
    deck_pass_begin(f);
    fputs(lattice_pass, f);
    deck_pass_end(f, "", "+v_pitch"); // a lattice site a pitch above every centre overlaps none
    deck_cut_and_dump(f);
    c->turn(f, s);
    fputs("run $(floor(v_spinup/v_dt+0.5))\ndump turn all custom ${every} ${dump} id type x y z vx vy vz radius\n"
          "run $(floor(v_measure/v_dt+0.5))\n", f);
    return exp_atomic_commit(&a, err, len);
}

// The decks need a wall material to line the drum with: without one (the
// wall stage did not run) there are none, and an earlier run's are removed.
static int write_decks(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    if (o->table.n_walls == 0) {
        char path[1200];
        deck_path(path, sizeof path, dir, "liggghts"), remove(path);
        deck_path(path, sizeof path, dir, "lammps"), remove(path);
        return 0;
    }
    deck_scene s;
    return scene_of(o, &s, err, len) || write_deck(dir, o, &s, &liggghts_deck, err, len) ||
           write_deck(dir, o, &s, &lammps_deck, err, len);
}

int cal_export_write(const char *dir, const cal_outcome *o, char *err, size_t len)
{
    return write_liggghts(dir, o, err, len) || write_lammps(dir, o, err, len) || write_decks(dir, o, err, len);
}

// The exports: what the parameter files leave out, the decks, and the peers
// check of DIR/peers when one was run on them (tests/peers/drum_peers.sh
// writes its summary.txt).
void cal_export_report(FILE *f, const char *dir)
{
    fputs("\n## The table in LIGGGHTS and LAMMPS\n\n`liggghts_parameters.in` (LIGGGHTS 3.8) leaves out of the paper's "
          "model:\n\n", f);
    write_differences(f, liggghts_differences, "- ", "  ");
    fputs("\n`lammps_parameters.in` (LAMMPS `pair_style granular`):\n\n", f);
    write_differences(f, lammps_differences, "- ", "  ");
    char path[1200], line[512];
    deck_path(path, sizeof path, dir, "liggghts");
    FILE *deck = fopen(path, "r");
    if (!deck) {
        fputs("\nNo complete decks: the table has no wall material to line the drum with (the wall stage did not "
              "run).\n", f);
        return;
    }
    fclose(deck);
    fputs("\n`liggghts_drum.in` and `lammps_drum.in` are complete decks of the calibration's drum at its tier (its "
          "geometry, the GSD at lambda, granucal's time step and why, the pour, the cut to the fill degree, the turn, "
          "dumps): run them as written in this folder (`liggghts -in liggghts_drum.in`, `lmp -in lammps_drum.in`); "
          "`-var NAME VALUE` sets lambda, rpm, lining, spinup, measure and the rest their headers list.\n", f);
    snprintf(path, sizeof path, "%s/peers/summary.txt", dir);
    FILE *s = fopen(path, "r");
    if (!s) {
        fprintf(f, "\nNo peers check was run on these decks. For a ci-tier calibration, `CALIBRATION=%s bash "
                   "tests/peers/drum_peers.sh build/granucal build/tests/drum_peers %s/peers` runs both as written "
                   "beside granucal on the same drum and measures them alike; the report then shows its numbers. "
                   "At the committed ci twin: `results/peers/README.md`.\n", dir, dir);
        return;
    }
    fputs("\nThe peers check run on these decks (`tests/peers/drum_peers.sh`, its `peers/summary.txt`):\n\n```\n", f);
    while (fgets(line, sizeof line, s)) fputs(line, f);
    fputs("```\n", f);
    fclose(s);
}

