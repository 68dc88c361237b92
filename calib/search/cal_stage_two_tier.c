// SPDX-License-Identifier: MIT
// Stages 2 and 3 across two tiers (cal_stages.h: cal_stage_two_tier). The
// map tier runs the whole one-tier search (grid, COBYLA, bound probes); its
// candidates make the cheap map (cal_multifidelity.c); this tier is run only
// where the corrected map puts the optimum, and each of its runs measures the
// discrepancy between the tiers there. No correction comes from anywhere but
// these paired runs.
//
// What the stage reports: the chosen pair is the best candidate run at this
// tier; the identified ranges are over those and over every map candidate
// corrected by the measured discrepancy (their measurements at the map tier
// plus the correction where they stand, marked "predicted"), since a handful
// of expensive runs alone would say nothing about the range.
//
// Levels: a map tier that has a map_tier of its own is itself such a stage,
// run first (ci -> λ 1000 -> λ 512: the λ 1000 stage maps with ci, and its
// result maps for λ 512). The level above fits its map on that result and
// corrects it by the discrepancy measured at its own runs alone, as two tiers
// do: no correction comes from another level or from any known answer.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_multifidelity.h"
#include "cal_posterior.h"
#include "cal_stages.h"
#include "exp_common.h"

/// An angle outside its tolerance costs this much per tolerance squared in
/// the map's objective under the paper's constraint rule: the map is smooth,
/// so a penalty stands in for the constraint (the expensive runs are then
/// judged by the stage's own rule).
static const double angle_penalty = 100.0;

typedef struct two_tier {
    cal_friction_search *search;
    cal_friction_result *r;
    const cal_bounds *bounds;
    const cal_mf_map *map; ///< the cheap map, for the posterior between runs
    double angle_aim_sd;   ///< the tier's angle_aim_sd (cal_config.h)
} two_tier;

static int n_measurements(const cal_friction_result *r) { return 1 + r->n_rpm; }

static void candidate_of(const cal_friction_result *r, const double *y, cal_candidate *k)
{
    k->angle_deg = y[0];
    for (int i = 0; i < r->n_rpm; ++i) k->csa[i] = y[1 + i], k->usable[i] = 1;
    cal_candidate_score(r, k);
}

// The penalty starts where the band, narrowed by angle_aim_sd of the
// prediction's sd (at most to its centre), ends; its scale stays the whole
// tolerance. Without the narrowing the optimum stands just outside the edge
// the CSA pulls toward, where the penalty's slope is still small.
double cal_two_tier_objective(const cal_friction_result *r, const double *y, const double *sd, double angle_aim_sd)
{
    cal_candidate k = {0};
    candidate_of(r, y, &k);
    if (r->angle_in_misfit) return k.objective;
    double violation = k.angle_violation;
    if (angle_aim_sd > 0) violation += fmin(angle_aim_sd * sd[0], r->angle_tolerance);
    double over = fmax(0, violation) / fmax(r->angle_tolerance, 0.1);
    return k.misfit + angle_penalty * over * over;
}

static double map_objective(const double *y, const double *sd, void *ctx)
{
    const two_tier *t = ctx;
    return cal_two_tier_objective(t->r, y, sd, t->angle_aim_sd);
}

static int run_here(double u, double v, cal_mf_point *run, void *ctx)
{
    two_tier *t = ctx;
    double mu_s, mu_r;
    cal_friction_to_mu(t->bounds, u, v, &mu_s, &mu_r);
    const cal_candidate *k = cal_friction_evaluate(t->search, mu_s, mu_r, "two-tier");
    if (!k) return 1;
    // A mean that is not steady enters with its own spread (the loop weighs
    // it by that, and it cannot agree); a failed run measured nothing.
    if (cal_candidate_run_vector(t->r, k, run->y, run->sd))
        for (int i = 0; i < n_measurements(t->r); ++i) run->y[i] = NAN;
    return 0;
}

