// SPDX-License-Identifier: MIT
/// @file cal_multifidelity.h
/// A friction search across two fidelities. A cheap tier maps the response
/// (the angle and the CSA at each speed) over the unit square of (μs, log μr);
/// a quadratic least-squares surface through those points is the map. The
/// expensive (converged) tier is run only where the map says the optimum is,
/// and at each such point the program measures the discrepancy between the
/// two tiers; the map, corrected by the discrepancy so far (per measurement:
/// a plane fitted to it and, by default, a kriging interpolation of what the
/// plane leaves, cal_mf_correction_kind), gives the next optimum. The search ends when
/// an expensive run agrees with what the corrected map predicted for it
/// within the data's noise, or its budget of expensive runs is spent.
///
/// Nothing here knows about drums: the stage gives the objective of a
/// measurement vector and a function that runs the expensive tier, so the
/// loop is tested on analytic responses (tests/unit/test_multifidelity.c).
#ifndef CAL_MULTIFIDELITY_H
#define CAL_MULTIFIDELITY_H

enum { CAL_MF_MAX_Y = 17, CAL_MF_MAX_FINE = 64, CAL_MF_TERMS = 6 };

/// Measurements at one point of the unit square (u: μs, v: log μr).
typedef struct cal_mf_point {
    double u, v;
    double y[CAL_MF_MAX_Y]; ///< angle first, then the CSA at each speed
    /// An expensive run's own error per measurement where it exceeds the
    /// problem's run_noise (a mean that did not reach its steady state); 0:
    /// the run_noise. Map points leave it 0.
    double sd[CAL_MF_MAX_Y];
} cal_mf_point;

/// The map: per measurement, coefficients of 1, u, v, u², uv, v² (the last
/// three 0 where too few points for a quadratic), and its rms residual.
typedef struct cal_mf_map {
    int n_y, n_terms;
    double coef[CAL_MF_MAX_Y][CAL_MF_TERMS];
    double rms[CAL_MF_MAX_Y];
} cal_mf_map;

/// Least squares through n points: quadratic with n >= 8 (two points per
/// coefficient beyond the linear ones), linear with n >= 3; 1 (and nothing
/// fitted) with fewer or a singular design.
int cal_mf_fit(const cal_mf_point *pts, int n, int n_y, cal_mf_map *map);

/// The same fit weighted: point i's measurement k counts by 1/sd[i][k]² (each
/// sd > 0), and rms is the weighted rms residual, sqrt(Σ e²/sd² / Σ 1/sd²).
/// For points of unequal trust: a level of a multilevel search fits its map on
/// the level below's runs and on its predictions, which are no measurements
/// (cal_stage_two_tier). sd NULL: cal_mf_fit.
int cal_mf_fit_weighted(const cal_mf_point *pts, const double (*sd)[CAL_MF_MAX_Y], int n, int n_y, cal_mf_map *map);

/// The map at (u, v).
void cal_mf_predict(const cal_mf_map *map, double u, double v, double *y);

/// How the discrepancy measured at the expensive runs is carried over the
/// square. AFFINE: least squares of a plane (its mean at the runs' centre, and
/// its slope along each direction three runs or more span), which does not
/// pass through the runs when the discrepancy curves between them. KRIGING:
/// that plane plus a Gaussian-process interpolation of its residuals (the
/// plane is the kriging trend), so the corrected map goes through every run
/// up to the runs' noise, and far from them falls back to the plane.
typedef enum cal_mf_correction_kind { CAL_MF_KRIGING = 0, CAL_MF_AFFINE = 1 } cal_mf_correction_kind;

/// "kriging" or "affine", as a config names it.
const char *cal_mf_correction_name(cal_mf_correction_kind kind);

/// Length of the kriging kernel exp(-d²/2ℓ²) in the unit square: the
/// discrepancy is taken to be smooth over a quarter of the search range.
#define CAL_MF_KRIGING_LENGTH 0.25

/// The measured discrepancy between the tiers, per measurement: its value
/// at (u0, v0), the runs' centre, and its slopes along u and v (0 along a
/// direction the runs do not span by 0.05, or with fewer than three runs);
/// with kriging, the kernel weights of the runs' residuals from that plane.
typedef struct cal_mf_correction {
    double at[CAL_MF_MAX_Y], du[CAL_MF_MAX_Y], dv[CAL_MF_MAX_Y];
    double u0, v0;
    int n_runs; ///< runs carrying kernel weights (0: the plane alone)
    double run_u[CAL_MF_MAX_FINE], run_v[CAL_MF_MAX_FINE];
    double weight[CAL_MF_MAX_Y][CAL_MF_MAX_FINE];
    /// The kriging's scale per measurement (the residuals' rms, at least the
    /// runs' noise) and each run's nugget ratio (its noise over that scale,
    /// squared), for its variance (cal_mf_correction_sd); scale 0: no kriging
    /// (the plane alone, or a system GSL could not factor).
    double scale[CAL_MF_MAX_Y], nugget[CAL_MF_MAX_Y][CAL_MF_MAX_FINE];
} cal_mf_correction;

/// Add the correction at (u, v) to y (n_y measurements); c NULL: nothing.
void cal_mf_correct(const cal_mf_correction *c, int n_y, double u, double v, double *y);

