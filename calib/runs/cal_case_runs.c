// SPDX-License-Identifier: MIT
// Calibration simulations through the result store (see cal_case_runs.h).
#include "cal_case_runs.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cal_files.h"
#include "cal_mpi.h"
#include "cal_pool.h"
#include "dem_checkpoint.h"
#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_drum_bed.h"
#include "exp_drum_turn.h"

// How this environment's drum runs are counted in the progress.
static cal_run_kind drum_kind(const cal_env *env) { return cal_progress_drum_kind(env->mapping); }

// The config's damping reading (its name was checked when the config was loaded).
static dem_damping_mode config_damping(const cal_config *c)
{
    dem_damping_mode mode = EXP_DAMPING_DEFAULT;
    char unused[160];
    exp_damping_from_name(c->damping, "damping", &mode, unused, sizeof unused);
    return mode;
}

static cal_drum_case drum_case(const cal_config *c, const cal_tier *t, double k_n, double gg_mu_s, double gg_mu_r,
                               double wall_mu_s, double wall_mu_r)
{
    // A tier with a slice depth runs a periodic slice of the config's drum.
    exp_drum_physics p = {.diameter = c->diameter, .periodic = t->slice_depth > 0, .depth = c->depth,
                          .slice_depth = t->slice_depth, .fill = c->fill, .lambda = t->lambda,
                          .gsd = c->gsd,
                          .density = c->density, .k_n = k_n, .xi = c->xi, .damping = config_damping(c),
                          .mu_s = gg_mu_s, .mu_r = gg_mu_r, .wall_mu_s = wall_mu_s, .wall_mu_r = wall_mu_r,
                          .fill_method = exp_default_drum_def().fill_method, .seed = (uint64_t)c->seed};
    if (t->fill_method) exp_drum_fill_method_from_name(t->fill_method, &p.fill_method); // checked on loading
    cal_drum_case d = {0};
    d.def = exp_drum_def_from_physics(&p);
    d.run = exp_default_drum_run_opts();
    d.run.average_time = t->average_time;
    d.n_average = 0; // each of the tier's speeds with its own averaging time, if it gives them
    for (unsigned k = 0; k < t->rpm_count && k < CAL_CASE_MAX_RPM && t->average_time_per_rpm_count; ++k)
        d.average_rpm[d.n_average] = t->rpm[k], d.average_time[d.n_average++] = cal_tier_average_time(t, t->rpm[k]);
    d.run.max_time = t->max_time, d.run.window = t->window;
    if (t->sample_interval > 0) d.run.sample_interval = t->sample_interval;
    if (t->steady_angle_tol_deg > 0) d.run.angle_tol_deg = t->steady_angle_tol_deg;
    if (t->steady_csa_tol_percent > 0) d.run.csa_tol_percent = t->steady_csa_tol_percent;
    if (t->steady_rule) exp_drum_steady_rule_from_name(t->steady_rule, &d.run.steady_rule); // checked on loading
    d.run.se_angle_deg = t->steady_se_angle_deg, d.run.se_csa_percent = t->steady_se_csa_percent;
    for (unsigned k = 0; k < t->turned_start_rpm_count && k < CAL_CASE_MAX_RPM; ++k)
        d.turned_rpm[d.n_turned++] = t->turned_start_rpm[k];
    d.turned_time = t->turned_start_time;
    d.fill = d.start = d.def;
    return d;
}

void cal_drum_case_set_seed(cal_drum_case *d, uint64_t seed) { d->def.seed = d->fill.seed = d->start.seed = seed; }

int cal_drum_case_turned(const cal_drum_case *c, double rpm)
{
    for (int k = 0; k < c->n_turned; ++k)
        if (c->turned_rpm[k] == rpm) return 1;
    return 0;
}

cal_drum_case cal_drum_case_granule(const cal_config *c, const cal_tier *t, double k_n, double mu_s, double mu_r)
{
    cal_drum_case d = drum_case(c, t, k_n, mu_s, mu_r, mu_s, mu_r);
    d.start = drum_case(c, t, k_n, c->pour_mu_s, c->pour_mu_r, c->pour_mu_s, c->pour_mu_r).def;
    return d;
}

cal_drum_case cal_drum_case_wall(const cal_config *c, const cal_tier *t, double k_n, double gg_mu_s, double gg_mu_r,
                                 double wall_mu_s, double wall_mu_r)
{
    cal_drum_case d = drum_case(c, t, k_n, gg_mu_s, gg_mu_r, wall_mu_s, wall_mu_r);
    d.fill = d.start = drum_case(c, t, k_n, gg_mu_s, gg_mu_r, gg_mu_s, gg_mu_r).def;
    return d;
}

exp_cylinder_def cal_cylinder_case_make(const cal_config *c, const cal_tier *t, double k_n, uint64_t seed)
{
    exp_cylinder_def d = exp_default_cylinder_def();
    d.lambda = t->cylinder_lambda, d.density = c->density, d.seed = seed;
    d.gsd = c->gsd;
    // Stage 1 comes before the friction is known: the pour uses the config's
    // stated prior friction (pour_mu_s, pour_mu_r). The stage reads how the
    // coordination number moves with k, not its level.
    d.granule = exp_granule_pair(k_n, c->xi, c->pour_mu_s, c->pour_mu_r, config_damping(c));
    d.wall = d.granule; // exp_cylinder gives it Table 3's boundary stiffness
    return d;
}

cal_bed_case cal_bed_case_make(const cal_config *c, const cal_tier *t, double k_n, uint64_t seed)
{
    cal_bed_case b = {.on_drum = cal_tier_stiffness_on_drum(t)};
    b.cylinder = cal_cylinder_case_make(c, t, k_n, seed);
    // The drum lined with granules at the pour's prior friction, as the cylinder is.
    b.drum_bed = drum_case(c, t, k_n, c->pour_mu_s, c->pour_mu_r, c->pour_mu_s, c->pour_mu_r).fill;
    b.drum_bed.seed = seed;
    return b;
}

static void contact_text(char *out, size_t len, const dem_contact_params *p)
{
    snprintf(out, len, "k=%.10g,%.10g,%.10g xi=%.10g mu=%.10g,%.10g damping=%d", p->k_n, p->k_s, p->k_r, p->xi,
             p->mu_s, p->mu_r, (int)p->damping);
}

