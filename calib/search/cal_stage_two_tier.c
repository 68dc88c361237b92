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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_multifidelity.h"
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
} two_tier;

static int n_measurements(const cal_friction_result *r) { return 1 + r->n_rpm; }

static void candidate_of(const cal_friction_result *r, const double *y, cal_candidate *k)
{
    k->angle_deg = y[0];
    for (int i = 0; i < r->n_rpm; ++i) k->csa[i] = y[1 + i], k->usable[i] = 1;
    cal_candidate_score(r, k);
}

static double map_objective(const double *y, void *ctx)
{
    const two_tier *t = ctx;
    cal_candidate k = {0};
    candidate_of(t->r, y, &k);
    if (t->r->angle_in_misfit) return k.objective;
    double over = fmax(0, k.angle_violation) / fmax(t->r->angle_tolerance, 0.1);
    return k.misfit + angle_penalty * over * over;
}

static int run_here(double u, double v, double *y, void *ctx)
{
    two_tier *t = ctx;
    double mu_s, mu_r;
    cal_friction_to_mu(t->bounds, u, v, &mu_s, &mu_r);
    const cal_candidate *k = cal_friction_evaluate(t->search, mu_s, mu_r, "two-tier");
    if (!k) return 1;
    if (cal_candidate_vector(t->r, k, y)) // a failed run: measured as far off as the penalty says, and not agreeing
        for (int i = 0; i < n_measurements(t->r); ++i) y[i] = NAN;
    return 0;
}

// The map from the cheap stage's usable candidates, in this stage's unit square.
static int fit_map(const cal_friction_result *cheap, const cal_bounds *b, int n_y, cal_mf_map *map)
{
    cal_mf_point *pts = calloc((size_t)cheap->n, sizeof *pts);
    if (!pts) return 1;
    int n = 0;
    for (int i = 0; i < cheap->n; ++i)
        if (!cal_candidate_vector(cheap, &cheap->cand[i], pts[n].y)) {
            cal_friction_to_unit(b, cheap->cand[i].mu_s, cheap->cand[i].mu_r, &pts[n].u, &pts[n].v);
            n++;
        }
    int bad = cal_mf_fit(pts, n, n_y, map);
    free(pts);
    return bad;
}

// Every usable map candidate, corrected where it stands, as a predicted candidate of this stage.
static void add_predicted(cal_friction_result *r, const cal_friction_result *cheap, const cal_bounds *b,
                          const cal_mf_correction *correction)
{
    for (int i = 0; i < cheap->n && r->n < CAL_MAX_EVALS; ++i) {
        double y[CAL_MF_MAX_Y], u, v;
        if (cal_candidate_vector(cheap, &cheap->cand[i], y)) continue;
        cal_friction_to_unit(b, cheap->cand[i].mu_s, cheap->cand[i].mu_r, &u, &v);
        cal_mf_correct(correction, n_measurements(r), u, v, y);
        cal_candidate *k = &r->cand[r->n++];
        memset(k, 0, sizeof *k);
        k->mu_s = cheap->cand[i].mu_s, k->mu_r = cheap->cand[i].mu_r;
        k->origin = "map + correction", k->predicted = 1;
        k->angle_sd_deg = NAN;
        candidate_of(r, y, k);
    }
}

static const char *outcome_of(const cal_mf_result *m)
{
    if (m->failed) return "stopped: a simulation could not be stored";
    if (m->agreed) return "agreed: the last run matched the corrected map within the data's noise";
    if (m->settled) return "settled: the corrected optimum came back to a point already run, without agreeing";
    return "stopped at max_evaluations without agreeing with the corrected map";
}

