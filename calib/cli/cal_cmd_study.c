// SPDX-License-Identifier: MIT
// `granucal study fidelity`: what accuracy costs in time. The drum at the
// config's granule-granule pair over a ladder of fidelity rungs (scale factor,
// slice or full drum, run length, steady-state window and tolerance), several
// seeds each, every simulation through the result store (resumable); then the
// error of each rung against the finest rung run, against its wall time.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <unistd.h>

#include "cal_case_runs.h"
#include "cal_cli_frame.h"
#include "cal_commands.h"
#include "cal_files.h"
#include "cal_mpi.h"
#include "cal_options.h"
#include "cal_plan.h"
#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_plot.h"

static const char synopsis[] =
    "usage: granucal study fidelity [CONFIG.yaml] [options]\n"
    "\n"
    "Runs the drum lined with granules at the config's granule-granule pair (Table 3:\n"
    "mu_s 0.8, mu_r 0.2, the same as the aluminium drum of the paper's Table B.1) on each\n"
    "rung of the config's `fidelity:` ladder: coarse-graining factor lambda (eq. 15-18),\n"
    "periodic slice or full drum, run length, steady-state window and tolerance. Each\n"
    "rung runs `seeds` beds (different granules) at every speed of `fidelity.rpm`.\n"
    "\n"
    "For each rung it records the angle and CSA at each speed (mean and spread over\n"
    "seeds), granules, particle-steps, wall time and peak memory, and reports the error\n"
    "against the finest rung that was run (smallest lambda; then full drum; then the\n"
    "longest run) beside the paper's Table B.1 (lambda 8, 27, 64).\n"
    "\n"
    "A rung whose predicted wall time exceeds the budget left is not run; its prediction\n"
    "(scaled from the largest rung run: granules ~ depth / lambda, steps ~ lambda^(-1/6)\n"
    "since eq. 16-17 keep the granule mass, so dt_crit ~ lambda^(1/6)) is listed instead.\n";

static const char epilogue[] =
    "Outputs in DIR: fidelity.csv (rung x speed), fidelity_summary.csv (rung),\n"
    "fidelity.md, fidelity_error_vs_cost.png, fidelity_vs_lambda.png (or, where every\n"
    "rung run has one lambda, fidelity_vs_slice_depth.png), store/.\n"
    "Run it again with the same options: stored simulations are not rerun.\n";

enum { MAX_RUNGS = 32, MAX_SPEEDS = 16, MAX_SEEDS = 16 };

// The paper's Table B.1: aluminium drum, calibrated model, angle and CSA.
static const struct {
    double lambda, angle_deg, csa_percent;
} table_b1[] = {{8, 33.4, 43.9}, {27, 33.9, 44.5}, {64, 34.6, 45.5}};

typedef struct options {
    const char *config, *out, *rungs, *rpm; ///< rungs, rpm: comma lists (NULL: all)
    const char *report;                     ///< where the report goes (NULL: out)
    double budget_hours, checkpoint_every_s;
    int jobs, seeds; ///< seeds 0: the config's
    int plan_only;   ///< --plan: print the plan and stop
    int yes;         ///< --yes: the whole ladder (no --rungs) may run
} options;

typedef struct rung_result {
    const cal_tier *rung;
    int ran;                     ///< 1 measured, 0 skipped (predicted only)
    double predicted_s;          ///< wall time predicted before running (NAN: no basis yet)
    double depth;                ///< m, slice or full drum
    double angle[MAX_SPEEDS], angle_sd[MAX_SPEEDS]; ///< mean and spread over seeds
    double csa[MAX_SPEEDS], csa_sd[MAX_SPEEDS];
    int steady[MAX_SPEEDS], usable[MAX_SPEEDS];    ///< runs steady / runs with a measurement
    double angle_se[MAX_SPEEDS];  ///< standard error of the mean over seeds (independent runs)
    double granules, particle_steps, wall_s, peak_rss_mb, dt_s;
    int runs;                     ///< simulations (seeds x speeds), for the wall time per run
    double angle_error, csa_error; ///< against the finest rung run
} rung_result;

typedef struct study {
    options opt;
    cal_config *c;
    cal_env env;
    char out[1024], report[1024];
    rung_result res[MAX_RUNGS];
    int n;
    int finest;                  ///< index of the finest rung run (converged only if shown: write_convergence)
    char err[2048];
} study;

// 0: parsed; -1: --help printed; else the exit status of a usage error.
static int parse_options(int argc, char **argv, options *o)
{
    *o = (options){.config = "configs/calibration.yaml", .out = "results/fidelity", .budget_hours = NAN,
                   .jobs = cal_default_jobs(), .checkpoint_every_s = CAL_CHECKPOINT_EVERY_S};
    const cal_option table[] = {
        cal_option_out(&o->out, "results folder (default results/fidelity)"),
        {.name = "report", .kind = CAL_OPT_TEXT, .text = &o->report, .value = "DIR",
         .help = "write fidelity.md, its CSVs and plots into DIR instead of OUT (the runs still go to OUT/store): a "
                 "few rungs or speeds reported beside the ladder's own fidelity.md, not over it"},
        cal_option_budget_hours(&o->budget_hours, "replaces fidelity.budget_hours"),
        {.name = "seeds", .kind = CAL_OPT_INT, .integer = &o->seeds, .lo = 1, .hi = MAX_SEEDS, .value = "N",
         .help = "replaces fidelity.seeds"},
        {.name = "rungs", .kind = CAL_OPT_TEXT, .text = &o->rungs, .value = "A,B,...",
         .help = "only these rungs, in config order (a name not in the ladder is refused); without it every rung, "
                 "which needs --yes"},
        {.name = "rpm", .kind = CAL_OPT_TEXT, .text = &o->rpm, .value = "A,B,...",
         .help = "only these of fidelity.rpm (e.g. --rpm 4 to narrow the 4 rpm angle's error first; default: every "
                 "speed)"},
        cal_option_jobs(&o->jobs),
        cal_option_checkpoint_every(&o->checkpoint_every_s, "wall seconds between a drum run's checkpoints (default "
                                                            "120; 0: none); a killed study, run again, resumes each turn"),
        cal_option_plan(&o->plan_only, "check the config, print the plan (each rung's drum runs, core-hours and wall "
                                       "hours on --jobs workers, expected and worst case, which fit the budget, and "
                                       "how many of its runs OUT/store holds; a rung held whole runs whatever the "
                                       "budget) and stop: nothing runs. Where it holds some, a last line (== left) says "
                                       "what is left"),
        {.name = "yes", .kind = CAL_OPT_FLAG, .flag = &o->yes, .set_to = 1,
         .help = "run every rung: without --rungs the study prints its plan and stops with exit status 2 (the whole "
                 "ladder is many hours)"},
    };
    const cal_command_line line = {.command = "study fidelity", .synopsis = synopsis, .epilogue = epilogue, .options = table,
                                   .n_options = sizeof table / sizeof *table};
    return cal_options_parse_config(&line, argc, argv, &o->config);
}