/// The kriging's own standard deviation of measurement k's correction at
/// (u, v): scale·sqrt(1 − kᵀ(K + nugget·I)⁻¹k), near 0 at a run (up to its
/// noise) and the scale far from every run. 0 where there is no kriging (c
/// NULL, fewer than two runs, or scale 0): the plane alone carries no
/// variance model.
double cal_mf_correction_sd(const cal_mf_correction *c, int k, double u, double v);

/// Why the correction carries no variance model for some of its n_y
/// measurements, NULL when the kriging's covers every one (kriging: 1 for a
/// kriging correction, 0 for an affine one): "an affine correction", "one run
/// at this tier (kriging needs two)", or "a kriging GSL could not factor".
/// Without one, cal_mf_correction_sd is 0 and whatever samples the corrected
/// map (the posterior) takes the correction as exact.
const char *cal_mf_correction_unmodelled(const cal_mf_correction *c, int n_y, int kriging);

/// What the stage gives the loop.
typedef struct cal_mf_problem {
    int n_y;
    /// What the search minimises, of a predicted measurement vector y and, per
    /// measurement, the sd of what a run there would read: the run noise and
    /// the kriging's sd of the correction where it stands, in quadrature.
    double (*objective)(const double *y, const double *sd, void *ctx);
    /// Whether the objective reads sd; 0: it is handed NULL, and the kriging's
    /// variance (a Cholesky solve per measurement) is not computed for it.
    int objective_uses_sd;
    /// Run the expensive tier at (u, v): run->y filled, and run->sd where a
    /// measurement's own error exceeds run_noise (a mean that is not steady:
    /// it enters the correction weighed by that error, and the run cannot
    /// agree); 0. A measurement it could not make at all: NAN, and the run
    /// neither agrees nor enters the correction. Nonzero when the run could
    /// not be done at all (the loop stops).
    int (*run_expensive)(double u, double v, cal_mf_point *run, void *ctx);
    const double *noise; ///< per measurement: how far a run may be from the prediction and agree
    /// Per measurement: the expensive runs' own noise (the tier's seed spread
    /// of a candidate), which kriging smooths rather than interpolates; NULL: 0.
    const double *run_noise;
    int max_expensive;   ///< budget of expensive runs (≤ CAL_MF_MAX_FINE)
    cal_mf_correction_kind correction;
    void *ctx;
} cal_mf_problem;

typedef struct cal_mf_result {
    int n;                                   ///< expensive runs made
    cal_mf_point run[CAL_MF_MAX_FINE];       ///< where, and what they measured
    double predicted[CAL_MF_MAX_FINE][CAL_MF_MAX_Y]; ///< what the corrected map said before each run
    cal_mf_correction correction;            ///< after the last run
    double delta[CAL_MF_MAX_Y];              ///< that correction at the last run's point
    int agreed;                              ///< 1: the last run agreed with its prediction
    int settled;                             ///< 1: the next optimum was a point already run (stopped there)
    int settled_noisy;                       ///< 1: settled on a run with an error of its own (not steady)
    int unmeasured;                          ///< 1: settled on a run that measured nothing usable
    int failed;                              ///< 1: an expensive run failed
    double u_uncorrected, v_uncorrected;     ///< the cheap map's own optimum
} cal_mf_result;

/// The loop above; it also stops when the corrected optimum lands within 0.01
/// of a point already run (a deterministic run there would repeat itself).
/// Returns 0; out->failed says whether a run failed.
int cal_mf_search(const cal_mf_map *cheap, const cal_mf_problem *p, cal_mf_result *out);

/// Where the stage wants one more expensive run after the search, given the
/// correction so far: 0 with (u, v), nonzero for none.
typedef int (*cal_mf_next_point)(const cal_mf_correction *c, double *u, double *v, void *ctx);

/// After cal_mf_search: up to `more` further runs, each where next() asks,
/// appended to out->run with the correction refitted after each (agreed and
/// delta then speak of the last of them). It stops early when next()
/// declines, asks for a point already run (within 0.01) or a run fails.
/// Returns why it stopped, for the report.
const char *cal_mf_refine(const cal_mf_map *cheap, const cal_mf_problem *p, int more, cal_mf_next_point next, void *ctx,
                          cal_mf_result *out);

/// After cal_mf_refine: the loop resumed from where out stands, up to `more`
/// runs at the corrected map's optimum, as cal_mf_search makes them. Runs made
/// where something else asked (the posterior) move the correction, and the
/// optimum with it; without this the stage would end on an optimum no run
/// checked. out->agreed, settled, settled_noisy and unmeasured then speak of
/// this resumed loop (all 0 on entry). Returns the runs it made (0 where a run
/// already failed, more is 0, or the optimum is a point already run).
int cal_mf_return(const cal_mf_map *cheap, const cal_mf_problem *p, int more, cal_mf_result *out);
/// The corrected map's optimum over the unit square (a 41 × 41 scan, then
/// NLopt BOBYQA from its best point).
void cal_mf_optimum(const cal_mf_map *map, const cal_mf_correction *c, const cal_mf_problem *p, double *u, double *v);

#endif