// A measured size table is named by its fingerprint, only when there is one,
// so that every log-normal run keeps its key.
static void gsd_table_text(const dem_gsd *g, char *out, size_t len)
{
    if (g->table.rows)
        snprintf(out + strlen(out), len - strlen(out), " gsd_table=%d:%016llx", g->table.rows,
                 (unsigned long long)dem_gsd_table_fingerprint(g));
}

static void drum_def_text(const exp_drum_def *d, char *out, size_t len)
{
    char gg[160], wall[160], plate[160];
    contact_text(gg, sizeof gg, &d->granule), contact_text(wall, sizeof wall, &d->wall);
    contact_text(plate, sizeof plate, &d->end_plate);
    snprintf(out, len,
             "drum v=%s D=%.10g depth=%.10g periodic=%d fill=%.10g lambda=%.10g rho=%.10g gsd=%.10g,%.10g,%.10g "
             "granule[%s] wall[%s] plate[%s] pixel=%.10g closing=%d seed=%llu",
             exp_results_version(), d->diameter, d->depth, d->periodic, d->fill, d->lambda, d->density, d->gsd.median_diameter,
             d->gsd.geometric_sd, d->gsd.truncation_sigmas, gg, wall, d->periodic ? "none" : plate, d->pixel,
             d->closing_px, (unsigned long long)d->seed);
    // Named only when not the pour, so that the stores of every pour run keep their keys.
    if (d->fill_method != EXP_FILL_POUR)
        snprintf(out + strlen(out), len - strlen(out), " fill_method=%s", exp_drum_fill_method_name(d->fill_method));
    gsd_table_text(&d->gsd, out, len);
}

exp_drum_run_opts cal_drum_run_opts(const cal_drum_case *c, double rpm)
{
    exp_drum_run_opts run = c->run;
    run.rpm = rpm;
    for (int k = 0; k < c->n_average; ++k)
        if (c->average_rpm[k] == rpm) run.average_time = c->average_time[k];
    if (cal_drum_case_turned(c, rpm)) { // from the turned bed: no tilt; MSER cuts the change of pair
        run.start_tilt_deg = 0, run.average_time = 0;
        run.steady_rule = EXP_STEADY_MSER;
    }
    return run;
}

// How that bed is turned first: the tier's run at `rpm`, for turned_time s,
// from the level bed with the tier's start tilt, every sample kept as the
// window (the windows' test cannot hold: nothing is averaged or stopped early).
static exp_drum_run_opts start_turn_opts(const cal_drum_case *c, double rpm)
{
    exp_drum_run_opts o = c->run;
    o.rpm = rpm, o.max_time = o.window = c->turned_time, o.average_time = 0;
    o.steady_rule = EXP_STEADY_WINDOWS;
    return o;
}

// The text that defines a turned bed: its drum and pairs, and its turn.
static void start_bed_key(const cal_drum_case *c, double rpm, char *out, size_t len)
{
    const exp_drum_run_opts o = start_turn_opts(c, rpm);
    char def[1024];
    drum_def_text(&c->start, def, sizeof def);
    snprintf(out, len, "turned_bed %s rpm=%.10g time=%.10g sample=%.10g network_dt=%d start_tilt=%.10g", def, rpm,
             o.max_time, o.sample_interval, o.adopt_network_dt, o.start_tilt_deg);
}

void cal_drum_key(const cal_drum_case *c, double rpm, char *out, size_t len)
{
    const exp_drum_run_opts run = cal_drum_run_opts(c, rpm), *r = &run;
    char def[1024], turn_wall[160], fill_wall[160], turn_plate[160], fill_plate[160];
    drum_def_text(&c->def, def, sizeof def);
    // Only the fill's wall pair may differ from the turn's (cal_drum_case_wall).
    contact_text(turn_wall, sizeof turn_wall, &c->def.wall), contact_text(fill_wall, sizeof fill_wall, &c->fill.wall);
    contact_text(turn_plate, sizeof turn_plate, &c->def.end_plate);
    contact_text(fill_plate, sizeof fill_plate, &c->fill.end_plate);
    if (strcmp(turn_wall, fill_wall) == 0) snprintf(fill_wall, sizeof fill_wall, "same");
    if (strcmp(turn_plate, fill_plate) == 0) snprintf(fill_plate, sizeof fill_plate, "same");
    snprintf(out, len,
             "%s filled_with_wall[%s] filled_with_plate[%s] rpm=%.10g max_time=%.10g sample=%.10g window=%.10g "
             "tol=%.10g,%.10g network_dt=%d start_tilt=%.10g",
             def, fill_wall, c->def.periodic ? "none" : fill_plate, rpm, r->max_time, r->sample_interval, r->window,
             r->angle_tol_deg, r->csa_tol_percent, r->adopt_network_dt, r->start_tilt_deg);
    // Named only when set, so that every record stored before it keeps its key.
    if (r->average_time > 0) snprintf(out + strlen(out), len - strlen(out), " average_time=%.10g", r->average_time);
    if (r->steady_rule == EXP_STEADY_MSER)
        snprintf(out + strlen(out), len - strlen(out), " steady=mser se=%.10g,%.10g", r->se_angle_deg, r->se_csa_percent);
    if (cal_drum_case_turned(c, rpm)) {
        char granule[160], wall[160];
        contact_text(granule, sizeof granule, &c->start.granule), contact_text(wall, sizeof wall, &c->start.wall);
        snprintf(out + strlen(out), len - strlen(out), " start=turned[time=%.10g tilt=%.10g granule[%s] wall[%s]]",
                 c->turned_time, c->run.start_tilt_deg, granule, wall);
    }
}

// Each value of `field` in text (up to the next space or ']') replaced by '*'.
static void mask_values(char *text, const char *field)
{
    const size_t n = strlen(field);
    for (char *at = strstr(text, field); at; at = strstr(at, field)) {
        char *value = at + n, *end = value + strcspn(value, " ]");
        if (end > value) *value = '*', memmove(value + 1, end, strlen(end) + 1);
        at = value + 1;
    }
}

void cal_drum_key_kind(const char *key, int any_scale, char *out, size_t len)
{
    snprintf(out, len, "%s", key);
    mask_values(out, " mu="), mask_values(out, " seed=");
    if (any_scale) mask_values(out, " lambda="), mask_values(out, " depth="), mask_values(out, "[k=");
}