static int wanted(const char *list, const char *name)
{
    if (!list) return 1;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)); p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == 0)) return 1;
    return 0;
}

/// Every name of --rungs must be a rung of the ladder: a misspelt one would
/// otherwise be skipped without a word. The error lists the rungs there are.
static int check_rungs(const cal_fidelity *f, const char *list, const char *path, char *err, size_t len)
{
    char copy[1024];
    snprintf(copy, sizeof copy, "%s", list);
    for (char *save = NULL, *t = strtok_r(copy, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        unsigned k = 0;
        while (k < f->rungs_count && strcmp(f->rungs[k].name, t) != 0) ++k;
        if (k < f->rungs_count) continue;
        char names[4096] = "";
        for (unsigned j = 0; j < f->rungs_count; ++j)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", j ? ", " : "", f->rungs[j].name);
        return exp_fail(err, len, "--rungs %s: '%s' is not a rung of %s (fidelity.rungs); its rungs: %s", list, t, path, names);
    }
    return 0;
}

/// Keeps only the speeds of `list` (comma-separated rpm) in the ladder's
/// speeds, in the config's order; a speed the ladder does not have is refused
/// (a study of a speed nobody configured would have no store to share).
static int narrow_speeds(cal_fidelity *f, const char *list, const char *path, char *err, size_t len)
{
    unsigned keep[MAX_SPEEDS] = {0};
    char copy[512];
    snprintf(copy, sizeof copy, "%s", list);
    for (char *save = NULL, *t = strtok_r(copy, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        double v;
        if (exp_parse_number(t, &v)) return exp_fail(err, len, "--rpm '%s': '%s' is not a number", list, t);
        unsigned k = 0;
        while (k < f->rpm_count && f->rpm[k] != v) ++k;
        if (k == f->rpm_count || k >= MAX_SPEEDS)
            return exp_fail(err, len, "--rpm %g: not one of fidelity.rpm in %s", v, path);
        keep[k] = 1;
    }
    unsigned n = 0;
    for (unsigned k = 0; k < f->rpm_count; ++k)
        if (keep[k]) f->rpm[n++] = f->rpm[k];
    f->rpm_count = n;
    return n ? 0 : exp_fail(err, len, "--rpm '%s': no speed given", list);
}

// A rung is a tier with the drum's knobs alone (cal_config.h): its drum case
// is the calibration's at the config's granule pair.
static cal_drum_case case_of(const study *s, const cal_tier *r, int seed)
{
    cal_drum_case d = cal_drum_case_granule(s->c, r, s->c->k_n, s->c->granule_mu_s, s->c->granule_mu_r);
    cal_drum_case_set_seed(&d, (uint64_t)(s->c->seed + seed));
    return d;
}

// 1 if every simulation of the rung is already in the store.
// How many of rung r's runs (its seeds x speeds) the store already holds (a file of their key).
static int runs_stored(const study *s, const cal_tier *r, const char *store)
{
    const cal_fidelity *f = s->c->fidelity;
    int n = 0;
    for (int seed = 0; seed < f->seeds; ++seed) {
        cal_drum_case d = case_of(s, r, seed);
        for (unsigned k = 0; k < f->rpm_count; ++k) {
            char key[2048], path[1300];
            cal_drum_key(&d, f->rpm[k], key, sizeof key);
            cal_store_path(store, key, path, sizeof path);
            n += access(path, F_OK) == 0;
        }
    }
    return n;
}

static int runs_of(const study *s) { return s->c->fidelity->seeds * (int)s->c->fidelity->rpm_count; }

static int all_stored(const study *s, const cal_tier *r) { return runs_stored(s, r, s->env.store) == runs_of(s); }

// Wall time of a rung scaled from a measured one: granules ~ depth/lambda
// (same bed volume per depth, granule volume ~ lambda), steps per simulated
// second ~ 1/dt ~ lambda^(-1/6) (eq. 14 with eq. 16-17: the coarse granule
// keeps the mass, the stiffness falls as lambda^(-1/3)), simulated time ~
// speeds x max_time plus the fill (about 3 s of settling whatever lambda).
static double predict_wall(const rung_result *base, const cal_tier *r, double depth)
{
    const double fill_s = 3.0;
    double n = base->granules * (base->rung->lambda / r->lambda) * (depth / base->depth);
    double steps_per_s = pow(base->rung->lambda / r->lambda, 1.0 / 6.0);
    double time = (fill_s + r->max_time) / (fill_s + base->rung->max_time);
    return base->wall_s * (n / base->granules) * steps_per_s * time;
}

static void mean_sd(const double *x, int n, double *mean, double *sd)
{
    double m = 0, v = 0;
    for (int i = 0; i < n; ++i) m += x[i];
    m = n ? m / n : NAN;
    for (int i = 0; i < n; ++i) v += (x[i] - m) * (x[i] - m);
    *mean = m, *sd = n > 1 ? sqrt(v / (n - 1)) : NAN;
}

// Each wanted rung's cost from the cost model (cal_plan.h): its seeds side by
// side, each settling its own bed and turning every speed; and whether it
// fits the budget left, in config order as run_ladder goes (which predicts
// from the rungs it has measured by then, so the two can differ).
static double print_plan(const study *s)
{
    const cal_fidelity *f = s->c->fidelity;
    int parallel = s->opt.jobs * cal_mpi_size();
    double budget_s = 3600 * (isfinite(s->opt.budget_hours) ? s->opt.budget_hours : f->budget_hours), spent = 0;
    cal_plan total = {{0}, {0}};
    cal_plan_cost left = {0}; // of the rungs that fit: their runs not stored, at the rung's expected cost per run
    int any_stored = 0;
    char store[1100], err[1024];
    cal_plan_history history; // unreadable: the plan takes max_time for MSER runs, and says how many
    snprintf(store, sizeof store, "%s/store", s->opt.out);
    cal_plan_history_read(&history, store, err, sizeof err);
    fprintf(stderr, "== plan: study fidelity, %d seed(s) x %u speed(s) a rung, %d worker(s); expected (worst case)\n", f->seeds,
            f->rpm_count, parallel);
    for (unsigned k = 0; k < f->rungs_count; ++k) {
        const cal_tier *rung = &f->rungs[k];
        if (!wanted(s->opt.rungs, rung->name)) continue;
        cal_plan p = {{0}, {0}};
        cal_drum_case d = cal_drum_case_granule(s->c, rung, s->c->k_n, s->c->granule_mu_s, s->c->granule_mu_r);
        for (int w = 0; w < 2; ++w)
            cal_plan_drum_batch(w ? &p.worst : &p.expected, &d, f->rpm, (int)f->rpm_count, f->seeds, 1, 0, 0, parallel, w,
                                &history);
        // A rung whose runs are all stored runs whatever the budget, as run_ladder does.
        int stored = runs_stored(s, rung, store), all = runs_of(s);
        int fits = stored == all || spent + p.expected.wall_s <= budget_s;
        spent += fits ? p.expected.wall_s : 0;
        char note[64] = "";
        if (stored > 0) snprintf(note, sizeof note, "  %d of %d stored", stored, all);
        fprintf(stderr, "   %-22s %4d drum runs %8.2f (%8.2f) core-hours %7.2f (%7.2f) h%s%s\n", rung->name, p.expected.runs,
                p.expected.core_s / 3600, p.worst.core_s / 3600, p.expected.wall_s / 3600, p.worst.wall_s / 3600,
                fits ? "" : "  over the budget left: not run", note);
        if (fits) {
            cal_plan_add(&total, &p);
            cal_plan_add_runs(&left, &p.expected, all - stored);
            any_stored |= stored > 0;
        }
    }
    char e[128], w[128], mser[1300];
    cal_plan_describe(&total.expected, parallel, e, sizeof e), cal_plan_describe(&total.worst, parallel, w, sizeof w);
    cal_plan_describe_mser(&total.expected, store, mser, sizeof mser);
    fprintf(stderr, "== plan: the rungs within the budget (%.3g h): %d drum runs, expected %s; worst case %s\n"
                    "   " CAL_PLAN_RUN_ASSUMPTION " (%s.) At %.2g particle-steps per core-second (this project's 2-core "
                    "machine): the whole of those rungs; where the store holds some of their runs, a last line says "
                    "what is left.\n",
            budget_s / 3600, total.expected.runs, e, w, mser, CAL_PLAN_RATE);
    if (any_stored) {
        char l[128];
        cal_plan_describe(&left, parallel, l, sizeof l);
        fprintf(stderr, "== left: %d of the %d drum runs not in %s yet; expected %s (each rung's expected cost per "
                        "run)\n", left.runs, total.expected.runs, store, l);
    }
    cal_plan_history_free(&history);
    return total.expected.wall_s;
}

// Run (or read back) every seed and speed of a rung and reduce them.
static int measure_rung(study *s, rung_result *out)
{
    const cal_fidelity *f = s->c->fidelity;
    double angle[MAX_SPEEDS][MAX_SEEDS], csa[MAX_SPEEDS][MAX_SEEDS];
    int n_ok[MAX_SPEEDS] = {0};
    out->granules = out->particle_steps = out->wall_s = out->peak_rss_mb = 0;
    out->runs = 0;
    // Every seed's speeds at once: their missing runs share the workers, so a
    // rung with one run left per seed does not leave the others idle.
    cal_drum_case cases[MAX_SEEDS];
    for (int seed = 0; seed < f->seeds; ++seed) cases[seed] = case_of(s, out->rung, seed);
    const int n_rpm = (int)f->rpm_count;
    cal_record *rec = calloc((size_t)f->seeds * (size_t)n_rpm, sizeof *rec);
    if (!rec) return exp_fail(s->err, sizeof s->err, "out of memory");
    if (cal_drum_evaluate_many(&s->env, cases, f->seeds, f->rpm, n_rpm, rec, s->err, sizeof s->err)) return free(rec), 1;
    for (int seed = 0; seed < f->seeds; ++seed)
        for (int k = 0; k < n_rpm; ++k) {
            cal_record *r = &rec[seed * n_rpm + k];
            out->wall_s += cal_record_cost_s(r);
            out->runs++;
            out->particle_steps += r->particle_steps;
            out->peak_rss_mb = fmax(out->peak_rss_mb, r->peak_rss_mb);
            if (cal_record_usable(r) && isfinite(r->angle_deg)) {
                angle[k][n_ok[k]] = r->angle_deg, csa[k][n_ok[k]] = r->csa_percent;
                n_ok[k]++;
                out->steady[k] += r->steady;
                out->granules += r->granules, out->dt_s = r->dt_s;
            }
            cal_record_free(r);
        }
    free(rec);
    int usable = 0;
    for (unsigned k = 0; k < f->rpm_count; ++k) {
        out->usable[k] = n_ok[k], usable += n_ok[k];
        mean_sd(angle[k], n_ok[k], &out->angle[k], &out->angle_sd[k]);
        // Seeds are independent runs, so their means are independent samples:
        // no correction for the frames' correlation within a run is needed here.
        out->angle_se[k] = out->angle_sd[k] / sqrt((double)n_ok[k]);
        mean_sd(csa[k], n_ok[k], &out->csa[k], &out->csa_sd[k]);
    }
    out->granules = usable ? out->granules / usable : NAN;
    out->ran = 1;
    return 0;
}

// The finest rung run: the smallest lambda, then the full drum, then the
// longest run and window.
static int finer(const rung_result *a, const rung_result *b)
{
    if (a->rung->lambda != b->rung->lambda) return a->rung->lambda < b->rung->lambda;
    if ((a->rung->slice_depth == 0) != (b->rung->slice_depth == 0)) return a->rung->slice_depth == 0;
    if (a->rung->max_time != b->rung->max_time) return a->rung->max_time > b->rung->max_time;
    return a->rung->window > b->rung->window;
}

static void errors_against_finest(study *s)
{
    const cal_fidelity *f = s->c->fidelity;
    s->finest = -1;
    for (int i = 0; i < s->n; ++i)
        if (s->res[i].ran && (s->finest < 0 || finer(&s->res[i], &s->res[s->finest]))) s->finest = i;
    for (int i = 0; i < s->n; ++i) {
        rung_result *r = &s->res[i];
        r->angle_error = r->csa_error = NAN;
        if (!r->ran || s->finest < 0) continue;
        const rung_result *ref = &s->res[s->finest];
        // The angle at the first speed (the lab's angle speed, 4 rpm in Table 2);
        // the CSA as the root mean square over the speeds.
        r->angle_error = fabs(r->angle[0] - ref->angle[0]);
        double sum = 0;
        int n = 0;
        for (unsigned k = 0; k < f->rpm_count; ++k)
            if (isfinite(r->csa[k]) && isfinite(ref->csa[k])) sum += pow(r->csa[k] - ref->csa[k], 2), n++;
        r->csa_error = n ? sqrt(sum / n) : NAN;
    }
}

static int write_csv(const study *s, char *err, size_t len)
{
    const cal_fidelity *f = s->c->fidelity;
    char path[1200];
    exp_atomic_file a;
    snprintf(path, sizeof path, "%s/fidelity.csv", s->report);
    if (exp_atomic_open(&a, path, err, len)) return 1;
    fputs("rung,lambda,slice_depth_m,max_time_s,window_s,seeds,rpm,angle_deg,angle_sd_seeds_deg,angle_se_deg,csa_percent,"
          "csa_sd_seeds_percent,steady_runs,usable_runs\n",
          a.f);
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran) continue;
        for (unsigned k = 0; k < f->rpm_count; ++k)
            fprintf(a.f, "%s,%g,%g,%g,%g,%d,%g,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%d\n", r->rung->name, r->rung->lambda,
                    r->rung->slice_depth, r->rung->max_time, r->rung->window, f->seeds, f->rpm[k], r->angle[k],
                    r->angle_sd[k], r->angle_se[k], r->csa[k], r->csa_sd[k], r->steady[k], r->usable[k]);
    }
    if (exp_atomic_commit(&a, err, len)) return 1;
    snprintf(path, sizeof path, "%s/fidelity_summary.csv", s->report);
    if (exp_atomic_open(&a, path, err, len)) return 1;
    fputs("rung,lambda,slice_depth_m,max_time_s,window_s,status,granules,particle_steps,wall_time_s,wall_time_per_run_s,"
          "predicted_wall_time_s,peak_rss_mb,dt_s,angle_error_deg,csa_rms_error_percent,finest_rung\n",
          a.f);
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        fprintf(a.f, "%s,%g,%g,%g,%g,%s,%.0f,%.4g,%.1f,%.1f,%.4g,%.1f,%.4g,%.3f,%.3f,%s\n", r->rung->name, r->rung->lambda,
                r->rung->slice_depth, r->rung->max_time, r->rung->window, r->ran ? "run" : "not run (over budget)",
                r->ran ? r->granules : NAN, r->ran ? r->particle_steps : NAN, r->ran ? r->wall_s : NAN,
                r->ran && r->runs ? r->wall_s / r->runs : NAN, r->predicted_s,
                r->ran ? r->peak_rss_mb : NAN, r->ran ? r->dt_s : NAN, r->angle_error, r->csa_error,
                s->finest >= 0 ? s->res[s->finest].rung->name : "");
    }
    return exp_atomic_commit(&a, err, len);
}

