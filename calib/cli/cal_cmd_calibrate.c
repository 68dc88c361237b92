// SPDX-License-Identifier: MIT
// `granucal calibrate`: the product. Validates every input, then runs the
// stages, each from the result store where it can, and writes the table.
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <cyaml/cyaml.h>

#include "cal_cli_frame.h"
#include "cal_commands.h"
#include "cal_files.h"
#include "cal_mpi.h"
#include "cal_options.h"
#include "cal_plan.h"
#include "cal_pool.h"
#include "cal_report.h"
#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_yaml.h"

static const char synopsis[] =
    "usage: granucal calibrate [CONFIG.yaml] [options]\n"
    "\n"
    "Calibrate the linear spring-dashpot model with sliding and rolling friction of a\n"
    "powder from rotating-drum measurements (Tiscar et al. 2019, section 4):\n"
    "  1. stiffness: coordination number of a poured cylinder for each candidate k_n;\n"
    "     keep the smallest k whose CN is within the seed-to-seed noise of the stiff limit;\n"
    "  2. granule-granule (mu_s, mu_r) in the drum lined with granules: NLopt COBYLA\n"
    "     minimises the occupied-area (CSA) misfit over the speeds subject to the dynamic\n"
    "     angle of repose matching the lab's (a tier with `angle_rule: misfit` puts the\n"
    "     angle into the misfit instead, for runs whose angle is as noisy as the band);\n"
    "  3. each wall material's (mu_s, mu_r), granule-granule frozen, the same way.\n"
    "After each search, the best mu_s is run at mu_r's two search bounds, and every\n"
    "candidate's chi^2 (angle and CSA, by the lab's and the tier's measured spreads)\n"
    "gives the identified range: the candidates within Delta chi^2 = 3.84 of the best,\n"
    "which these measurements cannot tell apart. A wall mu_r the drum does not resolve\n"
    "shows as a range that reaches the search bound, not as one noisy point.\n"
    "A tier with `map_tier: NAME` (the standard tier) searches across two tiers: NAME's\n"
    "whole search maps the plane (the standard tier's ci-map adds the box's corners to\n"
    "its grid: design_corners), then this tier runs only where that map, corrected by\n"
    "the discrepancy measured between the two at those runs, puts the optimum, until a\n"
    "run agrees with the corrected map within the data's noise (max_evaluations runs).\n"
    "With posterior_runs: N, up to N more runs follow, each where the posterior is\n"
    "still held wide by the corrected map's own uncertainty; none where its width is\n"
    "the data's (docs/calibration.md); with return_runs: M, up to M more after them\n"
    "at the corrected optimum they moved. With angle_aim_sd: Z, each of those runs is\n"
    "aimed Z standard deviations of what it would read inside the angle's band (by\n"
    "default the band itself, whose edge a soft penalty lets the aim slip past).\n"
    "Where NAME has a map_tier of its own, NAME's stage is itself two-tier (levels:\n"
    "ci-map -> lambda 1000 -> lambda 512, the fine-levels tier): its runs and its corrected\n"
    "map's predictions are the map of the level above, which corrects them only by the\n"
    "discrepancy measured at its own runs.\n"
    "\n"
    "CONFIG defaults to configs/calibration.yaml; it names the lab data files\n"
    "(repose_angle.csv: surface,rpm,angle_deg,angle_sd_deg; occupied_area.csv:\n"
    "surface,rpm,csa_percent,csa_sd_percent), the powder, the candidates, the bounds and\n"
    "the fidelity tiers. Every input is checked before the first simulation.\n";

static const char epilogue[] =
    "Progress: one line per simulation on stderr, ending with the step of the whole\n"
    "calibration (stiffness, granule, each wall material), the simulations done of the\n"
    "most it may take, and the time left at most, from the measured cost of each kind of\n"
    "simulation so far (stored ones included) shared by the simulations run at once.\n"
    "\n"
    "Resuming: every simulation is stored in OUT/store under a hash of everything that\n"
    "defines it; run the same command again after a kill and nothing finished is rerun.\n"
    "A drum run killed while turning resumes from its last checkpoint (OUT/store/*.turn.h5)\n"
    "and ends as it would have uninterrupted (bit for bit; its bed is settled again).\n"
    "A damaged record (cut short, not YAML) is moved to OUT/store/damaged/, kept, with\n"
    "one line saying so, and only its simulation runs again.\n"
    "Across machines: mpirun -np N granucal calibrate ... deals the simulations of each\n"
    "batch over the ranks (OUT must be on a filesystem all ranks share).\n"
    "\n"
    "Outputs in OUT: calibrated_parameters.{csv,md,h5} (value, identified_min/max,\n"
    "not_excluded_min/max, status and flags: calibrated (the data left at most half\n"
    "the search range), one-sided (on a search bound, or its interval open to one),\n"
    "bounded (both ends excluded, more than half left), not identified, not a\n"
    "result; the run's tier, lambda, data and purpose on every row; the posterior's\n"
    "median and 95 % credible interval), simulations.csv, report.md (every\n"
    "candidate, its chi^2, the ranges, the posterior, which measurement moves with\n"
    "which friction), cn_vs_k.png,\n"
    "angle_map_*.png, csa_vs_rpm_*.png, convergence_*.png, posterior_*.png,\n"
    "liggghts_parameters.in, lammps_parameters.in, and complete decks of the drum:\n"
    "liggghts_drum.in, lammps_drum.in. A tier marked `purpose: demonstration` (quick,\n"
    "ci, check) makes a demonstration, never a calibration, and every output says\n"
    "so, each figure above its title.\n";

typedef struct options {
    const char *config, *tier, *stage, *material, *out, *data;
    int jobs;
    double checkpoint_every_s;
    double budget_hours; ///< refuse a plan predicted to take longer (NAN: no limit)
    int plan_only;       ///< --plan: stop after printing the plan
} options;

static const char *const stages[] = {"all", "stiffness", "granule", "wall", NULL};

// --material NAME: that wall material alone, so the wall stage alone (a later --stage still wins).
static int take_material(const char *text, void *context)
{
    options *o = context;
    o->material = text, o->stage = "wall";
    return 0;
}