void cal_cylinder_key(const exp_cylinder_def *c, char *out, size_t len)
{
    char gg[160], wall[160];
    contact_text(gg, sizeof gg, &c->granule), contact_text(wall, sizeof wall, &c->wall);
    snprintf(out, len, "cylinder v=%s D=%.10g depth=%.10g lambda=%.10g rho=%.10g gsd=%.10g,%.10g,%.10g granule[%s] "
                       "wall[%s] seed=%llu",
             exp_results_version(), c->diameter, c->depth, c->lambda, c->density, c->gsd.median_diameter, c->gsd.geometric_sd,
             c->gsd.truncation_sigmas, gg, wall, (unsigned long long)c->seed);
    gsd_table_text(&c->gsd, out, len);
}

void cal_bed_key(const cal_bed_case *b, char *out, size_t len)
{
    if (!b->on_drum) {
        cal_cylinder_key(&b->cylinder, out, len);
        return;
    }
    char def[1024];
    drum_def_text(&b->drum_bed, def, sizeof def);
    snprintf(out, len, "drum_bed %s", def);
}

double cal_bed_predict_particle_steps(const cal_bed_case *b, double *memory_mb)
{
    if (b->on_drum) {
        exp_drum_cost c = exp_drum_predict_cost(&b->drum_bed, 0);
        return *memory_mb = c.memory_mb, c.fill_particle_steps;
    }
    exp_cylinder_cost c = exp_cylinder_predict_cost(&b->cylinder);
    return *memory_mb = c.memory_mb, c.particle_steps;
}

// "[stage] what: status (reason), angle ..., CSA ... — T s simulated in W s; ENDING"
static void show_record(const cal_env *env, const char *what, const cal_record *r, const char *ending)
{
    if (env->tty) fputs("\r\033[K", stderr);
    fprintf(stderr, "[%s] %s: %s", env->stage, what, r->status);
    if (r->reason && r->reason[0]) fprintf(stderr, " (%s)", r->reason);
    if (r->granules && (strncmp(what, "cylinder", 8) == 0 || strncmp(what, "drum bed", 8) == 0))
        fprintf(stderr, ", CN %.3f, %d granules", r->coordination, r->granules);
    else if (r->granules)
        fprintf(stderr, ", angle %.1f° ± %.1f, CSA %.1f %% ± %.1f", r->angle_deg, r->angle_sd_deg, r->csa_percent,
                r->csa_sd_percent);
    fprintf(stderr, " — %.2f s simulated in %.0f s; %s\n", r->simulated_time_s, r->wall_time_s, ending);
}

// A run done, with the whole calibration's progress.
static void show_done(const cal_env *env, const char *what, const cal_record *r)
{
    char progress[160], ending[200];
    cal_progress_describe(env->progress, progress, sizeof progress);
    snprintf(ending, sizeof ending, "%.0f s elapsed%s%s", exp_wall_seconds() - env->started, progress[0] ? "; " : "",
             progress);
    show_record(env, what, r, ending);
}

// A record every rank must find once a batch is done.
static int read_back(const cal_env *env, const char *key, cal_record *out, char *err, size_t len)
{
    int got = cal_store_get(env->store, key, out, err, len);
    if (got == 1) exp_fail(err, len, "no record in %s after running '%s'", env->store, key);
    return got != 0;
}

// ---- drum -----------------------------------------------------------------

/// One drum run: a candidate (index into the batch's cases) at one speed.
typedef struct drum_run {
    int c, k;
} drum_run;

// The missing runs of several candidates. When they all settle the same bed
// (the wall stage's candidates, or one candidate) it is settled once, here,
// and each run is a task: its speeds turn side by side. Otherwise (the
// granule stage's candidates each settle their own bed) each candidate is a
// task that settles its bed and turns its speeds in turn, so that one
// candidate's settling overlaps another's turning instead of leaving the
// other workers idle.
typedef struct drum_batch {
    cal_env *env;
    const cal_drum_case *cases;
    int n_cases;
    const double *rpm;
    int n_rpm;
    char (*keys)[2048];    ///< [c * n_rpm + k]
    drum_run *todo;        ///< this rank's missing runs
    int n_todo;
    int *case_todo;        ///< own-bed tasks: this rank's candidates with missing runs
    int n_case_todo;
    dem_world *bed;        ///< the shared bed (shared_fill)
    double bed_wall_s;
    // Runs from a level bed: todo[0..n_level_todo), as n_level_tasks tasks
    // of level_task (a run each on the shared bed, or a candidate each).
    int n_level_todo, n_level_tasks;
    cal_task_fn level_task;
    cal_done_fn level_done;
    // Runs from turned beds (run_turned): todo[turned_from..n_todo), each
    // with its bed and the bed's cost charged to it; the beds made side by
    // side first (prep, their hashes prepped).
    int turned_from;
    int n_turned_tasks;
    dem_world **turned_bed;
    double *turned_charge;
    drum_run *prep;
    char (*prepped)[17];
    int n_prep;
} drum_batch;

static const char *run_key(const drum_batch *b, drum_run r) { return b->keys[r.c * b->n_rpm + r.k]; }

static int write_failed_record(const cal_env *env, const char *key, const char *reason, int retry)
{
    char err[512];
    cal_record r = {.key = (char *)key, .status = "failed", .reason = (char *)reason, .retry = retry};
    if (cal_store_put(env->store, &r, err, sizeof err)) return fprintf(stderr, "granucal calibrate: %s\n", err), 1;
    return 0;
}

static int write_failed(const cal_env *env, const char *key, const char *reason)
{
    return write_failed_record(env, key, reason, 0);
}

// Killed from outside (a user, the OOM killer, a kill of the whole run), as
// opposed to a crash of the simulation itself (SIGSEGV, SIGABRT, SIGFPE, ...).
static int killed_from_outside(int sig)
{
    return sig == SIGKILL || sig == SIGTERM || sig == SIGINT || sig == SIGHUP || sig == SIGQUIT;
}

// A drum run's checkpoint: beside its record, named by the same hash.
static void checkpoint_path(const cal_env *env, const char *key, char *out, size_t len)
{
    char hash[17];
    cal_store_hash(key, hash);
    snprintf(out, len, "%s/%s.turn.h5", env->store, hash);
}