static void machine_line(FILE *f)
{
    struct utsname u;
    char model[256] = "unknown CPU", line[512];
    FILE *cpu = fopen("/proc/cpuinfo", "r");
    while (cpu && fgets(line, sizeof line, cpu))
        if (strncmp(line, "model name", 10) == 0) {
            const char *colon = strchr(line, ':');
            snprintf(model, sizeof model, "%.200s", colon ? colon + 2 : line);
            model[strcspn(model, "\n")] = 0;
            break;
        }
    if (cpu) fclose(cpu);
    uname(&u);
    fprintf(f, "Machine: %s, %ld cores online, %s %s.  \n", model, sysconf(_SC_NPROCESSORS_ONLN), u.sysname, u.release);
}

// "mean ± sd", or the mean alone when one seed gives no spread.
static void with_spread(char *out, size_t len, double mean, double sd)
{
    if (isfinite(sd)) snprintf(out, len, "%.2f ± %.2f", mean, sd);
    else snprintf(out, len, "%.2f", mean);
}

// Within 1° (angle at the first speed) and 1 point (CSA rms over the speeds)
// of the finest rung: the bar for "converged there".
#define CONVERGED_ANGLE_DEG 1.0
#define CONVERGED_CSA_PERCENT 1.0

static int within_band(const rung_result *r)
{
    return r->ran && r->angle_error <= CONVERGED_ANGLE_DEG && r->csa_error <= CONVERGED_CSA_PERCENT;
}