// 0: parsed; -1: --help printed; else the exit status of a usage error.
static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.config = "configs/calibration.yaml", .stage = "all", .checkpoint_every_s = CAL_CHECKPOINT_EVERY_S,
                   .budget_hours = NAN, .jobs = cal_default_jobs()};
    const cal_option table[] = {
        cal_option_tier(&o->tier, "fidelity tier from the config (ci, quick, standard, paper, ...)"),
        {.name = "stage", .kind = CAL_OPT_CHOICE, .text = &o->stage, .choices = stages, .value = "STAGE",
         .help = "the stage to run (default all); a later stage reads the earlier stages' results from OUT, else "
                 "the config's values"},
        {.name = "material", .kind = CAL_OPT_CUSTOM, .parse = take_material, .context = o, .value = "NAME",
         .help = "fit this wall material only (implies --stage wall)"},
        {.name = "data", .kind = CAL_OPT_TEXT, .text = &o->data, .value = "DIR",
         .help = "read DIR/repose_angle.csv and DIR/occupied_area.csv instead of the config's files (e.g. a twin "
                 "made by granucal synthesize)"},
        cal_option_out(&o->out, "results folder (default results/<config>-<tier>)"),
        cal_option_jobs(&o->jobs),
        cal_option_checkpoint_every(&o->checkpoint_every_s, "wall seconds between a drum run's checkpoints "
                                                            "(default 120; 0: none)"),
        cal_option_budget_hours(&o->budget_hours,
                                "refuse, before the first simulation, a run whose EXPECTED wall time (the plan's, "
                                "below; of a resumed run, what is left of it) is over H hours; the worst case is "
                                "printed beside it, not judged"),
        cal_option_plan(&o->plan_only,
                        "check every input, print the plan and stop: nothing runs, no folder is made. For each step "
                        "and in all: simulations, core-hours and wall hours on --jobs workers, EXPECTED and (in "
                        "parentheses) the worst case. Expected: each drum run ends at the steady test's first chance "
                        "(two windows, then its averaging), one under the MSER rule at the mean stop of the stored runs "
                        "of its kind (at least 3; else of its kind at any λ and k_n; else max_time); COBYLA starts at "
                        "the grid's best; the wall stages share "
                        "one grid; a two-tier stage runs its max_evaluations; k_n is stage 1's choice where its "
                        "cylinders are already in OUT/store, else the config's. Worst case: max_time, every "
                        "evaluation, the stiffest k_n. Records already in OUT/store are not subtracted there; where "
                        "OUT/store exists, a last line (== left; a run prints it too) replays the stages on it, running "
                        "and writing nothing, and says where a run would resume (the step, the records found, the runs of the "
                        "next batch missing) and the expected cost left: each step's expected runs less those found. "
                        "tests/calibration/plan_vs_committed.sh holds the expected figures within 30 % of what the "
                        "committed standard run (results/calibration-standard/) took."),
    };
    const cal_command_line line = {.command = "calibrate", .synopsis = synopsis, .epilogue = epilogue, .options = table,
                                   .n_options = sizeof table / sizeof *table};
    return cal_options_parse_config(&line, argc, argv, &o->config);
}

// ---- stage results kept between runs of single stages ---------------------------------

typedef struct stage_file {
    double k_n, mu_s, mu_r;
    char *k_n_from; ///< stage_stiffness.yaml: "stage 1" (its choice) or "config" (unresolved); absent in older files
    double mu_s_identified_min, mu_s_identified_max, mu_r_identified_min, mu_r_identified_max; ///< absent: 0
    double mu_s_not_excluded_min, mu_s_not_excluded_max, mu_r_not_excluded_min, mu_r_not_excluded_max; ///< absent: 0
} stage_file;
#define STAGE_FLOAT(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_OPTIONAL, stage_file, member)
static const cyaml_schema_field_t stage_fields[] = {
    STAGE_FLOAT("k_n", k_n), STAGE_FLOAT("mu_s", mu_s), STAGE_FLOAT("mu_r", mu_r),
    CYAML_FIELD_STRING_PTR("k_n_from", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, stage_file, k_n_from, 1, 15),
    STAGE_FLOAT("mu_s_identified_min", mu_s_identified_min), STAGE_FLOAT("mu_s_identified_max", mu_s_identified_max),
    STAGE_FLOAT("mu_r_identified_min", mu_r_identified_min), STAGE_FLOAT("mu_r_identified_max", mu_r_identified_max),
    STAGE_FLOAT("mu_s_not_excluded_min", mu_s_not_excluded_min), STAGE_FLOAT("mu_s_not_excluded_max", mu_s_not_excluded_max),
    STAGE_FLOAT("mu_r_not_excluded_min", mu_r_not_excluded_min), STAGE_FLOAT("mu_r_not_excluded_max", mu_r_not_excluded_max),
    CYAML_FIELD_END};
static const cyaml_schema_value_t stage_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, stage_file, stage_fields)};

// The two values of a stage 1 file's k_n_from.
static const char K_N_FROM_STAGE_1[] = "stage 1", K_N_FROM_CONFIG[] = "config";

// ranges: the identified μs and μr ranges, or NULL (stage 1); k_n_from: whether
// stage 1 chose k_n or fell back to the config's (NULL: a friction stage's file).
static int write_stage(const char *dir, const char *name, double k_n, double mu_s, double mu_r, const cal_range ranges[2],
                       const char *k_n_from, char *err, size_t len)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/stage_%s.yaml", dir, name);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    fprintf(a.f, "# written by granucal calibrate; read by later stages run alone. Not the table: the pair a later stage "
                 "freezes,\n# whatever its status (a bound, not a result); what each value is: calibrated_parameters.*\n"
                 "k_n: %.17g\nmu_s: %.17g\nmu_r: %.17g\n",
            k_n, mu_s, mu_r);
    if (k_n_from) fprintf(a.f, "k_n_from: %s\n", k_n_from);
    if (ranges && isfinite(ranges[1].lo))
        fprintf(a.f, "mu_s_identified_min: %.17g\nmu_s_identified_max: %.17g\nmu_r_identified_min: %.17g\n"
                     "mu_r_identified_max: %.17g\nmu_s_not_excluded_min: %.17g\nmu_s_not_excluded_max: %.17g\n"
                     "mu_r_not_excluded_min: %.17g\nmu_r_not_excluded_max: %.17g\n",
                ranges[0].lo, ranges[0].hi, ranges[1].lo, ranges[1].hi, ranges[0].bracket_lo, ranges[0].bracket_hi,
                ranges[1].bracket_lo, ranges[1].bracket_hi);
    return exp_atomic_commit(&a, err, len);
}

// The identified ranges a stage file kept (NAN if none: μr's range is never 0).
static void stage_ranges(const stage_file *s, cal_range *mu_s, cal_range *mu_r)
{
    *mu_s = *mu_r = CAL_NO_RANGE;
    if (!(s->mu_r_identified_min > 0)) return;
    mu_s->lo = s->mu_s_identified_min, mu_s->hi = s->mu_s_identified_max;
    mu_r->lo = s->mu_r_identified_min, mu_r->hi = s->mu_r_identified_max;
    if (!(s->mu_r_not_excluded_min > 0)) return; // a stage file written before the bracket was kept
    mu_s->bracket_lo = s->mu_s_not_excluded_min, mu_s->bracket_hi = s->mu_s_not_excluded_max;
    mu_r->bracket_lo = s->mu_r_not_excluded_min, mu_r->bracket_hi = s->mu_r_not_excluded_max;
}