// A line now and then from a simulation still running (a fine drum's fill
// or turn takes up to an hour), so a log shows it is alive and how far it is:
// "[PP] 4 rpm, seed 2: turn t = 3.2 s, 2827 granules, wall 600 s".
enum { HEARTBEAT_EVERY_S = 600 };
typedef struct heartbeat {
    char label[160]; ///< "[stage] what": a stage name is < 64, what < 64
    exp_progress_printer printer; ///< prints label; keep the heartbeat where it was started
} heartbeat;

// A simulation's progress: cores the pool has granted since it started are
// taken here, between two samples (cal_pool.h), then the heartbeat.
static void run_progress(const char *phase, double t, size_t granules, void *printer)
{
    int now = cal_pool_take_granted_cores();
    if (now)
        fprintf(stderr, "%s: %s t = %.4f s: on %d threads from here (the batch's other runs have ended)\n",
                ((const exp_progress_printer *)printer)->scene, phase, t, now);
    exp_print_progress(phase, t, granules, printer);
}

static void heartbeat_start(heartbeat *h, const char *stage, const char *what)
{
    snprintf(h->label, sizeof h->label, "[%s] %s", stage, what);
    double now = exp_wall_seconds();
    h->printer = (exp_progress_printer){h->label, now, now, HEARTBEAT_EVERY_S};
}

static void heartbeat_of_bed(heartbeat *h, const char *stage, const exp_drum_def *fill)
{
    char what[48];
    snprintf(what, sizeof what, "the bed of seed %llu", (unsigned long long)fill->seed);
    heartbeat_start(h, stage, what);
}

// A bed of `fill` poured and settled, with a heartbeat in the log; *wall_s:
// what it took. NULL with a message if the fill failed.
static dem_world *pour_bed(const cal_env *env, const exp_drum_def *fill, double *wall_s, char *err, size_t len)
{
    double t0 = exp_wall_seconds();
    heartbeat h;
    heartbeat_of_bed(&h, env->stage, fill);
    dem_world *bed = exp_drum_fill(fill, run_progress, &h.printer, err, len);
    *wall_s = exp_wall_seconds() - t0;
    return bed;
}

// A run stored by a task that goes on turning the same bed at other speeds:
// said at once, since the task's own line (with the progress) comes only when
// the bed's last speed is done.
static void announce_stored(const cal_env *env, const char *what, const cal_record *r, int speeds_left)
{
    char ending[64];
    snprintf(ending, sizeof ending, "stored, %d more speed(s) on this bed", speeds_left);
    show_record(env, what, r, ending);
}

// Turn `bed` at run r's speed and store the record; fill_s: the settling's
// wall time, charged to this run. The bed itself is turned only when it is
// this run's alone (a forked child's copy, own = 1); else a clone.
// speeds_left > 0: the caller turns this bed at that many more speeds (the
// run is announced when stored).
static int turn_and_store(drum_batch *b, dem_world *bed, drum_run r, double fill_s, int own, int speeds_left)
{
    const cal_drum_case *c = &b->cases[r.c];
    const char *key = run_key(b, r);
    char ck_path[1300], what[48], prefix[80];
    checkpoint_path(b->env, key, ck_path, sizeof ck_path);
    exp_drum_turn turn = {.def = &c->def, .run = cal_drum_run_opts(c, b->rpm[r.k]), .checkpoint_path = ck_path,
                          .key = key, .checkpoint_every_s = b->env->checkpoint_every_s,
                          .progress = run_progress, .log_prefix = prefix};
    snprintf(prefix, sizeof prefix, "[%s]", b->env->stage);
    snprintf(what, sizeof what, "%g rpm, seed %llu", turn.run.rpm, (unsigned long long)c->def.seed);
    heartbeat h;
    heartbeat_start(&h, b->env->stage, what);
    turn.progress_ctx = &h.printer;
    exp_drum_result res;
    dem_status st;
    dem_world *w = exp_drum_turn_bed(bed, own, &turn, &res, &st);
    if (!w) return write_failed(b->env, key, "out of memory copying the settled bed"), 1;
    cal_record rec = {.key = (char *)key, .reason = ""};
    rec.status = st != DEM_OK ? "failed" : res.steady ? "ok" : "not steady";
    if (st != DEM_OK) rec.reason = (char *)dem_world_error(w);
    rec.angle_deg = res.angle_deg, rec.angle_sd_deg = res.angle_sd_deg;
    rec.csa_percent = res.csa_percent, rec.csa_sd_percent = res.csa_sd_percent;
    rec.steady = res.steady, rec.simulated_time_s = res.simulated_time_s;
    rec.wall_time_s = res.wall_time_s;
    rec.fill_wall_time_s = fill_s;
    rec.peak_rss_mb = exp_peak_rss_mb();
    rec.dt_s = dem_world_dt(w), rec.particle_steps = (double)res.particle_steps, rec.granules = (int)res.granules;
    rec.dt_margin_min = res.dt_margin_min, rec.dt_lowered = res.dt_lowered;
    char err[512];
    int bad = cal_store_put(b->env->store, &rec, err, sizeof err);
    if (bad) fprintf(stderr, "granucal calibrate: %s\n", err);
    else dem_checkpoint_remove(ck_path); // the record holds the result now
    if (!bad && speeds_left > 0) announce_stored(b->env, what, &rec, speeds_left);
    if (!own) dem_world_destroy(w);
    return bad;
}

// Shared bed: task i is run todo[i]; a bed settled now is charged once, to the first.
static int turn_one(int i, void *ctx)
{
    drum_batch *b = ctx;
    return turn_and_store(b, b->bed, b->todo[i], i == 0 ? b->bed_wall_s : 0, b->env->use_fork, 0);
}

// Own bed: task i settles candidate case_todo[i]'s bed and turns a copy of it
// at each of its missing speeds.
static int settle_and_turn(int i, void *ctx)
{
    drum_batch *b = ctx;
    int c = b->case_todo[i], bad = 0;
    char err[1024];
    double fill_s;
    dem_world *bed = pour_bed(b->env, &b->cases[c].fill, &fill_s, err, sizeof err);
    int left = 0;
    for (int j = 0; j < b->n_level_todo; ++j) left += b->todo[j].c == c;
    for (int j = 0; j < b->n_level_todo; ++j) {
        if (b->todo[j].c != c) continue;
        --left;
        if (!bed) bad |= write_failed(b->env, run_key(b, b->todo[j]), err);
        else bad |= turn_and_store(b, bed, b->todo[j], fill_s, 0, left), fill_s = 0;
    }
    dem_world_destroy(bed);
    return bad;
}

