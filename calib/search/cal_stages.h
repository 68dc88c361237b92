// SPDX-License-Identifier: MIT
/// @file cal_stages.h
/// The three stages of the calibration (the paper's section 4):
///   1. stiffness: coordination number of a poured cylinder against k_n;
///   2. granule–granule (μs, μr) in the drum lined with granules;
///   3. each wall material's (μs, μr), granule–granule frozen.
#ifndef CAL_STAGES_H
#define CAL_STAGES_H

#include "cal_case_runs.h"
#include "cal_config.h"
#include "cal_data.h"
#include "cal_multifidelity.h"

enum { CAL_MAX_K = 64, CAL_MAX_EVALS = 512, CAL_MAX_RPM = 16 };

typedef struct cal_stiffness_result {
    int n;                       ///< stiffness candidates
    const char *scene;           ///< the bed swept, read after "the": "poured cylinder" or "drum's own poured bed"
    double k[CAL_MAX_K];
    double cn_mean[CAL_MAX_K], cn_sd[CAL_MAX_K]; ///< over seeds
    double wall_cn[CAL_MAX_K], solid_fraction[CAL_MAX_K];
    int granules[CAL_MAX_K], failed[CAL_MAX_K];
    double stiff_limit;          ///< CN at the stiffest candidate
    double tolerance;            ///< |CN - stiff limit| allowed
    const char *tolerance_rule;  ///< how the tolerance was set
    double chosen_k;
    int resolved;                ///< 0 if even the softest candidate is within the tolerance: the sweep shows no change
    double wall_time_s;
} cal_stiffness_result;

int cal_stage_stiffness(cal_env *env, const cal_config *c, const cal_tier *t, cal_stiffness_result *out, char *err,
                        size_t len);

/// Stage 1's rule on measured k, cn_mean, stiff_limit and tolerance: the
/// smallest k from which every stiffer candidate is within the tolerance of
/// the stiff limit (chosen_k), resolved only if every softer candidate is
/// outside it (the departure persists as k softens).
void cal_stiffness_choose(cal_stiffness_result *s);

/// One evaluated (μs, μr) candidate.
typedef struct cal_candidate {
    double mu_s, mu_r;
    double angle_deg, angle_sd_deg;     ///< at the angle's speed
    double csa[CAL_MAX_RPM], csa_sd[CAL_MAX_RPM];
    int usable[CAL_MAX_RPM];            ///< steady and not failed
    double misfit;                      ///< mean squared CSA misfit in data standard deviations (+ penalties)
    double angle_violation;             ///< |angle - target| - tolerance (≤ 0: matches)
    double objective;                   ///< what the search minimises: the CSA misfit, or with the
                                        ///< angle's squared z-score as one more term (angle_in_misfit)
    const char *origin;                 ///< "grid", "COBYLA", "bound probe", "two-tier" or "map + correction"
    int predicted;                      ///< 1: not run at this tier but the corrected cheap map's value
                                        ///< at a cheap candidate (two-tier stage): in the identified
                                        ///< range, never the chosen pair
    int level;                          ///< the level of the run it stands for: 0 this tier's, 1 its
                                        ///< map tier's, 2 that tier's map tier's...
    /// A predicted candidate's own standard deviation per measurement (angle,
    /// then CSA per speed): the noise of the run it stands for and the
    /// correction's kriging sd where it stands, in quadrature (0 for a run).
    /// The level above weighs it by this when it fits its map on this stage.
    double predicted_sd[CAL_MAX_RPM + 1];
    /// Per measurement (angle, then CSA per speed), where the mean comes from
    /// runs that did not reach their steady state: the spread of their series
    /// (the error of a mean over a stationary series cannot exceed it; a drift
    /// adds a bias beyond it). 0 for a steady measurement.
    double unsteady_sd[CAL_MAX_RPM + 1];
    double chi2;                        ///< χ² against the data with the lab's and the tier's spreads (identification)
    int identified;                     ///< 1 if the data cannot tell it from the best χ² (Δχ² within the threshold)
    double wall_time_s;
} cal_candidate;