// 1 if the stage file exists and was read; -1 if it is damaged. k_n_chosen
// (may be NULL): 1 if stage 1 chose its k_n, 0 if it is the config's, -1 if the
// file does not say (written before k_n_from was kept).
static int read_stage(const char *dir, const char *name, stage_file *out, int *k_n_chosen, char *err, size_t len)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/stage_%s.yaml", dir, name);
    if (access(path, F_OK) != 0) return 0;
    stage_file *s = NULL;
    if (exp_yaml_load(path, &stage_schema, (void **)&s, "delete it to rerun that stage", err, len)) return -1;
    int chosen = !s->k_n_from                              ? -1
                 : strcmp(s->k_n_from, K_N_FROM_STAGE_1) == 0 ? 1
                 : strcmp(s->k_n_from, K_N_FROM_CONFIG) == 0  ? 0
                                                              : -2;
    *out = *s, out->k_n_from = NULL; // the string goes with s
    exp_yaml_free(&stage_schema, s);
    if (chosen == -2)
        return exp_fail(err, len, "%s: field 'k_n_from': expected '%s' or '%s' (delete the file to rerun that stage)", path,
                        K_N_FROM_STAGE_1, K_N_FROM_CONFIG), -1;
    if (k_n_chosen) *k_n_chosen = chosen;
    return 1;
}

// ---- checks before the first simulation ------------------------------------------------

static int check_surface(const cal_series *angles, const cal_series *areas, const char *surface, char *err, size_t len)
{
    const cal_point *p[64];
    if (cal_series_select(angles, surface, p, 64) == 0)
        return exp_fail(err, len, "%s: no row for surface '%s' (the config names it)", angles->path, surface);
    if (cal_series_select(areas, surface, p, 64) == 0)
        return exp_fail(err, len, "%s: no row for surface '%s' (the config names it)", areas->path, surface);
    return 0;
}

typedef struct run {
    options opt;
    cal_config *c;
    const cal_tier *t;
    cal_series angles, areas;
    char out[1024];
    cal_env env;
    cal_stiffness_result stiffness;
    cal_friction_result *granule, *walls[16];
    int n_walls;
    cal_table table;
    cal_progress progress;
    char err[2048];
} run;

static void plan_progress(run *r);
static int check_predicted_cost(run *r);

// Where a data file is read from: --data DIR's file of that name, else the config's.
static void data_path(const run *r, const char *name, const char *configured, char *out, size_t len)
{
    if (r->opt.data) snprintf(out, len, "%s/%s", r->opt.data, name);
    else cal_config_data_path(r->c, configured, out, len);
}

// A measured size table (gsd_table) is kept beside the config's copy under
// its own name, which the copy then finds (a path relative to the config);
// a table named with folders is not, and the run says so.
static int keep_size_table(run *r)
{
    if (!r->c->gsd_table) return 0;
    if (strchr(r->c->gsd_table, '/')) {
        fprintf(stderr, "granucal calibrate: the size table '%s' is not kept in %s (its name has folders): a "
                        "re-derivation from that folder needs it there\n", r->c->gsd_table, r->out);
        return 0;
    }
    char from[1200], to[1200];
    cal_config_data_path(r->c, r->c->gsd_table, from, sizeof from);
    snprintf(to, sizeof to, "%s/%s", r->out, r->c->gsd_table);
    return cal_copy_file(from, to, r->err, sizeof r->err);
}

// The inputs this run read, copied into its results folder (config.yaml,
// repose_angle.csv, occupied_area.csv, a size table): its table can be re-derived from the
// folder alone (tests/calibration/verify_committed.sh) whatever the shipped
// config and data become.
static int keep_inputs(run *r)
{
    char from[1200], to[1200];
    snprintf(to, sizeof to, "%s/config.yaml", r->out);
    if (cal_copy_file(r->c->path, to, r->err, sizeof r->err)) return 1;
    const char *names[2] = {"repose_angle.csv", "occupied_area.csv"}, *configured[2] = {r->c->repose_angle, r->c->occupied_area};
    for (int k = 0; k < 2; ++k) {
        data_path(r, names[k], configured[k], from, sizeof from);
        snprintf(to, sizeof to, "%s/%s", r->out, names[k]);
        if (cal_copy_file(from, to, r->err, sizeof r->err)) return 1;
    }
    return keep_size_table(r);
}

// Everything checked, the plan predicted, then the results folder made: a
// refused run leaves nothing behind.
static int prepare(run *r)
{
    char path[1200];
    r->c = cal_config_load(r->opt.config, r->opt.tier, r->err, sizeof r->err);
    if (!r->c) return 1;
    r->t = cal_config_tier(r->c);
    data_path(r, "repose_angle.csv", r->c->repose_angle, path, sizeof path);
    if (cal_series_load(&r->angles, path, CAL_DATA_ANGLE, r->err, sizeof r->err)) return 1;
    data_path(r, "occupied_area.csv", r->c->occupied_area, path, sizeof path);
    if (cal_series_load(&r->areas, path, CAL_DATA_CSA, r->err, sizeof r->err)) return 1;
    if (check_surface(&r->angles, &r->areas, r->c->granule_surface, r->err, sizeof r->err)) return 1;
    int found = r->opt.material == NULL;
    for (unsigned k = 0; k < r->c->materials_count; ++k) {
        if (check_surface(&r->angles, &r->areas, r->c->materials[k].surface, r->err, sizeof r->err)) return 1;
        found |= r->opt.material && strcasecmp(r->opt.material, r->c->materials[k].name) == 0;
    }
    if (!found) return exp_fail(r->err, sizeof r->err, "--material '%s': not under materials in %s", r->opt.material, r->c->path);
    r->env.workers = r->opt.jobs;
    if (r->opt.out) snprintf(r->out, sizeof r->out, "%s", r->opt.out); // named, not made yet: the plan reads its store
    else {
        char stem[1024];
        const char *base = strrchr(r->c->path, '/');
        snprintf(stem, sizeof stem, "%s", base ? base + 1 : r->c->path);
        stem[strcspn(stem, ".")] = '\0';
        snprintf(r->out, sizeof r->out, "results/%.900s-%.60s", stem, r->t->name);
    }
    plan_progress(r);
    if (check_predicted_cost(r)) return 1;
    if (r->opt.plan_only) return 0; // the results folder is not made
    if (cal_prepare_output(r->out, r->err, sizeof r->err)) return 1;
    return cal_mpi_rank() == 0 ? keep_inputs(r) : 0;
}

// A stage's pair for later stages run alone: written by rank 0, and never by a
// plan's replay of the store (which writes nothing).
static int save_stage(run *r, const char *name, double k_n, double mu_s, double mu_r, const cal_range ranges[2],
                      const char *k_n_from)
{
    if (cal_mpi_rank() != 0 || r->env.store_only) return 0;
    return write_stage(r->out, name, k_n, mu_s, mu_r, ranges, k_n_from, r->err, sizeof r->err);
}

static int wants(const run *r, const char *stage) { return strcmp(r->opt.stage, "all") == 0 || strcmp(r->opt.stage, stage) == 0; }