// What the loop did, into the stage's result (and on stderr): its runs
// against their predictions, the outcome, the correction, and the map's
// candidates corrected as predicted candidates.
static void keep_loop(cal_friction_result *out, const cal_friction_result *cheap, const cal_mf_map *map,
                      const cal_mf_result *m, const char *tier, const cal_bounds *b)
{
    out->has_map = !m->failed && m->n > 0, out->cheap_map = *map, out->discrepancy = m->correction;
    out->expensive_candidates = m->n, out->two_tier_outcome = outcome_of(m);
    out->map_u = m->u_uncorrected, out->map_v = m->v_uncorrected;
    for (int k = 0; k < n_measurements(out); ++k) out->correction[k] = m->delta[k];
    for (int i = 0; i < m->n; ++i)
        fprintf(stderr, "-- run %d at tier '%s': angle %.2f° measured, %.2f° predicted by the corrected map\n", i + 1,
                tier, m->run[i].y[0], m->predicted[i][0]);
    fprintf(stderr, "-- %s after %d run(s) at tier '%s'; correction at the last run: angle %+.2f°\n", out->two_tier_outcome,
            m->n, tier, m->delta[0]);
    if (!m->failed && m->n > 0) add_predicted(out, cheap, b, &m->correction);
}

int cal_stage_two_tier(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, cal_friction_result *cheap, char *err, size_t len)
{
    const cal_tier *map_tier = cal_config_tier_named(c, t->map_tier); // checked on loading
    fprintf(stderr, "-- map: the whole search at tier '%s' (lambda %g)\n", map_tier->name, map_tier->lambda);
    env->mapping = 1; // progress: "NAME (map)", counted as map-tier drum runs
    int bad = cal_stage_friction(env, c, map_tier, angles, areas, k_n, material, gg_mu_s, gg_mu_r, cheap, err, len);
    env->mapping = 0;
    if (bad) return 1;
    cal_env_set_stage(env, material ? material->name : "granule");
    cal_progress_enter(env->progress, env->stage);
    two_tier tt = {.r = out};
    tt.search = cal_friction_begin(env, c, t, angles, areas, k_n, material, gg_mu_s, gg_mu_r, out, err, len);
    if (!tt.search) return 1;
    tt.bounds = cal_friction_bounds(tt.search);
    int n_y = n_measurements(out);
    snprintf(out->map_tier, sizeof out->map_tier, "%s", map_tier->name);
    out->map_candidates = cheap->n, out->map_wall_time_s = cheap->wall_time_s;
    out->map_simulations = cheap->simulations, out->map_core_s = cheap->core_s;
    out->nlopt_result = "NLopt BOBYQA on the corrected map (two tiers)";
    cal_mf_map map;
    if (n_y > CAL_MF_MAX_Y || fit_map(cheap, tt.bounds, n_y, &map)) {
        out->two_tier_outcome = "not run: too few usable map candidates to fit the map";
        return cal_friction_finish(tt.search) || exp_fail(err, len, "%s: %s (tier '%s')", env->stage, out->two_tier_outcome,
                                                          map_tier->name);
    }
    // Agreement within the data's noise (the lab's and the tier's); kriging
    // smooths only the tier's own (a candidate's seed spread).
    double noise[CAL_MF_MAX_Y], run_noise[CAL_MF_MAX_Y];
    noise[0] = out->angle_tolerance, run_noise[0] = t->angle_sd_deg / sqrt(cal_tier_beds(t));
    for (int i = 0; i < out->n_rpm; ++i) noise[1 + i] = cal_friction_csa_spread(out, i), run_noise[1 + i] = out->csa_tier_sd[i];
    cal_mf_problem p = {.n_y = n_y, .objective = map_objective, .run_expensive = run_here, .noise = noise, .run_noise = run_noise,
                        .max_expensive = t->max_evaluations, .ctx = &tt, .correction = cal_tier_map_correction(t)};
    out->map_correction = cal_mf_correction_name(p.correction);
    fprintf(stderr, "-- tier '%s' where the corrected map puts the optimum (at most %d runs; correction: %s)\n", t->name,
            t->max_evaluations, out->map_correction);
    cal_mf_result *m = calloc(1, sizeof *m);
    if (!m) return cal_friction_finish(tt.search), exp_fail(err, len, "out of memory");
    cal_mf_search(&map, &p, m);
    keep_loop(out, cheap, &map, m, t->name, tt.bounds);
    free(m);
    return cal_friction_finish(tt.search);
}