// One candidate's own noise at tier t, per measurement (angle, then CSA per
// speed): the tier's seed spreads over its beds. The kriging smooths it at
// this tier's runs; a level above weighs this tier's runs by it.
static void run_noise_of(const cal_tier *t, const cal_friction_result *r, double *noise)
{
    noise[0] = t->angle_sd_deg / sqrt(cal_tier_beds(t));
    for (int i = 0; i < r->n_rpm; ++i) noise[1 + i] = r->csa_tier_sd[i];
}

// A point's weight in a level's map is floored at this share of the data's
// spread: a tier whose spread is unmeasured (0) would otherwise weigh
// infinitely, and differences far below the data's spread do not move the
// search.
static const double sd_floor_of_spread = 0.1;

// Each usable candidate's standard deviation in the map of the level above:
// its tier's run noise for a run, its own predicted_sd for a prediction.
static void point_sd(const cal_friction_result *cheap, const cal_candidate *k, const double *cheap_noise,
                     const cal_friction_result *r, double *sd)
{
    double floor_sd[CAL_MF_MAX_Y];
    floor_sd[0] = sd_floor_of_spread * cal_friction_angle_spread(r);
    for (int i = 0; i < r->n_rpm; ++i) floor_sd[1 + i] = sd_floor_of_spread * cal_friction_csa_spread(r, i);
    for (int j = 0; j < n_measurements(cheap); ++j) sd[j] = fmax(k->predicted ? k->predicted_sd[j] : cheap_noise[j], floor_sd[j]);
}

// The map from the cheap stage's usable candidates, in this stage's unit
// square. A one-tier cheap stage: plain least squares through its runs, as
// two tiers always did. A two-tier cheap stage (levels): through its runs AND
// its predicted candidates, weighted by 1/sd². Its few runs alone (the λ 1000
// stage makes ~4) would give a plane at best and throw away what its map
// learned over the whole square; its predictions carry that map, corrected by
// what its runs measured. But they are not measurements: each counts with
// its own sd (the run it stands for and the kriging's sd of the correction
// where it stands, large far from that level's runs), so near the lower
// level's runs the fit follows those runs and far from them the prediction
// counts for what it is worth. The kriging of this level's discrepancy then
// sees this level's runs alone, with their own noise as its nugget: no
// predicted point is ever one of its exact data.
static int fit_map(const cal_friction_result *cheap, const double *cheap_noise, const cal_friction_result *r,
                   const cal_bounds *b, int n_y, cal_mf_map *map)
{
    cal_mf_point *pts = calloc((size_t)cheap->n, sizeof *pts);
    double(*sd)[CAL_MF_MAX_Y] = calloc((size_t)cheap->n, sizeof *sd);
    if (!pts || !sd) return free(pts), free(sd), 1;
    int n = 0;
    for (int i = 0; i < cheap->n; ++i)
        if (!cal_candidate_vector(cheap, &cheap->cand[i], pts[n].y)) {
            cal_friction_to_unit(b, cheap->cand[i].mu_s, cheap->cand[i].mu_r, &pts[n].u, &pts[n].v);
            point_sd(cheap, &cheap->cand[i], cheap_noise, r, sd[n]);
            n++;
        }
    int bad = cal_mf_fit_weighted(pts, cheap->n_levels ? (const double(*)[CAL_MF_MAX_Y])sd : NULL, n, n_y, map);
    free(pts), free(sd);
    return bad;
}