static int stage_stiffness(run *r, double *k_n, const char **source)
{
    *k_n = r->c->k_n, *source = "config k_n (stage 1 not run)";
    if (wants(r, "stiffness")) {
        unsigned n;
        cal_tier_stiffness(r->c, r->t, &n);
        int drum = cal_tier_stiffness_on_drum(r->t);
        fprintf(stderr, "== stage 1: stiffness, %u candidates × %d seeds (%s λ = %g)\n", n, r->t->seeds,
                drum ? "the drum's own bed," : "cylinder", drum ? r->t->lambda : r->t->cylinder_lambda);
        if (cal_stage_stiffness(&r->env, r->c, r->t, &r->stiffness, r->err, sizeof r->err)) return 1;
        if (!isfinite(r->stiffness.chosen_k))
            return exp_fail(r->err, sizeof r->err, "stage 1: no candidate's CN is within the tolerance of the stiff limit");
        if (!r->stiffness.resolved) {
            fprintf(stderr, "stage 1: the CN of the softest candidate is within the noise of the stiff limit: the sweep "
                            "does not resolve the stiffness at this tier; using the config's k_n = %g N/m\n", r->c->k_n);
            *source = "config k_n (stage 1 unresolved at this tier: CN flat within its noise)";
            return save_stage(r, "stiffness", *k_n, NAN, NAN, NULL, K_N_FROM_CONFIG);
        }
        *k_n = r->stiffness.chosen_k, r->table.k_calibrated = 1;
        *source = drum ? "stage 1 (the drum's poured bed, Fig. 12)" : "stage 1 (poured cylinder, Fig. 12)";
        return save_stage(r, "stiffness", *k_n, NAN, NAN, NULL, K_N_FROM_STAGE_1);
    }
    stage_file s;
    int chosen;
    int got = read_stage(r->out, "stiffness", &s, &chosen, r->err, sizeof r->err);
    if (got < 0) return 1;
    if (!got) return 0;
    *k_n = s.k_n;
    // An unresolved sweep stores the config's k_n too. The file says which
    // (k_n_from); one written before it did is known to hold stage 1's choice
    // only where that differs from the config's k_n.
    r->table.k_calibrated = chosen >= 0 ? chosen : s.k_n != r->c->k_n;
    *source = chosen == 0                 ? "config k_n (stage 1 of an earlier run unresolved: stage_stiffness.yaml)"
              : r->table.k_calibrated ? "stage 1, earlier run (stage_stiffness.yaml)"
                                      : "stage_stiffness.yaml of an earlier run, which does not say whether stage 1 chose it";
    return 0;
}

// Where a friction stage's pair came from: sources[0] if it matches the angle,
// [1] if it is the best misfit of a tier that puts the angle in the misfit,
// [2] if it is only the closest to the angle.
static const char *friction_source(const cal_friction_result *f, const char *const sources[3])
{
    return f->best_feasible ? sources[0] : f->angle_in_misfit ? sources[1] : sources[2];
}

// One friction stage: across two tiers where the tier names a map tier.
static int friction_stage(run *r, double k_n, const cal_material *m, double gg_mu_s, double gg_mu_r,
                          cal_friction_result *out)
{
    if (!r->t->map_tier)
        return cal_stage_friction(&r->env, r->c, r->t, &r->angles, &r->areas, k_n, m, gg_mu_s, gg_mu_r, out, r->err,
                                  sizeof r->err);
    cal_friction_result *cheap = calloc(1, sizeof *cheap);
    if (!cheap) return exp_fail(r->err, sizeof r->err, "out of memory");
    int bad = cal_stage_two_tier(&r->env, r->c, r->t, &r->angles, &r->areas, k_n, m, gg_mu_s, gg_mu_r, out, cheap,
                                 r->err, sizeof r->err);
    free(cheap);
    return bad;
}

static int stage_granule(run *r, double k_n, double *mu_s, double *mu_r, const char **source)
{
    *mu_s = r->c->granule_mu_s, *mu_r = r->c->granule_mu_r, *source = "config granule_mu_s/mu_r (stage 2 not run)";
    if (wants(r, "granule")) {
        fprintf(stderr, "== stage 2: granule-granule friction (k_n = %g N/m, drum λ = %g)\n", k_n, r->t->lambda);
        r->granule = calloc(1, sizeof *r->granule);
        if (!r->granule) return exp_fail(r->err, sizeof r->err, "out of memory");
        if (friction_stage(r, k_n, NULL, 0, 0, r->granule)) return 1;
        const cal_candidate *b = &r->granule->cand[r->granule->best];
        *mu_s = b->mu_s, *mu_r = b->mu_r;
        r->table.gg_mu_s_range = r->granule->mu_s_range, r->table.gg_mu_r_range = r->granule->mu_r_range;
        static const char *const sources[3] = {"stage 2 (drum lined with granules)",
                                               "stage 2, best misfit (angle outside its tolerance)",
                                               "stage 2, closest (angle not matched)"};
        *source = friction_source(r->granule, sources);
        r->table.gg_angle_matched = cal_candidate_angle_matched(&r->granule->cand[r->granule->best]);
        const cal_range ranges[2] = {r->granule->mu_s_range, r->granule->mu_r_range};
        return save_stage(r, "granule", k_n, *mu_s, *mu_r, ranges, NULL);
    }
    stage_file s;
    int got = read_stage(r->out, "granule", &s, NULL, r->err, sizeof r->err);
    if (got < 0) return 1;
    if (got) {
        *mu_s = s.mu_s, *mu_r = s.mu_r, *source = "stage 2, earlier run (stage_granule.yaml)";
        r->table.gg_angle_matched = -1;
        stage_ranges(&s, &r->table.gg_mu_s_range, &r->table.gg_mu_r_range);
    }
    return 0;
}

static int stage_walls(run *r, double k_n, double gg_mu_s, double gg_mu_r)
{
    if (!wants(r, "wall")) return 0;
    for (unsigned k = 0; k < r->c->materials_count; ++k) {
        const cal_material *m = &r->c->materials[k];
        if (r->opt.material && strcasecmp(r->opt.material, m->name) != 0) continue;
        fprintf(stderr, "== stage 3: %s wall friction (granule-granule frozen at mu_s = %.4g, mu_r = %.4g)\n", m->name,
                gg_mu_s, gg_mu_r);
        cal_friction_result *w = r->walls[r->n_walls++] = calloc(1, sizeof *w);
        if (!w) return exp_fail(r->err, sizeof r->err, "out of memory");
        if (friction_stage(r, k_n, m, gg_mu_s, gg_mu_r, w)) return 1;
        int t = r->table.n_walls++;
        snprintf(r->table.wall_name[t], 32, "%s", m->name);
        r->table.wall_mu_s[t] = w->cand[w->best].mu_s, r->table.wall_mu_r[t] = w->cand[w->best].mu_r;
        r->table.wall_mu_s_range[t] = w->mu_s_range, r->table.wall_mu_r_range[t] = w->mu_r_range;
        static const char *const sources[3] = {"stage 3 (drum lined with it)",
                                               "stage 3, best misfit (angle outside its tolerance)",
                                               "stage 3, closest (angle not matched)"};
        snprintf(r->table.wall_source[t], 96, "%s", friction_source(w, sources));
        r->table.wall_angle_matched[t] = cal_candidate_angle_matched(&w->cand[w->best]);
    }
    return 0;
}