/// The range of one parameter over the candidates the data cannot tell apart.
/// The candidates are a sparse set, so [lo, hi] alone can be narrower than
/// what the data say (one μs value identified says nothing of the gap to the
/// nearest excluded one): the bracket is the interval no evaluated candidate
/// excludes, from the nearest excluded value beyond each end, or the search
/// bound where nothing beyond was excluded.
typedef struct cal_range {
    double lo, hi;       ///< smallest and largest value among them
    double below, above; ///< the nearest excluded candidate's value beyond each end; NAN: none evaluated there
    double bracket_lo, bracket_hi; ///< below/above, or the search bound where NAN (cal_range_bracket)
} cal_range;

/// No range (the stage was not run).
#define CAL_NO_RANGE_INIT {NAN, NAN, NAN, NAN, NAN, NAN}
#define CAL_NO_RANGE ((cal_range)CAL_NO_RANGE_INIT)

/// Set g's bracket from below/above and the search bounds.
void cal_range_bracket(cal_range *g, double bound_lo, double bound_hi);

/// A friction's 95 % credible interval from its stage's posterior
/// (cal_posterior.h); known 0 where there is none (a stage read from an
/// earlier run's stage file, or too few runs to map).
typedef struct cal_credible {
    int known;
    double lo, hi;
    int reaches_lower, reaches_upper; ///< the interval runs to that search bound
    double width;                     ///< as a fraction of the search range, on the search's scale
    /// 1: the posterior takes its corrected map's correction as exact (no
    /// variance model: cal_posterior.correction_unmodelled), so it decides
    /// no status
    int correction_exact;
} cal_credible;

/// One tier below a two-tier stage's own (its map tier, or a level further
/// down where the map tier maps with another): what it ran, what it cost and
/// what its own search chose, so that a report shows what each level bought.
typedef struct cal_level {
    char tier[32];
    double lambda;
    int runs;           ///< candidates run at that tier (its predicted ones not counted)
    int simulations;    ///< their drum runs (stored ones included) and single-core seconds
    double core_s, wall_time_s;
    const char *outcome; ///< a two-tier level's loop end (cal_friction_result.two_tier_outcome); NULL: a one-tier search
    double best_mu_s, best_mu_r, best_angle_deg; ///< that level's chosen pair and its angle (NAN: none)
} cal_level;

/// What a friction stage found.
typedef struct cal_friction_result {
    char material[32];                  ///< "" for granule–granule
    char surface[64];
    double k_n;
    double frozen_mu_s, frozen_mu_r;    ///< granule–granule pair (wall stage)
    double angle_target, angle_tolerance, angle_rpm; ///< the data's angle, its tolerance (data and tier spreads)
    int angle_in_misfit;                             ///< the tier's angle_rule is "misfit"
    int n_rpm;
    double rpm[CAL_MAX_RPM], csa_data[CAL_MAX_RPM], csa_data_sd[CAL_MAX_RPM];
    double csa_tier_sd[CAL_MAX_RPM];    ///< the tier's measured seed spread at each speed (0: not measured)
    cal_provenance angle_source, csa_source; ///< whether the data files' numbers are synthetic (the figures say so)
    int n;                              ///< candidates evaluated
    cal_candidate cand[CAL_MAX_EVALS];
    int best;                           ///< index of the chosen candidate, -1 if none usable
    int best_feasible;                  ///< 1 if it matches the angle
    double chi2_least;                  ///< the smallest χ² of the candidates
    double chi2_threshold;              ///< Δχ² within which candidates are not told apart
    cal_range mu_s_range, mu_r_range;   ///< what the data identify (cal_friction_identify)
    int identified_count;               ///< candidates within the threshold
    const char *nlopt_result;
    double wall_time_s;
    int simulations;                    ///< drum runs of this tier's candidates (stored ones included)
    double core_s;                      ///< what they cost, single-core seconds (their records' costs)
    /// Two-tier stage (tier with map_tier): the tiers below it, their runs
    /// and cost, the correction measured (angle, then CSA per speed), and
    /// how the loop ended. n_levels 0: a one-tier stage.
    int n_levels;
    cal_level level[CAL_MAX_MAP_DEPTH]; ///< nearest first: level[0] is the map tier
    int expensive_candidates;
    double correction[CAL_MAX_RPM + 1]; ///< at the last run (cal_mf_result.delta)
    double map_u, map_v;                ///< the uncorrected cheap map's optimum (unit square)
    const char *two_tier_outcome;
    const char *map_correction;         ///< "kriging" or "affine" (cal_mf_correction_kind)
    /// Of expensive_candidates, the runs after the loop where the posterior
    /// asked (the tier's posterior_runs, cal_posterior_next_run), why they
    /// stopped, and the last share of the map's uncertainty they saw.
    int posterior_runs;
    const char *posterior_runs_outcome;
    /// Of expensive_candidates, the runs after those at the corrected
    /// optimum (the tier's return_runs, cal_mf_return), and how that resumed
    /// loop ended (NULL: not resumed).
    int return_runs;
    const char *return_outcome;
    double posterior_share;
    char posterior_share_of[48];
    /// The map the two-tier search ended with: the map tier's quadratic map in
    /// this stage's unit square and the discrepancy measured at this tier's
    /// runs (the posterior samples it: cal_posterior.h). has_map 0: a one-tier
    /// stage, or a loop that made no run.
    int has_map;
    cal_mf_map cheap_map;
    cal_mf_correction discrepancy;
} cal_friction_result;

