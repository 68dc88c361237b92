// SPDX-License-Identifier: MIT
// `granucal synthesize`: drum data made by a tier's own drum at known pairs.
// A twin experiment calibrates on them: the truth is known, so whether the
// pipeline finds it (inside the range it says it identifies) is a test of the
// pipeline at that tier, with no bias of the tier against the lab to correct.
// The runs are the calibration's own drum cases (cal_drum_case_granule,
// cal_drum_case_wall) on seeds the calibration does not use, so the data
// differ from any candidate's run by the tier's seed noise, as lab data
// differ from the model by the powder's.
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cal_case_runs.h"
#include "cal_cli_frame.h"
#include "cal_commands.h"
#include "cal_data.h"
#include "cal_files.h"
#include "cal_mpi.h"
#include "cal_options.h"
#include "cal_plan.h"
#include "cal_stages.h"
#include "cal_store.h"
#include "exp_atomic_file.h"
#include "exp_common.h"

enum { MAX_SEEDS = 16, MAX_WALLS = 16 };

static const char synopsis[] =
    "usage: granucal synthesize [CONFIG.yaml] [options]\n"
    "\n"
    "Makes the two data files a calibration reads (repose_angle.csv, occupied_area.csv)\n"
    "from the config's own drum at known friction pairs: the drum lined with granules at\n"
    "the granule-granule pair, and each wall material of the config at its pair (the\n"
    "granule pair frozen), at the tier's speeds and the angle's speed, each the mean over\n"
    "several beds (seeds) that the calibration itself does not use.\n"
    "\n"
    "A twin experiment: `granucal calibrate --data DIR` on these files must recover the\n"
    "pairs inside the ranges it reports; what it cannot recover, the tier cannot identify.\n"
    "The files say SYNTHETIC in their header with the command, version and seeds.\n";

static const char epilogue[] =
    "Each value is the mean over the seeds whose run is steady; its spread column is the\n"
    "standard error of that mean (sd over seeds / sqrt(n)), floored at 0.05. Where no seed\n"
    "reached a steady state by max_time (a bed that avalanches), the value is the mean of\n"
    "the runs that did not, its spread at least their series' mean spread (the error of\n"
    "each mean cannot exceed it), and a '# Not steady:' line in the file names the point.\n"
    "Only a point whose every run failed stops the synthesis.\n";

typedef struct pair {
    char name[32];
    double mu_s, mu_r;
} pair;

typedef struct options {
    const char *config, *tier, *out, *reuse;
    pair granule, walls[MAX_WALLS];
    int n_walls, has_granule, jobs, n_seeds;
    int plan_only; ///< --plan: print the plan and stop
    double k_n; ///< NAN: the config's
    long seeds[MAX_SEEDS];
} options;

static int parse_pair(const char *text, double *mu_s, double *mu_r)
{
    char *end;
    *mu_s = strtod(text, &end);
    if (end == text || *end != ',') return 1;
    const char *second = end + 1;
    *mu_r = strtod(second, &end);
    return end == second || *end || !(*mu_s > 0) || !(*mu_r > 0) || !isfinite(*mu_s) || !isfinite(*mu_r);
}