static void print_table(const char *dir)
{
    char path[1200], line[256];
    snprintf(path, sizeof path, "%s/calibrated_parameters.md", dir);
    FILE *f = fopen(path, "r");
    while (f && fgets(line, sizeof line, f)) fputs(line, stdout);
    if (f) fclose(f);
    printf("\nresults: %s (report.md, calibrated_parameters.csv, plots)\n", dir);
}

// A friction stage's plan: with a map tier, each level's runs as a step of
// their own, the deepest first as they run ("NAME (map 2)", "NAME (map)",
// each with its own cost), then this tier's.
static void plan_friction(run *r, const char *name, const cal_material *m)
{
    for (int level = cal_tier_map_depth(r->c, r->t); level >= 0; --level) {
        const cal_tier *t = cal_tier_map_level(r->c, r->t, level);
        char label[64];
        cal_progress_level_name(name, level, label, sizeof label);
        cal_progress_plan(&r->progress, label, cal_progress_drum_kind(level),
                          cal_friction_planned_runs(r->c, t, &r->angles, &r->areas, m));
    }
}

// ---- the plan: expected and worst-case cost, before the first simulation ----------------
//
// The expected figure assumes what the searches typically do (each also said
// in the printed plan):
//  - a drum run ends at the steady test's first chance, not at max_time
//    (cal_plan_turn_time);
//  - a one-tier search runs its grid (and the box's corners with
//    design_corners), then COBYLA, whose first point is the grid's best
//    (already run: max_evaluations - 1 new candidates after a grid), then the
//    two bound probes;
//  - the wall stages of one tier share their grid and corners: the same pairs on the same
//    bed (the granule pair frozen), run for the first material, found in the
//    store by the others;
//  - a two-tier stage runs all its max_evaluations at its own tier, and none of
//    its posterior_runs or return_runs (those only where the posterior asks;
//    the worst case counts them): it stops
//    earlier only when a run agrees with the corrected map within the data's
//    noise, or the map's optimum returns to a point already run, and with
//    the standard tier's small noise that is the exception (the committed
//    standard run stopped early in 1 of its 4 stages);
//  - the friction stages run at the k_n stage 1 will give (plan_stiffness).
// The worst case: every run turns max_time, every candidate a search may take
// is new, and k_n is the stiffest stage 1 may choose. Both are the cost of the
// whole calibration: records already in OUT/store are not subtracted.

enum { PLAN_MAX_TIERS = 16, PLAN_MAX_STEPS = CAL_PROGRESS_MAX_STAGES }; // stage 1, granule and 16 walls, each at every level

typedef struct plan_pass {
    int worst;
    double k_n;
    int parallel;
    int wall_grid_run[PLAN_MAX_TIERS]; ///< a wall stage of this tier ran its grid (expected figure)
    int wall_bed_kept[PLAN_MAX_TIERS]; ///< a one-bed wall stage of this tier settled its bed
    int turned_made[PLAN_MAX_TIERS][2]; ///< this tier's turned beds of stage 2 [0], stage 3 [1] made (expected figure)
    const cal_plan_history *history;    ///< OUT/store's MSER runs: when such a run stops (expected figure)
} plan_pass;

typedef struct plan {
    char name[PLAN_MAX_STEPS][64], what[PLAN_MAX_STEPS][64];
    cal_plan step[PLAN_MAX_STEPS];
    int n;
    cal_plan total;
    double k_expected, k_worst;
    char k_source[1400];
} plan;

static int tier_slot(const run *r, const cal_tier *t) { return (int)(t - r->c->tiers) % PLAN_MAX_TIERS; }

// 1 if every cylinder of stage 1 is in OUT/store (read only: a plan changes nothing).
static int cylinders_stored(const run *r, int *count)
{
    char store[1100], key[2048];
    snprintf(store, sizeof store, "%s/store", r->out);
    unsigned n;
    const double *stiffness = cal_tier_stiffness(r->c, r->t, &n);
    *count = 0;
    for (unsigned k = 0; k < n; ++k)
        for (int j = 0; j < r->t->seeds; ++j) {
            cal_bed_case d = cal_bed_case_make(r->c, r->t, stiffness[k], (uint64_t)(r->c->seed + j));
            cal_record rec;
            char err[1024];
            cal_bed_key(&d, key, sizeof key);
            if (cal_store_get(store, key, &rec, err, sizeof err) != 0) return 0;
            cal_record_free(&rec), ++*count;
        }
    return 1;
}

// The k_n the friction stages will run at, as far as it can be known before
// the first simulation: stage 1's choice where all its cylinders are stored
// (it then simulates nothing), the stage file of an earlier run where stage
// 1 is not run, else the config's k_n; the worst case, the stiffest stage 1
// may choose.
static void plan_stiffness(run *r, plan *p)
{
    unsigned n;
    const double *stiffness = cal_tier_stiffness(r->c, r->t, &n);
    p->k_expected = p->k_worst = r->c->k_n;
    snprintf(p->k_source, sizeof p->k_source, "the config's k_n");
    int stored;
    if (wants(r, "stiffness") && cylinders_stored(r, &stored)) {
        cal_env env = {.workers = 1};
        snprintf(env.store, sizeof env.store, "%s/store", r->out);
        cal_stiffness_result *s = calloc(1, sizeof *s);
        if (s && !cal_stage_stiffness(&env, r->c, r->t, s, r->err, sizeof r->err) && s->resolved) {
            p->k_expected = p->k_worst = s->chosen_k;
            snprintf(p->k_source, sizeof p->k_source, "stage 1's choice from its %d cylinders already in %s/store", stored,
                     r->out);
        } else if (s)
            snprintf(p->k_source, sizeof p->k_source, "the config's k_n: stage 1 does not resolve it from its %d stored "
                     "cylinders", stored);
        free(s);
        return;
    }
    if (wants(r, "stiffness")) {
        p->k_worst = fmax(r->c->k_n, stiffness[n - 1]);
        snprintf(p->k_source, sizeof p->k_source, "the config's k_n until stage 1 has chosen (worst case: its stiffest "
                 "candidate, %g N/m)", stiffness[n - 1]);
        return;
    }
    stage_file sf;
    char err[512];
    if (read_stage(r->out, "stiffness", &sf, NULL, err, sizeof err) == 1 && sf.k_n > 0) {
        p->k_expected = p->k_worst = sf.k_n;
        snprintf(p->k_source, sizeof p->k_source, "stage 1 of an earlier run (%s/stage_stiffness.yaml)", r->out);
    }
}