/// A candidate's scores from its measurements (angle_deg, csa, usable):
/// angle_violation, the CSA misfit and the search's objective, by the rule
/// in r (angle_in_misfit, targets, tolerance, data).
void cal_candidate_score(const cal_friction_result *r, cal_candidate *k);
/// 1 when the candidate's angle is within its tolerance even at its worst: a
/// mean that is not steady is taken unsteady_angle_sds of its own spread
/// (unsteady_sd[0]) farther off. The one rule for "matches the angle": the
/// ranking of candidates (cal_friction_best), the table, report and figures.
int cal_candidate_angle_matched(const cal_candidate *k);
/// A candidate's own uncertainty in measurement j (angle, then CSA per
/// speed), beside the data's and the tier's spreads: a prediction's sd (its
/// source's noise and the correction's kriging sd where it stands), or the
/// spread of a run's series where its mean did not reach steady; 0 for a
/// steady run. The identified ranges' χ² counts it; the report prints it.
double cal_candidate_own_sd(const cal_candidate *k, int j);
/// The candidate the stage's rule chooses among r->cand, -1 if none has an angle.
int cal_friction_best(const cal_friction_result *r);

/// The identified ranges (docs/calibration.md "Identified ranges"): each candidate's χ²
/// against every measurement (the angle by its tolerance, each CSA speed by
/// the lab's and the tier's spreads combined; a failed measurement counts
/// as 5 standard deviations), then every candidate whose χ² is within
/// Δχ² = 3.84 of the smallest (one parameter's 95 % confidence interval,
/// the χ² distribution with 1 degree of freedom) is one the data cannot
/// tell from the best; μs and μr range over those. Needs csa_tier_sd set.
void cal_friction_identify(cal_friction_result *r);

/// The not-excluded interval of μs (rolling = 0) or μr read along the other
/// parameter: bracketed only by excluded candidates whose other parameter lies
/// inside the identified range of that other one (the search bound where none
/// does). The stage's own interval (mu_s_range) lets any excluded pair
/// bracket, so a pair excluded at another μr closes μs; on a grid whose
/// columns share their μr values the two agree, on a two-tier stage's few
/// scattered runs they need not (docs/calibration.md). Reported beside the
/// stage's interval; no status reads it.
cal_range cal_friction_range_along(const cal_friction_result *r, int rolling, const cal_bounds *b);

/// The drum runs stage 2 (material == NULL) or 3 may take at tier t at most:
/// its speeds times beds times (grid points + COBYLA's evaluations + bound
/// probes), or with a map tier times its max_evaluations (the map tier's
/// runs are its own plan); -1 if the data lack the stage's surface (the stage
/// itself then says why).
int cal_friction_planned_runs(const cal_config *c, const cal_tier *t, const cal_series *angles,
                              const cal_series *areas, const cal_material *material);

/// The map tier's name of a stage (level[0]'s), "" for a one-tier stage.
static inline const char *cal_friction_map_tier(const cal_friction_result *r)
{
    return r->n_levels ? r->level[0].tier : "";
}