// A run ended: a process killed by a signal wrote nothing, so record it as
// failed (unless its record was stored before); then count it and show what it holds.
static void finish_run(cal_env *env, cal_run_kind kind, const char *key, const char *what, int code)
{
    char err[512];
    cal_record r;
    int got = cal_store_get(env->store, key, &r, err, sizeof err);
    if (got == 0) cal_record_free(&r);
    if (code < 0 && got != 0) {
        char reason[96];
        int outside = killed_from_outside(-code);
        snprintf(reason, sizeof reason, "the simulation process died (signal %d%s)", -code,
                 outside ? ", killed from outside: a later run retries it" : "");
        write_failed_record(env, key, reason, outside);
    }
    if (cal_store_get(env->store, key, &r, err, sizeof err) == 0) {
        cal_progress_count(env->progress, kind, cal_record_cost_s(&r));
        show_done(env, what, &r);
        cal_record_free(&r);
    } else cal_progress_count(env->progress, kind, NAN);
    env->simulations_run++;
}

static void show_run(drum_batch *b, drum_run r, int code, int n_cases)
{
    char what[96];
    const dem_contact_params *p = &b->cases[r.c].def.wall; // the granule stage's wall pair is its granule pair
    if (n_cases > 1) // candidates differ by pair, beds by seed
        snprintf(what, sizeof what, "mu_s = %.4g, mu_r = %.4g, %g rpm, seed %llu", p->mu_s, p->mu_r, b->rpm[r.k],
                 (unsigned long long)b->cases[r.c].def.seed);
    else snprintf(what, sizeof what, "%g rpm", b->rpm[r.k]);
    finish_run(b->env, drum_kind(b->env), run_key(b, r), what, code);
}

static void turned(int i, int code, void *ctx)
{
    drum_batch *b = ctx;
    show_run(b, b->todo[i], code, b->n_cases);
}

static void settled_and_turned(int i, int code, void *ctx)
{
    drum_batch *b = ctx;
    for (int j = 0; j < b->n_level_todo; ++j)
        if (b->todo[j].c == b->case_todo[i]) show_run(b, b->todo[j], code, b->n_cases);
}

void cal_env_set_stage(cal_env *env, const char *stage)
{
    cal_progress_level_name(stage, env->mapping, env->stage, sizeof env->stage);
}


// The level bed kept between candidates, let go (the turned beds stay).
static void release_kept_bed(cal_env *env)
{
    dem_world_destroy(env->kept_bed);
    env->kept_bed = NULL;
    env->kept_text[0] = 0;
}

void cal_sim_release(cal_env *env)
{
    release_kept_bed(env);
    for (int k = 0; k < env->n_turned; ++k) dem_world_destroy(env->turned[k].bed);
    free(env->turned);
    env->turned = NULL, env->n_turned = 0;
}

// ---- turned starts (cal_drum_case.n_turned) ---------------------------------

// A turned bed's hash (its store name) and file: it is a checkpoint of its
// own turn, kept when the turn ends (exp_drum_turn.checkpoint_at_end).
static void turned_bed_hash(const cal_drum_case *c, double rpm, char *key, size_t len, char hash[17])
{
    start_bed_key(c, rpm, key, len);
    cal_store_hash(key, hash);
}

static void turned_bed_path(const cal_env *env, const char *hash, char *out, size_t len)
{
    snprintf(out, len, "%s/%s.start.h5", env->store, hash);
}

// Case c's start bed poured and turned at `rpm`, resumed from (and saved to)
// its file in the store: once turned, a later process pours it again (a
// pour's cost) and takes the turn from the file. NULL with a message if it
// failed. *fill_s: the pour's wall time; res->wall_time_s the turn's, with
// what came before its file (res->earlier_wall_s).
// The turned bed's file read into an empty drum, or NULL (none, or one that
// cannot be read: the bed is then poured). The turn that follows reads the
// file again and goes on from it: a bed poured only to be overwritten by the
// file cost a pour (~4 min of one core at lambda 1000) each time a resumed
// calibration took a bed an earlier process had made.
static dem_world *turned_bed_from_file(const cal_drum_case *c, const char *path, const char *key)
{
    char err[512];
    if (access(path, F_OK) != 0) return NULL;
    dem_world *w = exp_drum_create_empty(&c->start, err, sizeof err);
    if (w && dem_checkpoint_read(w, path, key, NULL, 0, err, sizeof err) == 0) return w;
    dem_world_destroy(w);
    return NULL;
}

// from_file: a file an earlier process made may stand in for the pour (its
// cost was charged there). A file a worker of this process made is read after
// a pour as before: the pour is then charged here, in place of the worker's,
// which the file does not hold.
static dem_world *make_turned_bed(const cal_env *env, const cal_drum_case *c, double rpm, int from_file, double *fill_s,
                                  exp_drum_result *res, char *err, size_t len)
{
    char key[2048], hash[17], path[1300], what[64], prefix[80];
    turned_bed_hash(c, rpm, key, sizeof key, hash);
    turned_bed_path(env, hash, path, sizeof path);
    *fill_s = 0;
    dem_world *bed = from_file ? turned_bed_from_file(c, path, key) : NULL;
    if (!bed) bed = pour_bed(env, &c->start, fill_s, err, len);
    if (!bed) return NULL;
    snprintf(what, sizeof what, "the turned bed of seed %llu, %g rpm", (unsigned long long)c->start.seed, rpm);
    snprintf(prefix, sizeof prefix, "[%s]", env->stage);
    heartbeat h;
    heartbeat_start(&h, env->stage, what);
    exp_drum_turn turn = {.def = &c->start, .run = start_turn_opts(c, rpm), .checkpoint_path = path, .key = key,
                          .checkpoint_every_s = env->checkpoint_every_s, .checkpoint_at_end = 1,
                          .progress = run_progress, .progress_ctx = &h.printer, .log_prefix = prefix};
    dem_status st;
    exp_drum_turn_bed(bed, 1, &turn, res, &st);
    if (st == DEM_OK) return bed;
    exp_fail(err, len, "%s (%g s at %g rpm) failed: %s", what, c->turned_time, rpm, dem_world_error(bed));
    dem_world_destroy(bed);
    return NULL;
}