// Stage 1's poured cylinders: one batch, a task per candidate and seed, the stiffer dearer (a smaller step).
static void plan_cylinders(const run *r, int parallel, cal_plan_cost *cost)
{
    unsigned n;
    const double *stiffness = cal_tier_stiffness(r->c, r->t, &n);
    int m = 0, all = (int)n * r->t->seeds;
    double *task = calloc((size_t)all, sizeof *task);
    if (!task) return;
    for (unsigned k = 0; k < n; ++k)
        for (int j = 0; j < r->t->seeds; ++j) {
            cal_bed_case d = cal_bed_case_make(r->c, r->t, stiffness[k], (uint64_t)(r->c->seed + j));
            double memory_mb = 0, steps = cal_bed_predict_particle_steps(&d, &memory_mb);
            task[m++] = steps / CAL_PLAN_RATE;
            cost->core_s += steps / CAL_PLAN_RATE, cost->memory_mb = fmax(cost->memory_mb, memory_mb);
        }
    cost->runs += m;
    cost->wall_s += cal_plan_makespan(task, m, parallel);
    free(task);
}

// One batch of m candidates of a friction stage at tier t.
static void plan_batch(const run *r, plan_pass *pass, const cal_tier *t, const cal_material *m, const double *rpm,
                       int speeds, int candidates, cal_plan_cost *cost)
{
    if (candidates <= 0) return;
    // A wall stage's case, so that its runs' kind (cal_drum_key_kind) is the wall stage's: the kind masks
    // the pairs' values, but a wall pair other than the granules' (the centre of its search box) fills and
    // turns the drum with two linings, as every wall stage's run does.
    const double mu_s = r->c->granule_mu_s, mu_r = r->c->granule_mu_r;
    double wall_mu_s, wall_mu_r;
    cal_friction_to_mu(&r->c->wall, 0.5, 0.5, &wall_mu_s, &wall_mu_r);
    cal_drum_case d = m ? cal_drum_case_wall(r->c, t, pass->k_n, mu_s, mu_r, wall_mu_s, wall_mu_r)
                        : cal_drum_case_granule(r->c, t, pass->k_n, mu_s, mu_r);
    int beds = cal_tier_beds(t), *kept = &pass->wall_bed_kept[tier_slot(r, t)];
    cal_plan_drum_batch(cost, &d, rpm, speeds, candidates, beds, m != NULL, m && *kept, pass->parallel, pass->worst,
                        pass->history);
    if (m && beds == 1) *kept = 1;
}

// A friction stage at tier t by itself: a one-tier search, or (deciding) the
// runs of a two-tier stage at its own tier, one candidate at a time.
static int plan_search(const run *r, plan_pass *pass, const cal_tier *t, const cal_material *m, int deciding,
                       cal_plan_cost *cost, char *err, size_t len)
{
    double rpm[CAL_MAX_RPM];
    int speeds = cal_friction_speeds(r->c, t, &r->angles, &r->areas, m, rpm, NULL, err, len);
    if (speeds < 1) return 1;
    int *turned_made = &pass->turned_made[tier_slot(r, t)][m != NULL]; // every wall stage starts from one bed
    if (pass->worst || !*turned_made) {
        cal_drum_case d = cal_drum_case_granule(r->c, t, pass->k_n, r->c->granule_mu_s, r->c->granule_mu_r);
        cal_plan_turned_beds(cost, &d, cal_tier_beds(t), pass->parallel);
        *turned_made = 1;
    }
    if (deciding) {
        // the posterior's, and the return's after them, only where the posterior asks
        int runs = t->max_evaluations + (pass->worst ? t->posterior_runs + t->return_runs : 0);
        for (int i = 0; i < runs; ++i) plan_batch(r, pass, t, m, rpm, speeds, 1, cost);
        return 0;
    }
    int *grid_run = &pass->wall_grid_run[tier_slot(r, t)];
    if (pass->worst || !m || !*grid_run) {
        plan_batch(r, pass, t, m, rpm, speeds, t->grid * t->grid, cost);
        if (cal_tier_design_corners(t)) plan_batch(r, pass, t, m, rpm, speeds, 4, cost); // the same pairs for every wall too
    }
    if (m && (t->grid > 0 || cal_tier_design_corners(t))) *grid_run = 1;
    int cobyla = t->max_evaluations - (!pass->worst && t->grid > 0 && t->max_evaluations > 0);
    for (int i = 0; i < cobyla; ++i) plan_batch(r, pass, t, m, rpm, speeds, 1, cost);
    if (cal_tier_bound_probes(t)) plan_batch(r, pass, t, m, rpm, speeds, 2, cost);
    return 0;
}

// A step of the plan: its name and what it runs, expected and worst (w = 0, 1).
static cal_plan *plan_step(plan *p, const char *name, const char *what)
{
    if (p->n == PLAN_MAX_STEPS) return &p->step[p->n - 1]; // more materials than the config allows: never
    snprintf(p->name[p->n], sizeof p->name[0], "%s", name);
    snprintf(p->what[p->n], sizeof p->what[0], "%s", what);
    return &p->step[p->n++];
}

// A friction stage's steps: each level's, the deepest first as they run: the
// deepest map tier's whole search ("NAME (map 2)"...), then each level above
// deciding by its own runs ("NAME (map)", then NAME); a one-tier stage is
// its search alone.
static int plan_friction_steps(run *r, plan *p, plan_pass pass[2], const cal_material *m, const char *name)
{
    char label[64], what[64];
    for (int level = cal_tier_map_depth(r->c, r->t); level >= 0; --level) {
        const cal_tier *t = cal_tier_map_level(r->c, r->t, level);
        cal_progress_level_name(name, level, label, sizeof label);
        snprintf(what, sizeof what, "drum runs at tier '%.31s'", t->name);
        cal_plan *c = plan_step(p, label, what);
        for (int w = 0; w < 2; ++w)
            if (plan_search(r, &pass[w], t, m, t->map_tier != NULL, w ? &c->worst : &c->expected, r->err, sizeof r->err))
                return 1;
    }
    return 0;
}

// Every step of the calibration (as plan_progress), its expected and worst cost.
static int plan_cost(run *r, plan *p, const cal_plan_history *history)
{
    int parallel = r->env.workers * cal_mpi_size();
    plan_pass pass[2] = {{.worst = 0, .k_n = p->k_expected, .parallel = parallel, .history = history},
                         {.worst = 1, .k_n = p->k_worst, .parallel = parallel}};
    if (wants(r, "stiffness")) {
        cal_plan *c = plan_step(p, "stiffness", cal_tier_stiffness_on_drum(r->t) ? "poured drum beds" : "poured cylinders");
        plan_cylinders(r, parallel, &c->expected), plan_cylinders(r, parallel, &c->worst);
    }
    if (wants(r, "granule") && plan_friction_steps(r, p, pass, NULL, "granule")) return 1;
    for (unsigned k = 0; k < r->c->materials_count && wants(r, "wall"); ++k) {
        const cal_material *m = &r->c->materials[k];
        if ((!r->opt.material || strcasecmp(r->opt.material, m->name) == 0) && plan_friction_steps(r, p, pass, m, m->name))
            return 1;
    }
    for (int k = 0; k < p->n; ++k) cal_plan_add(&p->total, &p->step[k]);
    return 0;
}