/// A friction search in progress (targets set from the data, candidates so far).
typedef struct cal_friction_search cal_friction_search;

/// Start a stage's search: out's targets and tolerances from the data; NULL
/// and a message if the data lack them.
cal_friction_search *cal_friction_begin(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                                        const cal_series *areas, double k_n, const cal_material *material,
                                        double gg_mu_s, double gg_mu_r, cal_friction_result *out, char *err, size_t len);
/// Run (or find) the candidate at (mu_s, mu_r); NULL when the store failed.
cal_candidate *cal_friction_evaluate(cal_friction_search *s, double mu_s, double mu_r, const char *origin);
/// The search's bounds (granule or wall).
const cal_bounds *cal_friction_bounds(const cal_friction_search *s);
/// Choose the best, identify the ranges, free the search; 1 with the message
/// if a simulation could not be stored or every candidate failed.
int cal_friction_finish(cal_friction_search *s);

/// The speeds stage 2 (material == NULL) or 3 simulates at tier t, as its
/// search does: the data's CSA speeds for the stage's surface (those of the
/// tier's rpm list, if it has one), then the angle's speed if not among them
/// (in *angle_rpm, unless NULL). How many, or -1 with a message.
int cal_friction_speeds(const cal_config *c, const cal_tier *t, const cal_series *angles, const cal_series *areas,
                        const cal_material *material, double rpm[CAL_MAX_RPM], double *angle_rpm, char *err, size_t len);

/// Stage 2 (material == NULL) or 3 (a material of the config), one tier.
int cal_stage_friction(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, char *err, size_t len);

/// The drum case of the stage r at (mu_s, mu_r) on bed `bed` (seed + bed):
/// what the search runs, and what the report looks up in the store.
cal_drum_case cal_friction_case(const cal_config *c, const cal_tier *t, const cal_friction_result *r, double mu_s,
                                double mu_r, int bed);

/// The unit square's (u, v) as (μs, log μr) within bounds b, and back.
void cal_friction_to_mu(const cal_bounds *b, double u, double v, double *mu_s, double *mu_r);
void cal_friction_to_unit(const cal_bounds *b, double mu_s, double mu_r, double *u, double *v);
/// Speed i's CSA spread in the χ² and the misfit: the lab's (floored) and the
/// tier's in quadrature.
double cal_friction_csa_spread(const cal_friction_result *r, int i);
/// The angle's spread in the χ² and the misfit: its tolerance, floored.
double cal_friction_angle_spread(const cal_friction_result *r);
/// A candidate's measurement vector: its angle, then its CSA at each speed
/// (the order of cal_mf_point.y); 1 if a measurement is missing (failed or
/// unsteady: not a point of any map).
int cal_candidate_vector(const cal_friction_result *r, const cal_candidate *k, double *y);
/// A run's measurement vector for the two-tier loop: as cal_candidate_vector,
/// but a mean that is not steady counts, with its unsteady_sd in sd (0 for a
/// steady one); 1 only if a measurement is missing (every run failed).
int cal_candidate_run_vector(const cal_friction_result *r, const cal_candidate *k, double *y, double *sd);

/// What the two-tier loop minimises on the corrected map, of a predicted
/// measurement vector y (angle, then CSA per speed) whose run would read each
/// within sd: the stage's objective under angle_rule misfit; otherwise the
/// CSA misfit plus a penalty on the angle outside its tolerance band,
/// narrowed by angle_aim_sd × sd[0] (at most to its centre; the tier's key).
/// sd is read only where angle_aim_sd > 0 outside the misfit rule (may be NULL otherwise).
double cal_two_tier_objective(const cal_friction_result *r, const double *y, const double *sd, double angle_aim_sd);

/// The same stage across two tiers (the tier's map_tier maps, the tier itself
/// decides; cal_multifidelity.h): the cheap tier's whole search first (its
/// candidates in cheap_out), then the tier's own runs where the corrected map
/// puts the optimum. A map tier with a map_tier of its own is itself such a
/// stage (levels, run first, deepest first): its result, its runs and its
/// predicted candidates, is the map of the level above.
int cal_stage_two_tier(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, cal_friction_result *cheap_out, char *err, size_t len);

#endif