// Every usable map candidate, corrected where it stands, as a predicted
// candidate of this stage, with its own sd (its source's noise and the
// kriging's sd of the correction, in quadrature) for a level above.
static void add_predicted(cal_friction_result *r, const cal_friction_result *cheap, const double *cheap_noise,
                          const cal_bounds *b, const cal_mf_correction *correction)
{
    for (int i = 0; i < cheap->n && r->n < CAL_MAX_EVALS; ++i) {
        const cal_candidate *from = &cheap->cand[i];
        double y[CAL_MF_MAX_Y], u, v;
        if (cal_candidate_vector(cheap, from, y)) continue;
        cal_friction_to_unit(b, from->mu_s, from->mu_r, &u, &v);
        cal_mf_correct(correction, n_measurements(r), u, v, y);
        cal_candidate *k = &r->cand[r->n++];
        memset(k, 0, sizeof *k);
        k->mu_s = from->mu_s, k->mu_r = from->mu_r;
        k->origin = "map + correction", k->predicted = 1, k->level = from->level + 1;
        k->angle_sd_deg = NAN;
        for (int j = 0; j < n_measurements(r); ++j) {
            double source = from->predicted ? from->predicted_sd[j] : cheap_noise[j];
            k->predicted_sd[j] = hypot(source, cal_mf_correction_sd(correction, j, u, v));
        }
        candidate_of(r, y, k);
    }
}

static const char *outcome_of(const cal_mf_result *m)
{
    if (m->failed) return "stopped: a simulation could not be stored";
    if (m->agreed) return "agreed: the last run matched the corrected map within the data's noise";
    if (m->settled && m->unmeasured)
        return "stopped: the corrected optimum came back to a run that measured nothing (it failed); not settled";
    if (m->settled && m->settled_noisy)
        return "settled on a run that is not steady: the corrected optimum came back to it, whose mean counts "
               "with its own spread; a longer run there would tell more";
    if (m->settled) return "settled: the corrected optimum came back to a point already run, without agreeing";
    return "stopped at max_evaluations without agreeing with the corrected map";
}

// What a level below this stage ran, cost and chose.
static void describe_level(cal_level *l, const cal_friction_result *r, const cal_tier *t)
{
    memset(l, 0, sizeof *l);
    snprintf(l->tier, sizeof l->tier, "%s", t->name);
    l->lambda = t->lambda;
    for (int i = 0; i < r->n; ++i) l->runs += !r->cand[i].predicted;
    l->simulations = r->simulations, l->core_s = r->core_s, l->wall_time_s = r->wall_time_s;
    l->outcome = r->n_levels ? r->two_tier_outcome : NULL;
    const cal_candidate *best = r->best >= 0 ? &r->cand[r->best] : NULL;
    l->best_mu_s = best ? best->mu_s : NAN, l->best_mu_r = best ? best->mu_r : NAN;
    l->best_angle_deg = best ? best->angle_deg : NAN;
}

// The levels below this stage: its map tier, then the map tier's own levels.
static void keep_levels(cal_friction_result *out, const cal_friction_result *cheap, const cal_tier *map_tier)
{
    describe_level(&out->level[0], cheap, map_tier);
    out->n_levels = 1;
    for (int k = 0; k < cheap->n_levels && out->n_levels < CAL_MAX_MAP_DEPTH; ++k) out->level[out->n_levels++] = cheap->level[k];
}

// What the loop did, into the stage's result (and on stderr): its runs
// against their predictions, the outcome, the correction, and the map's
// candidates corrected as predicted candidates.
static void keep_loop(cal_friction_result *out, const cal_friction_result *cheap, const double *cheap_noise,
                      const cal_mf_map *map, const cal_mf_result *m, const char *loop_outcome, const char *tier,
                      const cal_bounds *b)
{
    out->has_map = !m->failed && m->n > 0, out->cheap_map = *map, out->discrepancy = m->correction;
    out->expensive_candidates = m->n, out->two_tier_outcome = loop_outcome;
    out->map_u = m->u_uncorrected, out->map_v = m->v_uncorrected;
    for (int k = 0; k < n_measurements(out); ++k) out->correction[k] = m->delta[k];
    for (int i = 0; i < m->n; ++i) {
        char own[64] = "";
        if (m->run[i].sd[0] > 0) snprintf(own, sizeof own, " (not steady: counts with ± %.2f°)", m->run[i].sd[0]);
        fprintf(stderr, "-- run %d at tier '%s': angle %.2f° measured%s, %.2f° predicted by the corrected map\n", i + 1,
                tier, m->run[i].y[0], own, m->predicted[i][0]);
    }
    fprintf(stderr, "-- %s after %d run(s) at tier '%s'", out->two_tier_outcome,
            m->n - out->posterior_runs - out->return_runs, tier);
    if (out->posterior_runs) fprintf(stderr, ", then %d where the posterior asked", out->posterior_runs);
    if (out->return_outcome)
        fprintf(stderr, ", then %d back at the corrected optimum (%s)", out->return_runs, out->return_outcome);
    fprintf(stderr, "; correction at the last run: angle %+.2f°\n", m->delta[0]);
    if (!m->failed && m->n > 0) add_predicted(out, cheap, cheap_noise, b, &m->correction);
}