// --seeds A,B,...: 1-16 whole numbers.
static int take_seeds(const char *text, void *context)
{
    options *o = context;
    char copy[256];
    snprintf(copy, sizeof copy, "%s", text);
    o->n_seeds = 0;
    for (char *save = NULL, *t = strtok_r(copy, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        double v;
        if (o->n_seeds == MAX_SEEDS || exp_parse_number(t, &v) || !exp_integer_in(v, 0, 1e9)) return 1;
        o->seeds[o->n_seeds++] = (long)v;
    }
    return o->n_seeds == 0;
}

// --granule MU_S,MU_R
static int take_granule(const char *text, void *context)
{
    options *o = context;
    o->has_granule = 1;
    return parse_pair(text, &o->granule.mu_s, &o->granule.mu_r);
}

// --wall NAME=MU_S,MU_R, one a material
static int take_wall(const char *text, void *context)
{
    options *o = context;
    const char *eq = strchr(text, '=');
    pair *p = &o->walls[o->n_walls];
    if (o->n_walls == MAX_WALLS || !eq || eq == text || (size_t)(eq - text) >= sizeof p->name ||
        parse_pair(eq + 1, &p->mu_s, &p->mu_r))
        return 1;
    snprintf(p->name, sizeof p->name, "%.*s", (int)(eq - text), text);
    o->n_walls++;
    return 0;
}

// 0: parsed; -1: --help printed; else the exit status of a usage error.
static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.config = "configs/calibration.yaml", .k_n = NAN, .n_seeds = 3, .seeds = {101, 102, 103},
                   .jobs = cal_default_jobs()};
    const cal_option table[] = {
        cal_option_tier(&o->tier, "fidelity tier whose drum is run (default: the config's)"),
        {.name = "granule", .kind = CAL_OPT_CUSTOM, .parse = take_granule, .context = o, .value = "MU_S,MU_R",
         .expected = "MU_S,MU_R, both > 0", .help = "granule-granule pair (default: granule_mu_s, granule_mu_r)"},
        {.name = "wall", .kind = CAL_OPT_CUSTOM, .parse = take_wall, .context = o, .value = "NAME=MU_S,MU_R",
         .expected = "NAME=MU_S,MU_R, both > 0 (at most 16 materials)",
         .help = "a wall material's pair, one option per material; a config material without one is refused (its "
                 "data would be missing)"},
        {.name = "k-n", .kind = CAL_OPT_REAL, .real = &o->k_n, .lo = 0, .lo_open = 1, .hi = INFINITY, .value = "K",
         .expected = "a stiffness in N/m", .help = "granule stiffness, N/m (default: the config's k_n)"},
        {.name = "seeds", .kind = CAL_OPT_CUSTOM, .parse = take_seeds, .context = o, .value = "A,B,...",
         .expected = "1-16 whole numbers separated by commas",
         .help = "drum seeds (default 101,102,103; the config's seed, which the calibration's candidates use, is "
                 "refused)"},
        cal_option_out(&o->out, "(default results/synthetic-<tier>); runs kept in DIR/store"),
        {.name = "reuse", .kind = CAL_OPT_TEXT, .text = &o->reuse, .value = "STORE",
         .help = "another run's store (e.g. a fidelity study's) to take records from: a simulation found there "
                 "under the same key (drum, pairs, seed, speed, tier, results version) is copied into DIR/store "
                 "byte for byte, not run again"},
        cal_option_jobs(&o->jobs),
        cal_option_plan(&o->plan_only, "check every input, print the plan (drum runs, core-hours and wall hours on "
                                       "--jobs workers, expected and worst case) and stop: nothing runs, no folder "
                                       "is made. Where OUT/store (or --reuse) holds some of the runs, a last line "
                                       "(== left) counts them and says what is left"),
    };
    const cal_command_line line = {.command = "synthesize", .synopsis = synopsis, .epilogue = epilogue, .options = table,
                                   .n_options = sizeof table / sizeof *table};
    return cal_options_parse_config(&line, argc, argv, &o->config);
}

/// One drum lining to make: its surface name in the data files and its cases.
typedef struct lining {
    const char *surface;
    const pair *wall; ///< NULL: the drum lined with granules
} lining;

typedef struct job {
    options opt;
    cal_config *c;
    const cal_tier *t;
    cal_env env;
    cal_progress progress; ///< one stage a lining: its runs done and the time left, on each run's line
    double k_n, gg_mu_s, gg_mu_r;
    double rpm[CAL_MAX_RPM], angle_rpm;
    int n_rpm;
    lining linings[MAX_WALLS + 1];
    int n_linings;
    char out[1024], err[2048];
} job;