static struct cal_turned_bed *kept_turned(cal_env *env, const char *hash)
{
    for (int k = 0; k < env->n_turned; ++k)
        if (strcmp(env->turned[k].hash, hash) == 0) return &env->turned[k];
    return NULL;
}

// Keep a turned bed for the rest of the process (a stage's beds are its seeds: a few).
static struct cal_turned_bed *keep_turned(cal_env *env, dem_world *bed, const char *hash, double wall_s)
{
    struct cal_turned_bed *more = realloc(env->turned, (size_t)(env->n_turned + 1) * sizeof *more);
    if (!more) return NULL;
    env->turned = more;
    struct cal_turned_bed *t = &env->turned[env->n_turned++];
    t->bed = bed, t->wall_s = wall_s;
    snprintf(t->hash, sizeof t->hash, "%s", hash);
    return t;
}

// The settled bed of this fill definition: the kept one, or a new one (whose
// wall time is then charged to the speeds turned now). NULL and a message
// when the fill failed.
static dem_world *settled_bed(cal_env *env, const exp_drum_def *fill, double *wall_s, char *err, size_t len)
{
    char text[1024];
    drum_def_text(fill, text, sizeof text);
    *wall_s = 0;
    if (env->kept_bed && strcmp(text, env->kept_text) == 0) return env->kept_bed;
    release_kept_bed(env);
    env->kept_bed = pour_bed(env, fill, wall_s, err, len);
    if (env->kept_bed) snprintf(env->kept_text, sizeof env->kept_text, "%s", text);
    return env->kept_bed;
}

// 1 if every missing run (all ranks') settles the same bed.
static int one_fill(const drum_batch *b, const drum_run *missing, int n_missing)
{
    char first[1024], text[1024];
    for (int i = 0; i < n_missing; ++i) {
        drum_def_text(&b->cases[missing[i].c].fill, i ? text : first, sizeof text);
        if (i && strcmp(text, first) != 0) return 0;
    }
    return 1;
}

// Pool task: make one turned bed into its file in the store; the parent
// then takes it from there (a pour and the file).
static int prepare_turned(int i, void *ctx)
{
    drum_batch *b = ctx;
    const drum_run r = b->prep[i];
    double fill_s;
    exp_drum_result res;
    char err[1024];
    dem_world *bed = make_turned_bed(b->env, &b->cases[r.c], b->rpm[r.k], 0, &fill_s, &res, err, sizeof err);
    if (!bed) return fprintf(stderr, "[%s] %s\n", b->env->stage, err), 1;
    dem_world_destroy(bed);
    return 0;
}

static void prepared(int i, int code, void *ctx) { (void)i, (void)code, (void)ctx; }

static int listed_hash(char (*hashes)[17], int n, const char *hash)
{
    for (int k = 0; k < n; ++k)
        if (strcmp(hashes[k], hash) == 0) return 1;
    return 0;
}

// The turned beds of runs[0..n) that this process does not keep and the
// store has no file of, made side by side when there are several (by rank
// 0: every rank then takes them from the store). Their hashes in
// b->prepped: made now, so their whole turn is this process's cost (rank
// 0's: another rank charges only its own pour of such a bed).
static void prepare_turned_beds(drum_batch *b, const drum_run *runs, int n)
{
    b->prep = calloc((size_t)n, sizeof *b->prep);
    char(*todo)[17] = calloc((size_t)n, sizeof *todo);
    b->prepped = todo;
    for (int i = 0; i < n && b->prep && todo && cal_mpi_rank() == 0; ++i) {
        char key[2048], hash[17], path[1300];
        turned_bed_hash(&b->cases[runs[i].c], b->rpm[runs[i].k], key, sizeof key, hash);
        turned_bed_path(b->env, hash, path, sizeof path);
        if (kept_turned(b->env, hash) || access(path, F_OK) == 0 || listed_hash(todo, b->n_prep, hash)) continue;
        snprintf(todo[b->n_prep], sizeof todo[0], "%s", hash);
        b->prep[b->n_prep++] = runs[i];
    }
    // One bed alone is made by the process that keeps it (turned_bed_of), without a second pour;
    // so is every bed where no file is kept (--checkpoint-every 0).
    if (b->n_prep > 1 && b->env->checkpoint_every_s > 0)
        cal_pool_run(b->n_prep, prepare_turned, prepared, b, b->env->workers, b->env->use_fork);
    else b->n_prep = 0;
    cal_mpi_barrier(); // the files are on the shared store now
}

// Run i of this rank's share from its turned bed: a task turning a copy of it.
static int turn_from_turned(int i, void *ctx)
{
    drum_batch *b = ctx;
    if (!b->turned_bed[i]) return 1; // its bed failed: recorded as failed
    return turn_and_store(b, b->turned_bed[i], b->todo[b->turned_from + i], b->turned_charge[i], b->env->use_fork, 0);
}

static void turned_from_turned(int i, int code, void *ctx)
{
    drum_batch *b = ctx;
    show_run(b, b->todo[b->turned_from + i], code, b->n_cases);
}

// The turned bed of run r, kept or made now (NULL: it failed; the run is
// recorded failed). *charge: its cost to this process, charged once.
static dem_world *turned_bed_of(drum_batch *b, drum_run r, double *charge)
{
    cal_env *env = b->env;
    char key[2048], hash[17], err[1024];
    turned_bed_hash(&b->cases[r.c], b->rpm[r.k], key, sizeof key, hash);
    struct cal_turned_bed *t = kept_turned(env, hash);
    if (!t) {
        double fill_s;
        exp_drum_result res;
        // On the parent's one thread, though no worker runs now: a parent that has run an OpenMP
        // region on more threads forks workers that can hang. libgomp keeps that team's threads in a
        // pool, a child inherits the pool but not its threads, and its first smaller region waits for
        // them to be released (the standard rerun's worker sat 20 min in a futex at 0 CPU, 2026-11-28,
        // acc31a7, reverted). A bed wanting more threads is made in a forked worker (prepare_turned).
        const int made_now = listed_hash(b->prepped, b->n_prep, hash); // by a worker of this batch
        dem_world *bed = make_turned_bed(env, &b->cases[r.c], b->rpm[r.k], !made_now, &fill_s, &res, err, sizeof err);
        if (!bed) return write_failed(env, run_key(b, r), err), NULL;
        // A file made by an earlier process was charged there; one made now by a worker, here.
        double turn_s = res.wall_time_s - (made_now ? 0 : res.earlier_wall_s);
        t = keep_turned(env, bed, hash, fill_s + turn_s);
        if (!t) return dem_world_destroy(bed), write_failed(env, run_key(b, r), "out of memory keeping the turned bed"), NULL;
    }
    *charge = t->wall_s, t->wall_s = 0;
    return t->bed;
}