// Which rungs agree with the finest one, and whether the ladder has been
// shown converged there: only if the next coarser scale factor run also
// agrees (a plateau); a rung is never called converged because it is the
// finest reached.
static void write_convergence(FILE *o, const study *s)
{
    if (s->finest < 0) return;
    const rung_result *ref = &s->res[s->finest];
    const rung_result *coarsest = NULL, *next = NULL;
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran || i == s->finest) continue;
        if (within_band(r) && (!coarsest || r->rung->lambda > coarsest->rung->lambda)) coarsest = r;
        if (r->rung->lambda > ref->rung->lambda && (!next || r->rung->lambda < next->rung->lambda)) next = r;
    }
    fprintf(o, "\nThe finest rung run is %s (λ %g). ", ref->rung->name, ref->rung->lambda);
    if (coarsest)
        fprintf(o, "The coarsest rung within %g° and %g point of it is %s (λ %g). ", CONVERGED_ANGLE_DEG,
                CONVERGED_CSA_PERCENT, coarsest->rung->name, coarsest->rung->lambda);
    else fprintf(o, "No other rung lies within %g° and %g point of it. ", CONVERGED_ANGLE_DEG, CONVERGED_CSA_PERCENT);
    // Within the band is not enough: a difference the seeds resolve (over two
    // standard errors of the difference) says the angle is still moving.
    double se = next ? hypot(next->angle_se[0], ref->angle_se[0]) : NAN;
    int resolved = next && isfinite(se) && se > 0 && next->angle_error > 2 * se;
    if (next && within_band(next) && resolved)
        fprintf(o, "The next coarser λ run (%s, λ %g) lies within that band, **but the angle is still moving**: it "
                   "differs by %.2f ± %.2f° (%.1f standard errors of the difference), so the ladder has not been shown "
                   "converged.\n",
                next->rung->name, next->rung->lambda, next->angle_error, se, next->angle_error / se);
    else if (next && within_band(next))
        fprintf(o, "The next coarser λ run (%s, λ %g) agrees with it within that band (%.2f°, %s), so the ladder has "
                   "levelled off there, as far as these seeds tell.\n",
                next->rung->name, next->rung->lambda, next->angle_error,
                isfinite(se) ? "within two standard errors of the difference" : "one seed: no spread");
    else if (next)
        fprintf(o, "**The ladder has not been shown converged:** between %s (λ %g) and %s (λ %g) the angle still moves "
                   "by %.2f° and the CSA by %.2f points.\n",
                next->rung->name, next->rung->lambda, ref->rung->name, ref->rung->lambda, next->angle_error,
                next->csa_error);
    else fputs("**No coarser λ was run beside it: its convergence is not shown.**\n", o);
}