// The speeds the calibration's granule stage simulates at this tier, from the
// config's data files (cal_friction_speeds): the same runs a candidate makes.
static int choose_speeds(job *j)
{
    char path[1200];
    cal_series angles, areas;
    cal_config_data_path(j->c, j->c->repose_angle, path, sizeof path);
    if (cal_series_load(&angles, path, CAL_DATA_ANGLE, j->err, sizeof j->err)) return 1;
    cal_config_data_path(j->c, j->c->occupied_area, path, sizeof path);
    if (cal_series_load(&areas, path, CAL_DATA_CSA, j->err, sizeof j->err)) return cal_series_free(&angles), 1;
    j->n_rpm = cal_friction_speeds(j->c, j->t, &angles, &areas, NULL, j->rpm, &j->angle_rpm, j->err, sizeof j->err);
    cal_series_free(&angles), cal_series_free(&areas);
    return j->n_rpm < 0;
}

// The granule lining, then each config material with its --wall pair.
static int choose_linings(job *j)
{
    j->linings[j->n_linings++] = (lining){j->c->granule_surface, NULL};
    for (unsigned k = 0; k < j->c->materials_count; ++k) {
        const cal_material *m = &j->c->materials[k];
        const pair *w = NULL;
        for (int i = 0; i < j->opt.n_walls; ++i)
            if (strcasecmp(j->opt.walls[i].name, m->name) == 0) w = &j->opt.walls[i];
        if (!w) return exp_fail(j->err, sizeof j->err, "no --wall %s=MU_S,MU_R for the material '%s' of %s", m->name, m->name, j->c->path);
        j->linings[j->n_linings++] = (lining){m->surface, w};
    }
    for (int i = 0; i < j->opt.n_walls; ++i) {
        int known = 0;
        for (unsigned k = 0; k < j->c->materials_count; ++k) known |= strcasecmp(j->opt.walls[i].name, j->c->materials[k].name) == 0;
        if (!known) return exp_fail(j->err, sizeof j->err, "--wall %s: not a material of %s", j->opt.walls[i].name, j->c->path);
    }
    for (int s = 0; s < j->opt.n_seeds; ++s) // the candidates' beds: seed, seed + 1, ... (cal_tier_beds)
        if (j->opt.seeds[s] >= j->c->seed && j->opt.seeds[s] < j->c->seed + cal_tier_beds(j->t))
            return exp_fail(j->err, sizeof j->err, "--seeds: %ld is a bed of %s's calibration candidates at tier '%s'; a "
                            "twin needs other beds", j->opt.seeds[s], j->c->path, j->t->name);
    return 0;
}

static cal_drum_case case_of(const job *j, const lining *l, long seed)
{
    cal_drum_case d = l->wall ? cal_drum_case_wall(j->c, j->t, j->k_n, j->gg_mu_s, j->gg_mu_r, l->wall->mu_s, l->wall->mu_r)
                              : cal_drum_case_granule(j->c, j->t, j->k_n, j->gg_mu_s, j->gg_mu_r);
    cal_drum_case_set_seed(&d, (uint64_t)seed);
    return d;
}

typedef struct summary {
    double mean, se;
    int n;
    /// No seed reached a steady state here: the mean is over the runs that
    /// did not, and `series` is the mean spread of their series over the
    /// averaging window, an upper bound of each mean's error (0: steady).
    double series;
} summary;

static summary summarise(const double *v, int n)
{
    summary s = {NAN, NAN, n, 0};
    if (n == 0) return s;
    double sum = 0, sq = 0;
    for (int i = 0; i < n; ++i) sum += v[i];
    s.mean = sum / n;
    for (int i = 0; i < n; ++i) sq += (v[i] - s.mean) * (v[i] - s.mean);
    s.se = n > 1 ? sqrt(sq / (n - 1) / n) : NAN;
    return s;
}

/// Per lining and speed: the angle and CSA over the seeds.
typedef struct lining_result {
    summary angle[CAL_MAX_RPM], csa[CAL_MAX_RPM];
} lining_result;