static void print_plan(const run *r, const plan *p)
{
    int parallel = r->env.workers * cal_mpi_size();
    fprintf(stderr, "== plan: tier '%s', %d worker(s); expected (worst case)\n", r->t->name, parallel);
    int what = 28; // widened where a tier's name is long, so the columns stay aligned
    for (int k = 0; k < p->n; ++k) what = what > (int)strlen(p->what[k]) ? what : (int)strlen(p->what[k]);
    for (int k = 0; k < p->n; ++k) {
        const cal_plan *c = &p->step[k];
        fprintf(stderr, "   %-18s %4d (%4d) %-*s %7.2f (%7.2f) core-hours %6.2f (%6.2f) h\n", p->name[k], c->expected.runs,
                c->worst.runs, what, p->what[k], c->expected.core_s / 3600, c->worst.core_s / 3600,
                c->expected.wall_s / 3600, c->worst.wall_s / 3600);
    }
    char e[128], w[128];
    cal_plan_describe(&p->total.expected, parallel, e, sizeof e), cal_plan_describe(&p->total.worst, parallel, w, sizeof w);
    fprintf(stderr, "== plan: expected %d simulations, %s; worst case %d simulations, %s; %.0f MB a simulation\n",
            p->total.expected.runs, e, p->total.worst.runs, w, fmax(p->total.expected.memory_mb, p->total.worst.memory_mb));
    char store[1100], mser[1300];
    snprintf(store, sizeof store, "%s/store", r->out);
    cal_plan_describe_mser(&p->total.expected, store, mser, sizeof mser);
    fprintf(stderr, "   expected: each drum run ends at the steady test's first chance (two windows, then its averaging), "
                    "one under the MSER rule at the mean stop of the stored runs of its kind where there are at least "
                    "%d (%s), else at max_time; a search's COBYLA starts at the grid's best (run already), the wall "
                    "stages share one grid, a "
                    "two-tier stage runs all its max_evaluations and none of its posterior_runs or return_runs; k_n %g N/m, %s. Worst "
                    "case: max_time every run, every candidate new (posterior_runs and return_runs too), k_n %g N/m. At %.2g particle-steps per core-second (this project's 2-core machine); "
                    "records already in %s/store are not subtracted.\n",
            CAL_PLAN_HISTORY_MIN, mser, p->k_expected, p->k_source, p->k_worst, CAL_PLAN_RATE, r->out);
}

// ---- what is left: the stages replayed from OUT/store (--plan) ----------------------------
//
// A calibration is deterministic given its records, so replaying its stages on
// the store alone, running nothing, ends exactly where the run would resume.
// The replay runs in a forked child (cal_pool_probe): its stages' memory,
// progress and lines stay there; it writes nothing (env.store_only).

typedef struct replay_outcome {
    int stopped; ///< the store ends inside the calibration (else it holds all of it)
    int current; ///< the progress stage it ended in
    int missing; ///< runs of the batch it ended at that the store lacks
    int done[CAL_PROGRESS_MAX_STAGES]; ///< each stage's records found
    double eta_expected_s, eta_bound_s; ///< the time left at the stored runs' own costs (cal_progress)
} replay_outcome;

static int replay_in_child(void *ctx, void *result)
{
    run *r = ctx;
    replay_outcome *o = result;
    r->env.store_only = 1, r->env.use_fork = 0, r->env.store_missing = 0;
    snprintf(r->env.store, sizeof r->env.store, "%s/store", r->out);
    double k_n, mu_s, mu_r;
    const char *k_source, *gg_source;
    o->stopped = stage_stiffness(r, &k_n, &k_source) || stage_granule(r, k_n, &mu_s, &mu_r, &gg_source) ||
                 stage_walls(r, k_n, mu_s, mu_r);
    if (o->stopped && r->env.store_missing == 0) return 1; // an error of its own, not the store's end
    o->current = r->progress.current, o->missing = r->env.store_missing;
    for (int k = 0; k < r->progress.n_stages; ++k) o->done[k] = r->progress.stage[k].done;
    o->eta_expected_s = cal_progress_expected_eta_s(&r->progress), o->eta_bound_s = cal_progress_eta_s(&r->progress);
    return 0;
}

// Runs step k of the plan has left after the replay: none before the stage it
// ended in; there, its expected count less the records found (at least the
// batch it ended at); after it, the expected count.
static int step_runs_left(const run *r, const plan *p, int k, const replay_outcome *o)
{
    if (!o->stopped) return 0;
    int j = 0;
    while (j < r->progress.n_stages && strcmp(r->progress.stage[j].name, p->name[k]) != 0) ++j;
    if (j < o->current) return 0;
    int left = p->step[k].expected.runs - o->done[j];
    return j == o->current && left < o->missing ? o->missing : left > 0 ? left : 0;
}

// What is left of the plan's expected figure: each step's runs left at its expected cost per run.
static cal_plan_cost cost_left(const run *r, const plan *p, const replay_outcome *o)
{
    cal_plan_cost left = {0};
    for (int k = 0; k < p->n; ++k) {
        const cal_plan_cost *e = p->step[k].expected.runs > 0 ? &p->step[k].expected : &p->step[k].worst;
        cal_plan_add_runs(&left, e, step_runs_left(r, p, k, o));
    }
    return left;
}

// Where the store ends and what is left, at the plan's cost per run and at the stored runs' own costs.
static void print_left(const run *r, const replay_outcome *o, const cal_plan_cost *left)
{
    int found = 0;
    for (int k = 0; k < r->progress.n_stages; ++k) found += o->done[k];
    if (!o->stopped) {
        fprintf(stderr, "== left: nothing; %s/store holds every simulation of this calibration (%d found): a run "
                        "re-derives its outputs from it\n", r->out, found);
        return;
    }
    char e[128], measured[160] = "";
    cal_plan_describe(left, r->env.workers * cal_mpi_size(), e, sizeof e);
    if (isfinite(o->eta_expected_s) && isfinite(o->eta_bound_s)) {
        char expected[32], bound[32];
        cal_progress_format_duration(o->eta_expected_s, expected, sizeof expected);
        cal_progress_format_duration(o->eta_bound_s, bound, sizeof bound);
        snprintf(measured, sizeof measured, "; at the stored runs' own wall times, %s (at most %s)", expected, bound);
    }
    fprintf(stderr, "== left: %s/store holds this calibration up to step %d of %d (%s), %d simulation(s) found, %d "
                    "of the next batch missing. Expected left: %d simulations, %s (each step's expected runs less "
                    "those found, at the plan's cost per run)%s. What the search does from there, only running it "
                    "shows.\n",
            r->out, o->current + 1, r->progress.n_stages, o->current >= 0 ? r->progress.stage[o->current].name : "-",
            found, o->missing, left->runs, e, measured);
}