// Every speed of every rung run: the angle ± the standard error of its seed
// mean, and the CSA ± its seed sd (the first table shows the first speed only).
static void write_speeds_table(FILE *o, const study *s)
{
    const cal_fidelity *f = s->c->fidelity;
    fputs("\nEvery speed, angle (°) ± SE / CSA (%) ± seed sd:\n\n| rung |", o);
    for (unsigned k = 0; k < f->rpm_count; ++k) fprintf(o, " %g rpm |", f->rpm[k]);
    fputs("\n|---|", o);
    for (unsigned k = 0; k < f->rpm_count; ++k) fputs("---|", o);
    fputc('\n', o);
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran) continue;
        fprintf(o, "| %s |", r->rung->name);
        for (unsigned k = 0; k < f->rpm_count; ++k) {
            char angle[48], csa[48];
            with_spread(angle, sizeof angle, r->angle[k], r->angle_se[k]);
            with_spread(csa, sizeof csa, r->csa[k], r->csa_sd[k]);
            fprintf(o, " %s / %s |", angle, csa);
        }
        fputc('\n', o);
    }
}

// What the rungs run differ in, for the figure of the first speed: the scale
// factor, or where every rung has one λ, the slice depth (a slice-depth study).
static int against_depth(const study *s)
{
    double lambda = NAN, depth = NAN;
    int depths_differ = 0;
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran) continue;
        if (isfinite(lambda) && r->rung->lambda != lambda) return 0;
        depths_differ |= isfinite(depth) && r->depth != depth;
        lambda = r->rung->lambda, depth = r->depth;
    }
    return depths_differ;
}

static const char *versus_file(const study *s)
{
    return against_depth(s) ? "fidelity_vs_slice_depth.png" : "fidelity_vs_lambda.png";
}