// A record of the same simulation in the --reuse store, copied byte for byte
// (its writer stays the run that made it). The key names everything that
// defines the run, and cal_store_get checks the whole key, not just its hash.
// 0: copied, or nothing to copy (already here, or absent there: it will run).
static int copy_record(const char *from_dir, const char *to_dir, const char *key, int *copied, char *err, size_t len)
{
    char from[1200], to[1200];
    cal_store_path(to_dir, key, to, sizeof to);
    if (access(to, F_OK) == 0) return 0;
    cal_record r;
    int found = cal_store_get(from_dir, key, &r, err, len);
    if (found != 0) return found < 0;
    cal_record_free(&r);
    cal_store_path(from_dir, key, from, sizeof from);
    ++*copied;
    return cal_copy_file(from, to, err, len);
}

// Every seed and speed of a lining that the --reuse store already holds.
static int reuse_records(job *j, const cal_drum_case *cases, int n)
{
    int copied = 0;
    for (int s = 0; s < n; ++s)
        for (int k = 0; k < j->n_rpm; ++k) {
            char key[2048];
            cal_drum_key(&cases[s], j->rpm[k], key, sizeof key);
            if (copy_record(j->opt.reuse, j->env.store, key, &copied, j->err, sizeof j->err)) return 1;
        }
    if (copied) fprintf(stderr, "   %d of %d run(s) taken from %s\n", copied, n * j->n_rpm, j->opt.reuse);
    return 0;
}

// Run (or read from the store) one lining's seeds; a speed with no usable
// run is an error: the data would have a hole the calibration would trip on.
static int make_lining(job *j, const lining *l, lining_result *out)
{
    int n = j->opt.n_seeds;
    cal_drum_case cases[MAX_SEEDS];
    cal_record *rec = calloc((size_t)(n * j->n_rpm), sizeof *rec);
    if (!rec) return exp_fail(j->err, sizeof j->err, "out of memory");
    for (int s = 0; s < n; ++s) cases[s] = case_of(j, l, j->opt.seeds[s]);
    if (j->opt.reuse && reuse_records(j, cases, n)) return free(rec), 1;
    cal_env_set_stage(&j->env, l->surface);
    cal_progress_enter(&j->progress, l->surface);
    if (cal_drum_evaluate_many(&j->env, cases, n, j->rpm, j->n_rpm, rec, j->err, sizeof j->err)) return free(rec), 1;
    int bad = 0;
    for (int k = 0; k < j->n_rpm; ++k) {
        // The steady seeds; where none is, those that ran but did not settle, with their spreads (a
        // calibration's two-tier loop counts such a run the same way: cal_multifidelity.h).
        for (int steady = 1; steady >= 0; --steady) {
            double angle[MAX_SEEDS], csa[MAX_SEEDS], angle_sd = 0, csa_sd = 0;
            int m = 0;
            for (int s = 0; s < n; ++s) {
                const cal_record *r = &rec[s * j->n_rpm + k];
                if (!cal_record_usable(r) || !isfinite(r->angle_deg) || (steady && !r->steady)) continue;
                angle[m] = r->angle_deg, csa[m++] = r->csa_percent;
                angle_sd += r->angle_sd_deg, csa_sd += r->csa_sd_percent;
            }
            out->angle[k] = summarise(angle, m), out->csa[k] = summarise(csa, m);
            if (m && !steady) {
                out->angle[k].series = angle_sd / m, out->csa[k].series = csa_sd / m;
                fprintf(stderr, "-- %s at %g rpm: no seed reached a steady state; its data are the mean of %d run(s) "
                                "that did not, spread %.2f° and %.2f %% (their series' spread)\n",
                        l->surface, j->rpm[k], m, out->angle[k].series, out->csa[k].series);
            }
            if (m) break;
        }
        if (out->angle[k].n == 0 && !bad)
            bad = exp_fail(j->err, sizeof j->err, "%s at %g rpm: every seed's run failed (see %s/store)", l->surface,
                           j->rpm[k], j->out);
    }
    for (int i = 0; i < n * j->n_rpm; ++i) cal_record_free(&rec[i]);
    free(rec);
    return bad;
}