// cal_mf_next_point for the runs after the loop: the posterior on the map
// corrected so far, and where it asks for a run (cal_posterior_next_run).
static int posterior_next(const cal_mf_correction *c, double *u, double *v, void *ctx)
{
    two_tier *t = ctx;
    cal_friction_result *r = t->r;
    r->has_map = 1, r->cheap_map = *t->map, r->discrepancy = *c;
    cal_posterior post;
    char why[200];
    if (cal_posterior_sample(r, t->bounds, &post, why, sizeof why)) {
        fprintf(stderr, "-- posterior: %s; no run after the loop\n", why);
        return 1;
    }
    cal_posterior_need need;
    int none = cal_posterior_next_run(r, t->bounds, &post, u, v, &need);
    r->posterior_share = need.share;
    snprintf(r->posterior_share_of, sizeof r->posterior_share_of, "%s",
             need.measurement >= 0 ? post.observable[need.measurement] : "no measurement the data can tell");
    const char *unmodelled = post.correction_unmodelled;
    if (none && unmodelled)
        fprintf(stderr, "-- posterior: %s: the correction has no variance model, so no share of the map's uncertainty "
                        "to judge by; no more runs\n",
                unmodelled);
    else if (none && need.measurement < 0)
        fprintf(stderr, "-- posterior: no measurement moves by one data spread with a parameter the data can tell: "
                        "no run would narrow it; no more runs\n");
    else if (none) // the rest is the data's spread and the map's residual, which runs here do not shrink
        fprintf(stderr, "-- posterior: the map's own uncertainty is %.0f %% of the variance of %s (below %.0f %%): "
                        "the width is the data's (sd %.3g) and the map's residual (rms %.3g), which runs at this tier "
                        "do not narrow; no more runs\n", 100 * need.share, r->posterior_share_of,
                100 * CAL_POSTERIOR_MAP_SHARE, post.data_sd[need.measurement], post.map_rms[need.measurement]);
    else {
        double mu_s, mu_r;
        cal_friction_to_mu(t->bounds, *u, *v, &mu_s, &mu_r);
        fprintf(stderr, "-- posterior: the map's own uncertainty is %.0f %% of the variance of %s: one more run where "
                        "it weighs most, mu_s = %.4g, mu_r = %.4g\n", 100 * need.share, r->posterior_share_of, mu_s, mu_r);
    }
    cal_posterior_free(&post);
    return none;
}

// The level below, whole: the map tier's one-tier search, or where the map
// tier maps with another, its own two-tier stage (recursing; the config
// check bounds the depth and refuses cycles). env->mapping is the level
// running, for progress labels and costs.
static int map_stage(cal_env *env, const cal_config *c, const cal_tier *map_tier, const cal_series *angles,
                     const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s, double gg_mu_r,
                     cal_friction_result *cheap, char *err, size_t len)
{
    fprintf(stderr, "-- map: the whole search at tier '%s' (lambda %g)\n", map_tier->name, map_tier->lambda);
    int level = env->mapping, bad;
    env->mapping = level + 1; // progress: "NAME (map)", "NAME (map 2)"..., counted by level
    if (map_tier->map_tier) {
        cal_friction_result *cheaper = calloc(1, sizeof *cheaper);
        bad = !cheaper ? exp_fail(err, len, "out of memory")
                       : cal_stage_two_tier(env, c, map_tier, angles, areas, k_n, material, gg_mu_s, gg_mu_r, cheap,
                                            cheaper, err, len);
        free(cheaper);
    } else bad = cal_stage_friction(env, c, map_tier, angles, areas, k_n, material, gg_mu_s, gg_mu_r, cheap, err, len);
    env->mapping = level;
    return bad;
}