static int write_markdown(const study *s, const char *command, double wall, char *err, size_t len)
{
    const cal_fidelity *f = s->c->fidelity;
    char path[1200];
    exp_atomic_file a;
    snprintf(path, sizeof path, "%s/fidelity.md", s->report);
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *o = a.f;
    fprintf(o, "# What accuracy costs in time: the drum fidelity ladder\n\nCommand: `%s`  \ngranucal %s (commit %s), "
               "config `%s`, %.0f s wall for this run (stored simulations are not rerun).  \n",
            command, exp_version(), cal_build_commit(), s->c->path, wall);
    machine_line(o);
    fprintf(o, "Drum lined with granules, granule-granule pair μs = %g, μr = %g, k_n = %g N/m; %d seed(s) per rung; "
               "speeds",
            s->c->granule_mu_s, s->c->granule_mu_r, s->c->k_n, f->seeds);
    for (unsigned k = 0; k < f->rpm_count; ++k) fprintf(o, " %g", f->rpm[k]);
    fputs(" rpm. The angle is the first speed's, with the standard error of its mean over the seeds (independent "
          "runs: sd / sqrt(seeds)); errors are against the finest rung run.\n\n",
          o);
    fputs("| rung | λ | depth | run / window / averaged on (s) | granules | angle (°) ± SE | SE ≤ 0.5°? | CSA (%) ± seeds | "
          "angle error (°) | CSA rms error (%) | wall per run (s) | particle-steps | peak MiB |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
          o);
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        char depth[32];
        if (r->rung->slice_depth > 0) snprintf(depth, sizeof depth, "%g mm slice", 1e3 * r->rung->slice_depth);
        else snprintf(depth, sizeof depth, "full drum");
        if (!r->ran) {
            fprintf(o, "| %s | %g | %s | %g / %g / %g | not run | | | | | | predicted %.3g h for the rung | | |\n",
                    r->rung->name, r->rung->lambda, depth, r->rung->max_time, r->rung->window, r->rung->average_time,
                    r->predicted_s / 3600);
            continue;
        }
        char angle[48], csa[48];
        with_spread(angle, sizeof angle, r->angle[0], r->angle_se[0]);
        with_spread(csa, sizeof csa, r->csa[0], r->csa_sd[0]);
        fprintf(o, "| %s%s | %g | %s | %g / %g / %g | %.0f | %s | %s | %s | %.2f | %.2f | %.0f | %.3g | %.0f |\n",
                r->rung->name, i == s->finest ? " (finest)" : "", r->rung->lambda, depth, r->rung->max_time,
                r->rung->window, r->rung->average_time,
                r->granules, angle, isfinite(r->angle_se[0]) ? (r->angle_se[0] <= 0.5 ? "yes" : "no") : "one seed",
                csa, r->angle_error, r->csa_error, r->runs ? r->wall_s / r->runs : NAN, r->particle_steps,
                r->peak_rss_mb);
    }
    write_convergence(o, s);
    if (f->rpm_count > 1) write_speeds_table(o, s);
    fputs("\nThe paper's Table B.1 (aluminium drum, calibrated model; its rpm is not stated), beside the rungs:\n\n"
          "| λ | angle (°) | CSA (%) |\n|---|---|---|\n",
          o);
    for (size_t k = 0; k < sizeof table_b1 / sizeof *table_b1; ++k)
        fprintf(o, "| %g (paper) | %.1f | %.1f |\n", table_b1[k].lambda, table_b1[k].angle_deg, table_b1[k].csa_percent);
    for (int i = 0; i < s->n; ++i)
        if (s->res[i].ran)
            fprintf(o, "| %g (%s, %g rpm) | %.2f | %.2f |\n", s->res[i].rung->lambda, s->res[i].rung->name, f->rpm[0],
                    s->res[i].angle[0], s->res[i].csa[0]);
    fprintf(o, "\nFiles: `fidelity.csv` (every rung and speed), `fidelity_summary.csv`, `fidelity_error_vs_cost.png`, "
               "`%s`%s.\n",
            versus_file(s), f->rpm_count > 1 ? ", `fidelity_vs_rpm.png`" : "");
    return exp_atomic_commit(&a, err, len);
}

// Each rung run, in the order of the ladder: what the two figures plot.
typedef struct rung_points {
    int n;
    double cost[MAX_RUNGS], angle_error[MAX_RUNGS], csa_error[MAX_RUNGS]; ///< all but the finest
    const char *name[MAX_RUNGS];
    int m;
    double lambda[MAX_RUNGS], depth_mm[MAX_RUNGS], angle[MAX_RUNGS], angle_sd[MAX_RUNGS], csa[MAX_RUNGS],
        csa_sd[MAX_RUNGS];
    const char *rung_of[MAX_RUNGS];
} rung_points;

static void collect_rungs(const study *s, rung_points *p)
{
    p->n = p->m = 0;
    for (int i = 0; i < s->n; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran) continue;
        p->lambda[p->m] = r->rung->lambda, p->depth_mm[p->m] = 1e3 * r->depth;
        p->angle[p->m] = r->angle[0], p->csa[p->m] = r->csa[0];
        p->angle_sd[p->m] = isfinite(r->angle_sd[0]) ? r->angle_sd[0] : 0;
        p->csa_sd[p->m] = isfinite(r->csa_sd[0]) ? r->csa_sd[0] : 0;
        p->rung_of[p->m++] = r->rung->name;
        if (i == s->finest) continue; // its error is zero by definition
        p->cost[p->n] = r->wall_s, p->angle_error[p->n] = r->angle_error, p->csa_error[p->n] = r->csa_error;
        p->name[p->n++] = r->rung->name;
    }
}