static double spread_of(summary s)
{
    double se = isfinite(s.se) ? fmax(s.se, 0.05) : 0.05;
    return fmax(se, s.series);
}

static void write_header(FILE *f, const job *j, const lining_result *res, const char *what, const char *command)
{
    fprintf(f, "# SYNTHETIC - not lab data. %s made by the drum of tier '%s' (lambda %g, %s, max_time %g s)\n", what,
            j->t->name, j->t->lambda, j->t->slice_depth > 0 ? "periodic slice" : "full drum", j->t->max_time);
    fprintf(f, "# of %s, granucal %s (commit %s), k_n %g N/m, granule-granule mu_s %g mu_r %g", j->c->path, exp_version(),
            cal_build_commit(), j->k_n,
            j->gg_mu_s, j->gg_mu_r);
    for (int i = 0; i < j->opt.n_walls; ++i)
        fprintf(f, ", %s mu_s %g mu_r %g", j->opt.walls[i].name, j->opt.walls[i].mu_s, j->opt.walls[i].mu_r);
    fprintf(f, ".\n# Mean over the usable runs of seeds");
    for (int s = 0; s < j->opt.n_seeds; ++s) fprintf(f, "%s%ld", s ? "," : " ", j->opt.seeds[s]);
    fprintf(f, "; spread = standard error of that mean (floor 0.05).\n");
    for (int l = 0; l < j->n_linings; ++l)
        for (int k = 0; k < j->n_rpm; ++k)
            if (res[l].angle[k].series > 0)
                fprintf(f, "# Not steady: %s at %g rpm (no seed reached the tier's standard error by max_time): the mean of "
                           "the runs that did not, spread the larger of that error and their series' mean spread.\n",
                        j->linings[l].surface, j->rpm[k]);
    fprintf(f, "# Made by: %s\n", command);
}

// One data file: the angle at the angle's speed, or the CSA at every speed
// (the schemas of cal_data.h).
static int write_series(job *j, const lining_result *res, const char *command, int angle)
{
    char path[1200];
    exp_atomic_file a;
    snprintf(path, sizeof path, "%s/%s", j->out, angle ? "repose_angle.csv" : "occupied_area.csv");
    if (exp_atomic_open(&a, path, j->err, sizeof j->err)) return 1;
    write_header(a.f, j, res, angle ? "Dynamic angle of repose" : "Occupied cross-section area (eq. 20)", command);
    fputs(angle ? "surface,rpm,angle_deg,angle_sd_deg\n" : "surface,rpm,csa_percent,csa_sd_percent\n", a.f);
    for (int l = 0; l < j->n_linings; ++l)
        for (int k = 0; k < j->n_rpm; ++k) {
            if (angle && j->rpm[k] != j->angle_rpm) continue;
            summary v = angle ? res[l].angle[k] : res[l].csa[k];
            fprintf(a.f, "%s,%g,%.3f,%.3f\n", j->linings[l].surface, j->rpm[k], v.mean, spread_of(v));
        }
    return exp_atomic_commit(&a, j->err, sizeof j->err);
}

static int write_files(job *j, const lining_result *res, const char *command)
{
    return write_series(j, res, command, 1) || write_series(j, res, command, 0);
}

// 1 if a store holds the record of key (read only; NULL: no store).
static int stored_in(const char *store, const char *key)
{
    char err[512];
    cal_record r;
    if (!store || cal_store_peek(store, key, &r, err, sizeof err) != 0) return 0;
    return cal_record_free(&r), 1;
}