// The plan (and a run) on a store that holds part of the calibration: where it
// resumes, and what is left (*left; 1 if known, 0 with no store or no replay).
static int plan_left(run *r, const plan *p, cal_plan_cost *left)
{
    char store[1100];
    snprintf(store, sizeof store, "%s/store", r->out);
    if (cal_mpi_size() > 1 || access(store, F_OK) != 0) return 0; // nothing stored (or ranks, which must not fork)
    replay_outcome *o = calloc(1, sizeof *o);
    if (!o) return 0;
    int known = cal_pool_probe(replay_in_child, r, o, sizeof *o) == 0;
    if (known) *left = cost_left(r, p, o), print_left(r, o, left);
    else fprintf(stderr, "== left: not known: replaying %s stopped on an error; a run says which\n", store);
    free(o);
    return known;
}

// The plan printed; refused if one simulation per worker cannot fit the
// memory free, or if the EXPECTED wall time left (the whole plan's on a store
// that holds none of it) is over --budget-hours.
static int check_predicted_cost(run *r)
{
    plan *p = calloc(1, sizeof *p);
    if (!p) return exp_fail(r->err, sizeof r->err, "out of memory");
    plan_stiffness(r, p);
    char store[1100];
    snprintf(store, sizeof store, "%s/store", r->out);
    cal_plan_history history;
    int failed = cal_plan_history_read(&history, store, r->err, sizeof r->err) || plan_cost(r, p, &history);
    cal_plan_history_free(&history);
    if (failed) return free(p), 1;
    print_plan(r, p);
    for (int k = 0; k < p->n; ++k) cal_progress_expect(&r->progress, p->name[k], p->step[k].expected.runs);
    cal_plan_cost left;
    int resumed = plan_left(r, p, &left); // a resumed run says where it resumes, as its plan does
    int parallel = r->env.workers * cal_mpi_size();
    double memory_mb = fmax(p->total.expected.memory_mb, p->total.worst.memory_mb);
    char e[128], w[128];
    cal_plan_describe(resumed ? &left : &p->total.expected, parallel, e, sizeof e);
    cal_plan_describe(&p->total.worst, parallel, w, sizeof w);
    double expected_h = (resumed ? left.wall_s : p->total.expected.wall_s) / 3600;
    free(p);
    long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    double free_mb = pages > 0 && page > 0 ? (double)pages * (double)page / 1048576 : INFINITY;
    if (memory_mb * r->env.workers > free_mb)
        return exp_fail(r->err, sizeof r->err, "tier '%s': %.0f MB a simulation; %d at once need more than the %.0f MB "
                        "free: use fewer --jobs or a coarser tier", r->t->name, memory_mb, r->env.workers, free_mb);
    if (expected_h > r->opt.budget_hours)
        return exp_fail(r->err, sizeof r->err, "tier '%s': expected%s %s (the whole calibration's worst case %s), over "
                        "--budget-hours %g, which judges the expected figure: nothing was run", r->t->name,
                        resumed ? " left" : "", e, w, r->opt.budget_hours);
    return 0;
}

// Every stage this run will do, with the simulations it may take, so that
// progress lines can say how far the whole calibration is and the time left.
static void plan_progress(run *r)
{
    cal_progress *p = &r->progress;
    cal_progress_init(p, r->env.workers * cal_mpi_size());
    unsigned n_k;
    cal_tier_stiffness(r->c, r->t, &n_k);
    if (wants(r, "stiffness")) cal_progress_plan(p, "stiffness", CAL_RUN_CYLINDER, (int)n_k * r->t->seeds);
    if (wants(r, "granule")) plan_friction(r, "granule", NULL);
    for (unsigned k = 0; k < r->c->materials_count && wants(r, "wall"); ++k) {
        const cal_material *m = &r->c->materials[k];
        if (!r->opt.material || strcasecmp(r->opt.material, m->name) == 0) plan_friction(r, m->name, m);
    }
    r->env.progress = p;
}

static int calibrate(run *r, const char *command)
{
    double k_n, gg_mu_s, gg_mu_r;
    const char *k_source, *gg_source;
    r->env.started = exp_wall_seconds();
    r->table.gg_mu_s_range = r->table.gg_mu_r_range = CAL_NO_RANGE; // until stage 2 says
    if (stage_stiffness(r, &k_n, &k_source) || stage_granule(r, k_n, &gg_mu_s, &gg_mu_r, &gg_source) ||
        stage_walls(r, k_n, gg_mu_s, gg_mu_r))
        return 1;
    r->table.density = r->c->density, r->table.xi = r->c->xi, r->table.k_n = k_n, r->table.k_source = k_source;
    r->table.gg_mu_s = gg_mu_s, r->table.gg_mu_r = gg_mu_r, r->table.gg_source = gg_source;
    if (cal_mpi_rank() != 0) return 0;
    cal_outcome o = {.config = r->c, .tier = r->t, .stiffness = wants(r, "stiffness") ? &r->stiffness : NULL,
                     .granule = r->granule, .n_walls = r->n_walls, .table = r->table, .command = command,
                     .angle_data_synthetic = r->angles.synthetic, .csa_data_synthetic = r->areas.synthetic,
                     .wall_time_s = exp_wall_seconds() - r->env.started, .ranks = cal_mpi_size(), .workers = r->env.workers};
    for (int w = 0; w < r->n_walls; ++w) o.walls[w] = r->walls[w];
    if (cal_report_write(r->out, &o, r->err, sizeof r->err)) return 1;
    print_table(r->out);
    fprintf(stderr, "granucal calibrate: done in %.0f s; %llu simulations run now, the rest from the store\n",
            o.wall_time_s, r->env.simulations_run);
    return 0;
}

int cal_cmd_calibrate(int argc, char **argv)
{
    run *r = calloc(1, sizeof *r);
    if (!r) return fputs("granucal calibrate: out of memory\n", stderr), 1;
    int status = parse_options(argc, argv, &r->opt);
    if (status) return free(r), status < 0 ? 0 : status;
    char command[2048];
    cal_cli_begin(&argc, &argv, command, sizeof command);
    status = prepare(r);
    if (!status && r->opt.plan_only) fputs("granucal calibrate: --plan: every input checked, nothing was run\n", stderr);
    else if (!status) {
        snprintf(r->env.store, sizeof r->env.store, "%s/store", r->out);
        r->env.use_fork = cal_mpi_size() == 1, r->env.tty = isatty(2); // workers: set by prepare, for the plan
        r->env.checkpoint_every_s = r->opt.checkpoint_every_s;
        status = calibrate(r, command);
    }
    status = cal_cli_end("calibrate", status, r->err, &r->env, r->c);
    cal_series_free(&r->angles), cal_series_free(&r->areas);
    free(r->granule);
    for (int w = 0; w < r->n_walls; ++w) free(r->walls[w]);
    free(r);
    return status;
}
