// SPDX-License-Identifier: MIT
/// @file cal_stages.h
/// The three stages of the calibration (the paper's section 4):
///   1. stiffness: coordination number of a poured cylinder against k_n;
///   2. granule–granule (μs, μr) in the drum lined with granules;
///   3. each wall material's (μs, μr), granule–granule frozen.
#ifndef CAL_STAGES_H
#define CAL_STAGES_H

#include "cal_config.h"
#include "cal_data.h"
#include "cal_sim.h"

enum { CAL_MAX_K = 64, CAL_MAX_EVALS = 512, CAL_MAX_RPM = 16 };

typedef struct cal_stiffness_result {
    int n;                       ///< stiffness candidates
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
    const char *origin;                 ///< "grid", "COBYLA" or "bound probe"
    double chi2;                        ///< χ² against the data with the lab's and the tier's spreads (identification)
    int identified;                     ///< 1 if the data cannot tell it from the best χ² (Δχ² within the threshold)
    double wall_time_s;
} cal_candidate;

/// The range of one parameter over the candidates the data cannot tell apart.
typedef struct cal_range {
    double lo, hi;       ///< smallest and largest value among them
    double below, above; ///< the nearest excluded candidate's value beyond each end; NAN: none evaluated there
} cal_range;

/// What a friction stage found.
typedef struct cal_friction_result {
    char material[32];                  ///< "" for granule–granule
    char surface[64];
    double k_n;
    double frozen_mu_s, frozen_mu_r;    ///< granule–granule pair (wall stage)
    double angle_target, angle_tolerance, angle_rpm; ///< target in the tier's scale: lab + offset
    double angle_lab, angle_offset;                  ///< the lab's angle and the tier's offset
    int angle_in_misfit;                             ///< the tier's angle_rule is "misfit"
    int n_rpm;
    double rpm[CAL_MAX_RPM], csa_data[CAL_MAX_RPM], csa_data_sd[CAL_MAX_RPM];
    double csa_tier_sd[CAL_MAX_RPM];    ///< the tier's measured seed spread at each speed (0: not measured)
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
} cal_friction_result;

/// A candidate's scores from its measurements (angle_deg, csa, usable):
/// angle_violation, the CSA misfit and the search's objective, by the rule
/// in r (angle_in_misfit, targets, tolerance, data).
void cal_candidate_score(const cal_friction_result *r, cal_candidate *k);
/// The candidate the stage's rule chooses among r->cand, -1 if none has an angle.
int cal_friction_best(const cal_friction_result *r);

/// The identified ranges (README "Identified ranges"): each candidate's χ²
/// against every measurement (the angle by its tolerance, each CSA speed by
/// the lab's and the tier's spreads combined; a failed measurement counts
/// as 5 standard deviations), then every candidate whose χ² is within
/// Δχ² = 3.84 of the smallest (one parameter's 95 % confidence interval,
/// the χ² distribution with 1 degree of freedom) is one the data cannot
/// tell from the best; μs and μr range over those. Needs csa_tier_sd set.
void cal_friction_identify(cal_friction_result *r);

/// The drum runs stage 2 (material == NULL) or 3 may take at most: its
/// speeds times (grid points + COBYLA's evaluations + bound probes); -1 if
/// the data lack the stage's surface (the stage itself then says why).
int cal_friction_planned_runs(const cal_config *c, const cal_tier *t, const cal_series *angles,
                              const cal_series *areas, const cal_material *material);

/// Stage 2 (material == NULL) or 3 (a material of the config).
int cal_stage_friction(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, char *err, size_t len);

#endif