// The runs that start from a turned bed: the beds first (kept, from the
// store, or made now), then this rank's share of the runs as tasks.
static void deal_turned(drum_batch *b, const drum_run *runs, int n)
{
    prepare_turned_beds(b, runs, n);
    int rank = cal_mpi_rank(), size = cal_mpi_size();
    b->turned_from = b->n_todo;
    for (int i = 0; i < n; ++i)
        if (i % size == rank) b->todo[b->n_todo++] = runs[i];
    int m = b->n_todo - b->turned_from;
    b->turned_bed = calloc((size_t)m + 1, sizeof *b->turned_bed);
    b->turned_charge = calloc((size_t)m + 1, sizeof *b->turned_charge);
    if (!b->turned_bed || !b->turned_charge) {
        for (int j = 0; j < m; ++j) write_failed(b->env, run_key(b, b->todo[b->turned_from + j]), "out of memory");
        return;
    }
    for (int j = 0; j < m; ++j) b->turned_bed[j] = turned_bed_of(b, b->todo[b->turned_from + j], &b->turned_charge[j]);
    b->n_turned_tasks = m;
}

// The runs from a level bed: dealt over the ranks; this rank's share as
// tasks, on one bed settled here (every run the same fill) or a candidate each.
static void deal_level(drum_batch *b, const drum_run *missing, int n_missing)
{
    int rank = cal_mpi_rank(), size = cal_mpi_size();
    if (one_fill(b, missing, n_missing)) { // runs dealt one by one
        for (int i = 0; i < n_missing; ++i)
            if (i % size == rank) b->todo[b->n_todo++] = missing[i];
        b->n_level_todo = b->n_todo;
        if (b->n_todo == 0) return;
        char err[1024];
        b->bed = settled_bed(b->env, &b->cases[b->todo[0].c].fill, &b->bed_wall_s, err, sizeof err);
        if (!b->bed) {
            for (int i = 0; i < b->n_todo; ++i) write_failed(b->env, run_key(b, b->todo[i]), err);
            return;
        }
        b->level_task = turn_one, b->level_done = turned, b->n_level_tasks = b->n_todo;
        return;
    }
    int n_with = 0; // candidates dealt whole: each settles its own bed
    for (int i = 0; i < n_missing; ++i) {
        int first_of_case = i == 0 || missing[i].c != missing[i - 1].c;
        if (first_of_case && n_with++ % size == rank) b->case_todo[b->n_case_todo++] = missing[i].c;
    }
    for (int i = 0; i < n_missing; ++i)
        for (int j = 0; j < b->n_case_todo; ++j)
            if (missing[i].c == b->case_todo[j]) b->todo[b->n_todo++] = missing[i];
    b->n_level_todo = b->n_todo;
    b->level_task = settle_and_turn, b->level_done = settled_and_turned, b->n_level_tasks = b->n_case_todo;
}

// Task i of the batch: a level task, then the runs from turned beds.
static int batch_task(int i, void *ctx)
{
    drum_batch *b = ctx;
    return i < b->n_level_tasks ? b->level_task(i, ctx) : turn_from_turned(i - b->n_level_tasks, ctx);
}

static void batch_done(int i, int code, void *ctx)
{
    drum_batch *b = ctx;
    if (i < b->n_level_tasks) b->level_done(i, code, ctx);
    else turned_from_turned(i - b->n_level_tasks, code, ctx);
}

// Deal the missing runs over the ranks and run this rank's share, those
// from a level bed and those from a turned one side by side (the beds they
// start from are made first).
static void run_missing_drum(drum_batch *b, const drum_run *missing, int n_missing)
{
    drum_run *level = calloc((size_t)n_missing, sizeof *level), *turned = calloc((size_t)n_missing, sizeof *turned);
    int n_level = 0, n_turned = 0;
    if (!level || !turned) {
        for (int i = 0; i < n_missing; ++i) write_failed(b->env, run_key(b, missing[i]), "out of memory");
        return free(level), free(turned);
    }
    for (int i = 0; i < n_missing; ++i) {
        if (cal_drum_case_turned(&b->cases[missing[i].c], b->rpm[missing[i].k])) turned[n_turned++] = missing[i];
        else level[n_level++] = missing[i];
    }
    if (n_level > 0) deal_level(b, level, n_level);
    if (n_turned > 0) deal_turned(b, turned, n_turned);
    int tasks = b->n_level_tasks + b->n_turned_tasks;
    if (tasks > 0) cal_pool_run(tasks, batch_task, batch_done, b, b->env->workers, b->env->use_fork);
    free(level), free(turned);
}

// A record of the store: 0 found, 1 missing (or damaged: run again), -1 an error.
// Store-only, a damaged record stays where it is: a plan changes nothing.
static int look_up(const cal_env *env, const char *key, cal_record *out, char *err, size_t len)
{
    return env->store_only ? cal_store_peek(env->store, key, out, err, len) : cal_store_lookup(env->store, key, out, err, len);
}

// Store-only, a batch with n runs missing: the evaluation ends here (an error).
static int store_ends(cal_env *env, int n, char *err, size_t len)
{
    env->store_missing = n;
    return exp_fail(err, len, "the store ends here: %d run(s) of this batch not in %s", n, env->store), 1;
}

// A record found in the store: a simulation done, at the cost it had; then released.
static void count_stored(cal_env *env, cal_run_kind kind, cal_record *r)
{
    cal_progress_count(env->progress, kind, cal_record_cost_s(r));
    cal_record_free(r);
}

static int ran_here(const drum_batch *b, drum_run r)
{
    for (int i = 0; i < b->n_todo; ++i)
        if (b->todo[i].c == r.c && b->todo[i].k == r.k) return 1;
    return 0;
}