// What accuracy costs: each rung's errors against the finest at its wall
// time, the rung named beside its angle point.
static int plot_error_vs_cost(const study *s, const rung_points *p, char *err, size_t len)
{
    char path[1200], title[160];
    snprintf(path, sizeof path, "%s/fidelity_error_vs_cost.png", s->report);
    snprintf(title, sizeof title, "What accuracy costs: error against the finest rung (%s)",
             s->finest >= 0 ? s->res[s->finest].rung->name : "none");
    exp_plot_series v[2] = {
        {.n = (size_t)p->n, .x = p->cost, .y = p->angle_error, .names = p->name, .label = "angle error (°)",
         .rgb = {0.84, 0.15, 0.16}, .style = EXP_PLOT_POINTS, .marker = EXP_MARK_CIRCLE},
        {.n = (size_t)p->n, .x = p->cost, .y = p->csa_error, .label = "CSA rms error over the speeds (%)",
         .rgb = {0.12, 0.40, 0.75}, .style = EXP_PLOT_POINTS, .marker = EXP_MARK_SQUARE},
    };
    exp_plot_axes axes = {.title = title, .xlabel = "wall time of the rung (s)",
                          .ylabel = "error (° for the angle, % for the CSA)", .log_x = 1};
    return exp_plot_png(path, &axes, 2, v, 1000, 640, err, len);
}

// The first speed's angle and CSA against λ, or against the slice depth where
// every rung has one λ; beside the paper's Table B.1 (λ 8, 27, 64, its drum at
// 4 rpm) on a λ axis at 4 rpm only.
static int plot_vs_lambda(const study *s, const rung_points *p, char *err, size_t len)
{
    double b1_l[3], b1_a[3], b1_c[3], rpm = s->c->fidelity->rpm[0];
    for (int k = 0; k < 3; ++k)
        b1_l[k] = table_b1[k].lambda, b1_a[k] = table_b1[k].angle_deg, b1_c[k] = table_b1[k].csa_percent;
    int depth = against_depth(s), with_b1 = !depth && rpm == 4;
    size_t m = (size_t)p->m;
    const double *x = depth ? p->depth_mm : p->lambda;
    exp_plot_series v[4] = {
        {.n = m, .x = x, .y = p->angle, .err = p->angle_sd, .names = p->rung_of,
         .label = "angle, granucal (bars: seed sd)",
         .rgb = {0.84, 0.15, 0.16}, .style = EXP_PLOT_POINTS, .marker = EXP_MARK_CIRCLE},
        {.n = m, .x = x, .y = p->csa, .err = p->csa_sd, .label = "CSA, granucal (bars: seed sd)",
         .rgb = {0.12, 0.40, 0.75}, .style = EXP_PLOT_POINTS, .marker = EXP_MARK_SQUARE},
        {.n = 3, .x = b1_l, .y = b1_a, .label = "angle, paper's Table B.1 (4 rpm)", .rgb = {0.95, 0.6, 0.5},
         .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_TRIANGLE, .dashed = 1},
        {.n = 3, .x = b1_l, .y = b1_c, .label = "CSA, paper's Table B.1 (4 rpm)", .rgb = {0.5, 0.65, 0.95},
         .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_DIAMOND, .dashed = 1},
    };
    char path[1200], title[160];
    snprintf(path, sizeof path, "%s/%s", s->report, versus_file(s));
    if (depth)
        snprintf(title, sizeof title, "Angle and CSA against the slice depth (λ %g, %g rpm)", p->lambda[0], rpm);
    else snprintf(title, sizeof title, "Angle and CSA against the scale factor λ (%g rpm)", rpm);
    exp_plot_axes axes = {.title = title, .xlabel = depth ? "slice depth (mm; the drum's depth for a full drum)" : "scale factor λ",
                          .ylabel = "angle (°) / CSA (%)", .log_x = !depth};
    return exp_plot_png(path, &axes, with_b1 ? 4 : 2, v, 1000, 640, err, len);
}