// How many of lining l's runs (its seeds x speeds) OUT/store or --reuse
// already holds: a synthesis runs a fixed set, so its keys say what is left.
static int runs_stored(const job *j, const lining *l, const char *store)
{
    int n = 0;
    for (int s = 0; s < j->opt.n_seeds; ++s) {
        cal_drum_case d = case_of(j, l, j->opt.seeds[s]);
        for (int k = 0; k < j->n_rpm; ++k) {
            char key[2048];
            cal_drum_key(&d, j->rpm[k], key, sizeof key);
            n += stored_in(store, key) || stored_in(j->opt.reuse, key);
        }
    }
    return n;
}

// What is left where OUT/store (or --reuse) holds runs already: each lining's
// runs not stored, at its expected cost per run.
static void print_left(const job *j, const cal_plan *lining_cost, const char *store)
{
    cal_plan_cost left = {0};
    int stored = 0, all = 0;
    for (int l = 0; l < j->n_linings; ++l) {
        int have = runs_stored(j, &j->linings[l], store), runs = j->opt.n_seeds * j->n_rpm;
        stored += have, all += runs;
        cal_plan_add_runs(&left, &lining_cost[l].expected, runs - have);
    }
    if (stored == 0) return;
    char e[128];
    cal_plan_describe(&left, j->opt.jobs * cal_mpi_size(), e, sizeof e);
    fprintf(stderr, "== left: %d of %d drum runs already in %s%s%s; expected left: %d drum runs, %s (each lining's "
                    "expected cost per run)\n", stored, all, store, j->opt.reuse ? " or " : "",
            j->opt.reuse ? j->opt.reuse : "", left.runs, e);
}

// What making the data costs: each lining's seeds side by side, each seed
// settling its own bed and turning the speeds (cal_plan.h); then what is
// left of it where a store holds some.
static void print_plan(const job *j)
{
    int parallel = j->opt.jobs * cal_mpi_size();
    cal_plan total = {{0}, {0}};
    fprintf(stderr, "== plan: synthesize at tier '%s', %d worker(s); expected (worst case)\n", j->t->name, parallel);
    int wall_beds_made = 0; // the wall linings start from one set of turned beds (the frozen pair's)
    char store[1100], err[1024];
    cal_plan_history history; // unreadable: the plan takes max_time for MSER runs, and says how many
    snprintf(store, sizeof store, "%s/store", j->out);
    cal_plan_history_read(&history, store, err, sizeof err);
    cal_plan lining_cost[MAX_WALLS + 1];
    for (int l = 0; l < j->n_linings; ++l) {
        cal_plan p = {{0}, {0}};
        cal_drum_case d = case_of(j, &j->linings[l], j->opt.seeds[0]);
        const int turned_beds_here = !j->linings[l].wall || !wall_beds_made;
        wall_beds_made |= j->linings[l].wall != NULL;
        for (int w = 0; w < 2; ++w) {
            cal_plan_cost *cost = w ? &p.worst : &p.expected;
            if (turned_beds_here) cal_plan_turned_beds(cost, &d, j->opt.n_seeds, parallel);
            cal_plan_drum_batch(cost, &d, j->rpm, j->n_rpm, j->opt.n_seeds, 1, 0, 0, parallel, w, &history);
        }
        fprintf(stderr, "   %-20s %4d drum runs %7.2f (%7.2f) core-hours %6.2f (%6.2f) h\n", j->linings[l].surface,
                p.expected.runs, p.expected.core_s / 3600, p.worst.core_s / 3600, p.expected.wall_s / 3600,
                p.worst.wall_s / 3600);
        cal_plan_add(&total, &p);
        lining_cost[l] = p;
    }
    char e[128], w[128], mser[1300];
    cal_plan_describe(&total.expected, parallel, e, sizeof e), cal_plan_describe(&total.worst, parallel, w, sizeof w);
    cal_plan_describe_mser(&total.expected, store, mser, sizeof mser);
    fprintf(stderr, "== plan: %d drum runs (%d lining(s) x %d seed(s) x %d speed(s)); expected %s; worst case %s; %.0f MB a "
                    "simulation\n   " CAL_PLAN_RUN_ASSUMPTION " (%s.) k_n %g N/m. At %.2g particle-steps per core-second "
                    "(this project's 2-core machine): the whole synthesis; where a store holds some of it, a last line says what "
                    "is left.\n",
            total.expected.runs, j->n_linings, j->opt.n_seeds, j->n_rpm, e, w, total.expected.memory_mb, mser, j->k_n,
            CAL_PLAN_RATE);
    cal_plan_history_free(&history);
    print_left(j, lining_cost, store);
}