int cal_drum_evaluate_many(cal_env *env, const cal_drum_case *cases, int n_cases, const double *rpm, int n,
                           cal_record *out, char *err, size_t len)
{
    if (n > 32) return exp_fail(err, len, "at most 32 speeds per candidate"), 1;
    int runs = n_cases * n;
    drum_batch b = {.env = env, .cases = cases, .n_cases = n_cases, .rpm = rpm, .n_rpm = n};
    b.keys = calloc((size_t)runs, sizeof *b.keys);
    b.todo = calloc((size_t)runs, sizeof *b.todo);
    b.case_todo = calloc((size_t)n_cases, sizeof *b.case_todo);
    drum_run *missing = calloc((size_t)runs, sizeof *missing);
    int n_missing = 0, bad = !b.keys || !b.todo || !b.case_todo || !missing;
    if (bad) exp_fail(err, len, "out of memory");
    cal_mpi_barrier(); // every rank sees the same store, so all deal the missing runs alike
    for (int c = 0; c < n_cases && !bad; ++c)
        for (int k = 0; k < n && !bad; ++k) {
            cal_drum_key(&cases[c], rpm[k], b.keys[c * n + k], sizeof b.keys[0]);
            int got = look_up(env, b.keys[c * n + k], &out[c * n + k], err, len);
            bad = got < 0;
            if (got == 1) missing[n_missing++] = (drum_run){c, k};
            if (got == 0) count_stored(env, drum_kind(env), &out[c * n + k]);
        }
    if (!bad && n_missing > 0 && env->store_only) bad = store_ends(env, n_missing, err, len);
    if (!bad && n_missing > 0) run_missing_drum(&b, missing, n_missing);
    cal_mpi_barrier(); // every rank's records are on the shared store now
    int read = 0;
    while (!bad && read < runs) bad = read_back(env, b.keys[read], &out[read], err, len), read += !bad;
    for (int i = 0; i < n_missing && !bad; ++i) // other ranks' runs
        if (!ran_here(&b, missing[i]))
            cal_progress_count(env->progress, drum_kind(env), cal_record_cost_s(&out[missing[i].c * n + missing[i].k]));
    if (bad) // the caller gets no records: release those read
        while (read > 0) cal_record_free(&out[--read]);
    free(b.keys), free(b.todo), free(b.case_todo), free(missing);
    free(b.turned_bed), free(b.turned_charge), free(b.prep), free(b.prepped);
    return bad;
}

int cal_drum_evaluate(cal_env *env, const cal_drum_case *c, const double *rpm, int n, cal_record *out, char *err,
                      size_t len)
{
    return cal_drum_evaluate_many(env, c, 1, rpm, n, out, err, len);
}

// ---- stage-1 beds: the poured cylinder or the drum's bed ----------------------

typedef struct bed_batch {
    cal_env *env;
    const cal_bed_case *cases;
    int *todo;
    char (*keys)[2048];
} bed_batch;

static int pour_one(int i, void *ctx)
{
    bed_batch *b = ctx;
    int k = b->todo[i];
    const cal_bed_case *c = &b->cases[k];
    double t0 = exp_wall_seconds();
    char err[1024];
    exp_cylinder_result res;
    dem_world *w = c->on_drum ? exp_drum_bed_run(&c->drum_bed, NULL, NULL, &res, err, sizeof err)
                              : exp_cylinder_run(&c->cylinder, NULL, NULL, &res, err, sizeof err);
    if (!w) return write_failed(b->env, b->keys[k], err), 1;
    cal_record r = {.key = b->keys[k], .status = "ok", .reason = ""};
    r.coordination = res.coordination, r.coordination_interior = res.coordination_interior;
    r.wall_contacts_per_granule = res.wall_contacts_per_granule, r.solid_fraction = res.solid_fraction;
    r.steady = 1, r.simulated_time_s = res.simulated_time_s, r.wall_time_s = exp_wall_seconds() - t0;
    r.peak_rss_mb = exp_peak_rss_mb(), r.particle_steps = res.particle_steps;
    r.dt_s = dem_world_dt(w), r.granules = (int)res.granules;
    dem_world_destroy(w);
    int bad = cal_store_put(b->env->store, &r, err, sizeof err);
    if (bad) fprintf(stderr, "granucal calibrate: %s\n", err);
    return bad;
}

static void poured(int i, int code, void *ctx)
{
    bed_batch *b = ctx;
    const cal_bed_case *c = &b->cases[b->todo[i]];
    char what[96];
    snprintf(what, sizeof what, "%s k_n = %g N/m, seed %llu", c->on_drum ? "drum bed" : "cylinder",
             c->cylinder.granule.k_n, (unsigned long long)c->cylinder.seed);
    finish_run(b->env, CAL_RUN_CYLINDER, b->keys[b->todo[i]], what, code);
}

int cal_bed_evaluate(cal_env *env, const cal_bed_case *cases, int n, cal_record *out, char *err, size_t len)
{
    char(*keys)[2048] = calloc((size_t)n, sizeof *keys);
    int *todo = calloc((size_t)n, sizeof *todo), n_todo = 0, n_missing = 0, bad = 0;
    char *missing = calloc((size_t)n, 1); // missing here and run by another rank
    if (!keys || !todo || !missing) return free(keys), free(todo), free(missing), exp_fail(err, len, "out of memory"), 1;
    cal_mpi_barrier();
    for (int k = 0; k < n && !bad; ++k) {
        cal_bed_key(&cases[k], keys[k], sizeof keys[k]);
        int got = look_up(env, keys[k], &out[k], err, len);
        bad = got < 0;
        missing[k] = got == 1;
        if (got == 1 && n_missing++ % cal_mpi_size() == cal_mpi_rank()) todo[n_todo++] = k, missing[k] = 0;
        if (got == 0) count_stored(env, CAL_RUN_CYLINDER, &out[k]);
    }
    if (!bad && n_missing > 0 && env->store_only) bad = store_ends(env, n_missing, err, len);
    bed_batch b = {env, cases, todo, keys};
    if (!bad && n_todo > 0) cal_pool_run(n_todo, pour_one, poured, &b, env->workers, env->use_fork);
    cal_mpi_barrier();
    for (int k = 0; k < n && !bad; ++k) {
        bad = read_back(env, keys[k], &out[k], err, len);
        if (!bad && missing[k]) cal_progress_count(env->progress, CAL_RUN_CYLINDER, cal_record_cost_s(&out[k])); // another rank's
    }
    free(keys), free(todo), free(missing);
    return bad;
}