// Each rung's angle and CSA against the drum's speed (a study of several
// speeds): where the rungs part, speed by speed. One colour a rung; the angle
// solid with circles, the CSA dashed with squares; bars: the seed sd. The
// first 8 rungs run (a colour each): beyond that the plot would not be read.
static int plot_vs_rpm(const study *s, char *err, size_t len)
{
    static const double palette[][3] = {{0.84, 0.15, 0.16}, {0.12, 0.40, 0.75}, {0.17, 0.63, 0.17},
                                        {0.58, 0.40, 0.74}, {1.00, 0.50, 0.05}, {0.55, 0.34, 0.29},
                                        {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}};
    enum { MAX_PLOTTED = sizeof palette / sizeof *palette };
    const cal_fidelity *f = s->c->fidelity;
    exp_plot_series v[2 * MAX_PLOTTED];
    char label[MAX_PLOTTED][96];
    size_t n = 0;
    for (int i = 0; i < s->n && n < 2 * MAX_PLOTTED; ++i) {
        const rung_result *r = &s->res[i];
        if (!r->ran) continue;
        const size_t c = n / 2;
        const double *rgb = palette[c];
        snprintf(label[c], sizeof label[0], "%s: angle (solid), CSA (dashed)", r->rung->name);
        v[n] = (exp_plot_series){.n = f->rpm_count, .x = f->rpm, .y = r->angle, .err = r->angle_sd,
                                 .label = label[c], .rgb = {rgb[0], rgb[1], rgb[2]},
                                 .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_CIRCLE};
        v[n + 1] = (exp_plot_series){.n = f->rpm_count, .x = f->rpm, .y = r->csa, .err = r->csa_sd,
                                     .rgb = {rgb[0], rgb[1], rgb[2]}, .dashed = 1,
                                     .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_SQUARE};
        n += 2;
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/fidelity_vs_rpm.png", s->report);
    exp_plot_axes axes = {.title = "Angle and CSA against the drum's speed, each rung (bars: seed sd)",
                          .xlabel = "drum speed (rpm)", .ylabel = "angle (°) / CSA (%)"};
    return exp_plot_png(path, &axes, n, v, 1000, 640, err, len);
}

static int write_plots(const study *s, char *err, size_t len)
{
    rung_points p;
    collect_rungs(s, &p);
    if (p.n > 0 && plot_error_vs_cost(s, &p, err, len)) return 1;
    if (p.m > 0 && plot_vs_lambda(s, &p, err, len)) return 1;
    return p.m > 0 && s->c->fidelity->rpm_count > 1 && plot_vs_rpm(s, err, len);
}

// Run each wanted rung that fits the budget, in config order.
static int run_ladder(study *s)
{
    const cal_fidelity *f = s->c->fidelity;
    double budget_s = 3600 * (isfinite(s->opt.budget_hours) ? s->opt.budget_hours : f->budget_hours), spent = 0;
    for (unsigned k = 0; k < f->rungs_count && s->n < MAX_RUNGS; ++k) {
        const cal_tier *rung = &f->rungs[k];
        if (!wanted(s->opt.rungs, rung->name)) continue;
        rung_result *r = &s->res[s->n++];
        memset(r, 0, sizeof *r);
        r->rung = rung, r->depth = rung->slice_depth > 0 ? rung->slice_depth : s->c->depth;
        r->predicted_s = NAN;
        const rung_result *base = NULL; // the largest rung measured so far
        for (int i = 0; i < s->n - 1; ++i)
            if (s->res[i].ran && (!base || s->res[i].particle_steps > base->particle_steps)) base = &s->res[i];
        if (base) r->predicted_s = predict_wall(base, rung, r->depth);
        if (base && r->predicted_s > budget_s - spent && !all_stored(s, rung)) {
            fprintf(stderr, "[fidelity] %s: not run, predicted %.3g h > %.3g h of budget left\n", rung->name,
                    r->predicted_s / 3600, (budget_s - spent) / 3600);
            continue;
        }
        cal_env_set_stage(&s->env, rung->name);
        cal_sim_release(&s->env); // each rung settles its own beds: its cost includes them
        fprintf(stderr, "[fidelity] %s: lambda %g, %s, %g s per speed, %d seed(s)%s\n", rung->name, rung->lambda,
                rung->slice_depth > 0 ? "periodic slice" : "full drum", rung->max_time, f->seeds,
                base ? "" : " (no prediction: first rung)");
        if (measure_rung(s, r)) return 1;
        spent += r->wall_s;
    }
    return 0;
}

int cal_cmd_study(int argc, char **argv)
{
    int asks_help = argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0);
    if (!asks_help && (argc < 2 || strcmp(argv[1], "fidelity") != 0)) {
        fprintf(stderr, "granucal study: the study to run is `fidelity`; see `granucal study --help`\n");
        return 2;
    }
    study *s = calloc(1, sizeof *s);
    if (!s) return fputs("granucal study: out of memory\n", stderr), 1;
    // `study --help` is the fidelity study's: the one study there is.
    int status = asks_help ? parse_options(argc, argv, &s->opt) : parse_options(argc - 1, argv + 1, &s->opt);
    if (status) return free(s), status < 0 ? 0 : status;
    char command[2048];
    cal_cli_begin(&argc, &argv, command, sizeof command);
    double t0 = exp_wall_seconds();
    s->c = cal_config_load(s->opt.config, NULL, s->err, sizeof s->err);
    if (s->c && !s->c->fidelity) status = exp_fail(s->err, sizeof s->err, "%s: has no `fidelity:` section", s->c->path);
    else if (!s->c) status = 1;
    if (!status && s->opt.seeds) s->c->fidelity->seeds = s->opt.seeds;
    if (!status && s->opt.rungs) status = check_rungs(s->c->fidelity, s->opt.rungs, s->c->path, s->err, sizeof s->err);
    if (!status && s->opt.rpm) status = narrow_speeds(s->c->fidelity, s->opt.rpm, s->c->path, s->err, sizeof s->err);
    if (!status && (s->opt.plan_only || (!s->opt.rungs && !s->opt.yes))) {
        print_plan(s);
        if (s->opt.plan_only) fputs("granucal study: --plan: the config checked, nothing was run\n", stderr);
        else
            status = 2, fputs("granucal study: no --rungs: the plan above is the whole ladder; run it with --yes, or choose "
                              "rungs with --rungs A,B (nothing was run)\n", stderr);
        if (s->c) cal_config_free(s->c);
        free(s);
        cal_mpi_finalize();
        return status;
    }
    if (!status) {
        snprintf(s->out, sizeof s->out, "%s", s->opt.out);
        snprintf(s->report, sizeof s->report, "%s", s->opt.report ? s->opt.report : s->opt.out);
        status = cal_prepare_output(s->out, s->err, sizeof s->err) || cal_mkdirs(s->report, s->err, sizeof s->err);
    }
    if (!status) {
        snprintf(s->env.store, sizeof s->env.store, "%s/store", s->out);
        s->env.workers = s->opt.jobs, s->env.use_fork = cal_mpi_size() == 1, s->env.tty = isatty(2);
        s->env.checkpoint_every_s = s->opt.checkpoint_every_s;
        s->env.started = t0;
        status = run_ladder(s);
    }
    if (!status && cal_mpi_rank() == 0) {
        errors_against_finest(s);
        status = write_csv(s, s->err, sizeof s->err) || write_markdown(s, command, exp_wall_seconds() - t0, s->err, sizeof s->err) ||
                 write_plots(s, s->err, sizeof s->err);
        if (!status) fprintf(stderr, "granucal study: wrote %s/fidelity.md and its CSV and plots\n", s->report);
    }
    status = cal_cli_end("study", status, s->err, &s->env, s->c);
    free(s);
    return status;
}