static int prepare(job *j)
{
    j->c = cal_config_load(j->opt.config, j->opt.tier, j->err, sizeof j->err);
    if (!j->c) return 1;
    j->t = cal_config_tier(j->c);
    j->k_n = isfinite(j->opt.k_n) ? j->opt.k_n : j->c->k_n;
    j->gg_mu_s = j->opt.has_granule ? j->opt.granule.mu_s : j->c->granule_mu_s;
    j->gg_mu_r = j->opt.has_granule ? j->opt.granule.mu_r : j->c->granule_mu_r;
    if (choose_speeds(j) || choose_linings(j)) return 1;
    if (j->opt.out) snprintf(j->out, sizeof j->out, "%s", j->opt.out);
    else snprintf(j->out, sizeof j->out, "results/synthetic-%.60s", j->t->name);
    if (j->opt.reuse && access(j->opt.reuse, R_OK | X_OK) != 0)
        return exp_fail(j->err, sizeof j->err, "--reuse %s: %s", j->opt.reuse, strerror(errno));
    print_plan(j);
    if (j->opt.plan_only) return 0; // no folder made
    if (cal_prepare_output(j->out, j->err, sizeof j->err)) return 1;
    snprintf(j->env.store, sizeof j->env.store, "%s/store", j->out);
    j->env.workers = j->opt.jobs, j->env.use_fork = cal_mpi_size() == 1, j->env.tty = isatty(2);
    j->env.checkpoint_every_s = CAL_CHECKPOINT_EVERY_S, j->env.started = exp_wall_seconds();
    return 0;
}

// Each lining a stage of seeds × speeds drum runs (those reused or stored
// count as done, and their recorded cost sets the time left from the start).
static void plan_progress(job *j)
{
    cal_progress_init(&j->progress, j->env.workers * cal_mpi_size());
    for (int l = 0; l < j->n_linings; ++l)
        cal_progress_plan(&j->progress, j->linings[l].surface, CAL_RUN_DRUM, j->opt.n_seeds * j->n_rpm);
    j->env.progress = &j->progress;
}

int cal_cmd_synthesize(int argc, char **argv)
{
    job *j = calloc(1, sizeof *j);
    if (!j) return fputs("granucal synthesize: out of memory\n", stderr), 1;
    int status = parse_options(argc, argv, &j->opt);
    if (status) return free(j), status < 0 ? 0 : status;
    char command[2048];
    cal_cli_begin(&argc, &argv, command, sizeof command);
    lining_result res[MAX_WALLS + 1];
    status = prepare(j);
    if (!status && j->opt.plan_only) {
        fputs("granucal synthesize: --plan: every input checked, nothing was run\n", stderr);
        j->n_linings = 0; // nothing to make, nothing to write
    } else if (!status) plan_progress(j);
    for (int l = 0; l < j->n_linings && !status; ++l) {
        fprintf(stderr, "== %s: %d seed(s) x %d speed(s)\n", j->linings[l].surface, j->opt.n_seeds, j->n_rpm);
        status = make_lining(j, &j->linings[l], &res[l]);
    }
    if (!status && !j->opt.plan_only && cal_mpi_rank() == 0) {
        status = write_files(j, res, command);
        if (!status) fprintf(stderr, "granucal synthesize: wrote %s/repose_angle.csv and occupied_area.csv\n", j->out);
    }
    status = cal_cli_end("synthesize", status, j->err, &j->env, j->c);
    free(j);
    return status;
}