int cal_stage_two_tier(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, cal_friction_result *cheap, char *err, size_t len)
{
    const cal_tier *map_tier = cal_config_tier_named(c, t->map_tier); // checked on loading
    if (map_stage(env, c, map_tier, angles, areas, k_n, material, gg_mu_s, gg_mu_r, cheap, err, len)) return 1;
    cal_env_set_stage(env, material ? material->name : "granule");
    cal_progress_enter(env->progress, env->stage);
    two_tier tt = {.r = out, .angle_aim_sd = t->angle_aim_sd};
    tt.search = cal_friction_begin(env, c, t, angles, areas, k_n, material, gg_mu_s, gg_mu_r, out, err, len);
    if (!tt.search) return 1;
    tt.bounds = cal_friction_bounds(tt.search);
    int n_y = n_measurements(out);
    keep_levels(out, cheap, map_tier);
    out->nlopt_result = "NLopt BOBYQA on the corrected map (two tiers)";
    // Agreement within the data's noise (the lab's and the tier's); kriging
    // smooths only the tier's own (a candidate's seed spread).
    double noise[CAL_MF_MAX_Y], run_noise[CAL_MF_MAX_Y], cheap_noise[CAL_MF_MAX_Y];
    noise[0] = out->angle_tolerance;
    for (int i = 0; i < out->n_rpm; ++i) noise[1 + i] = cal_friction_csa_spread(out, i);
    run_noise_of(t, out, run_noise), run_noise_of(map_tier, cheap, cheap_noise);
    cal_mf_map map;
    if (n_y > CAL_MF_MAX_Y || fit_map(cheap, cheap_noise, out, tt.bounds, n_y, &map)) {
        out->two_tier_outcome = "not run: too few usable map candidates to fit the map";
        return cal_friction_finish(tt.search) || exp_fail(err, len, "%s: %s (tier '%s')", env->stage, out->two_tier_outcome,
                                                          map_tier->name);
    }
    cal_mf_problem p = {.n_y = n_y, .objective = map_objective, .objective_uses_sd = t->angle_aim_sd > 0,
                        .run_expensive = run_here, .noise = noise, .run_noise = run_noise,
                        .max_expensive = t->max_evaluations, .ctx = &tt, .correction = cal_tier_map_correction(t)};
    out->map_correction = cal_mf_correction_name(p.correction);
    fprintf(stderr, "-- tier '%s' where the corrected map puts the optimum (at most %d runs; correction: %s)\n", t->name,
            t->max_evaluations, out->map_correction);
    cal_mf_result *m = calloc(1, sizeof *m);
    if (!m) return cal_friction_finish(tt.search), exp_fail(err, len, "out of memory");
    cal_mf_search(&map, &p, m);
    const char *loop_outcome = outcome_of(m);
    int loop_runs = m->n;
    tt.map = &map;
    out->posterior_runs_outcome = cal_mf_refine(&map, &p, t->posterior_runs, posterior_next, &tt, m);
    out->posterior_runs = m->n - loop_runs;
    if (out->posterior_runs > 0 && t->return_runs > 0) {
        // Said here, as each of the loop's other runs says why it is where it is.
        fprintf(stderr, "-- back where the corrected map, with the posterior's %d run(s) in it, puts the optimum "
                        "(return_runs: at most %d)\n", out->posterior_runs, t->return_runs);
        out->return_runs = cal_mf_return(&map, &p, t->return_runs, m);
        out->return_outcome = outcome_of(m);
    }
    keep_loop(out, cheap, cheap_noise, &map, m, loop_outcome, t->name, tt.bounds);
    free(m);
    return cal_friction_finish(tt.search);
}
