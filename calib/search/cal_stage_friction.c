// SPDX-License-Identifier: MIT
// Stages 2 and 3 (sections 4.2, 4.3): find (μs, μr) so that the drum's
// dynamic angle of repose matches the lab's and its occupied-area curve
// (eq. 20) fits best. The paper's three steps (pairs that match the angle;
// their CSA curves; the best of them) as one problem for NLopt's COBYLA:
//   minimise   the CSA misfit           (mean squared, in data standard deviations)
//   subject to |angle - target| <= tol  (tol: the lab's and the tier's spreads combined)
// over μs and log10 μr, scaled to the unit square. A tier whose single-run
// angle noise is as wide as that band (angle_rule: misfit) instead minimises
// one misfit over all measurements: the angle's squared z-score (by the same
// tolerance) averaged with the CSA speeds' (a hard band would let the noise
// choose among the pairs near its edges). A grid over the square
// comes first: it maps the angle over the plane (Fig. 13, 17), shows the
// ambiguity (every pair matching the angle) and starts COBYLA from its best
// point. Every candidate uses the same seed and therefore the same settled
// bed procedure, so the objective is deterministic. After the search, two
// bound probes (the best μs at μr's search bounds) and the identified ranges:
// where the drum cannot tell μr apart (a wall's μr below ~0.03 at the ci
// tier, results/table3_ci/wall_mu_r_response/), the table says over what
// range, not just which point noise picked.
#include <gsl/gsl_cdf.h>
#include <math.h>
#include <nlopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_files.h"
#include "cal_stages.h"
#include "exp_common.h"

/// A speed without a steady measurement costs 5 data standard deviations
/// squared (the search steers away from it without stopping). An unsteady
/// run's mean still says how far off it is: it costs its own squared z-score
/// plus the penalty, so it never scores better than a steady run at the same
/// value (a flat 25 did beat real misfits where the lab's spread is small:
/// the guide's first tiny run chose an unsteady candidate). A failed run,
/// with no value at all, costs the penalty alone.
static const double failed_speed_penalty = 25.0;
/// The lab's CSA spread is floored: a quoted 0 would make one speed dominate.
static const double min_csa_sd = 0.1;
/// Likewise the angle's tolerance where it is a term of the misfit (°).
static const double min_angle_sd = 0.1;

typedef struct cal_friction_search {
    cal_env *env;
    const cal_config *c;
    const cal_tier *t;
    const cal_material *material;
    cal_friction_result *r;
    double sim_rpm[CAL_MAX_RPM]; ///< speeds simulated: the CSA speeds, and the angle's
    int n_sim, angle_index;
    int beds;                    ///< beds (seeds) each candidate is run on and averaged over
    int failed;                  ///< the store failed: stop the search
    nlopt_opt opt;
    double started;              ///< wall clock at the stage's start, for the ETA
    char *err;
    size_t len;
} search;

static double to_mu_s(const cal_bounds *b, double u) { return b->mu_s_min + u * (b->mu_s_max - b->mu_s_min); }
static double to_mu_r(const cal_bounds *b, double v)
{
    return pow(10, log10(b->mu_r_min) + v * (log10(b->mu_r_max) - log10(b->mu_r_min)));
}

void cal_friction_to_mu(const cal_bounds *b, double u, double v, double *mu_s, double *mu_r)
{
    *mu_s = to_mu_s(b, u), *mu_r = to_mu_r(b, v);
}

void cal_friction_to_unit(const cal_bounds *b, double mu_s, double mu_r, double *u, double *v)
{
    *u = (mu_s - b->mu_s_min) / (b->mu_s_max - b->mu_s_min);
    *v = (log10(mu_r) - log10(b->mu_r_min)) / (log10(b->mu_r_max) - log10(b->mu_r_min));
}
static const cal_bounds *bounds_of(const search *s) { return s->material ? &s->c->wall : &s->c->granule; }

// A measurement's squared z-score; plus the penalty where it is not usable
// (unsteady), the penalty alone where there is no value (failed).
static double squared_z(double value, double target, double sd, int usable)
{
    double z = (value - target) / sd;
    if (!isfinite(z)) return failed_speed_penalty;
    return usable ? z * z : z * z + failed_speed_penalty;
}

double cal_friction_angle_spread(const cal_friction_result *r) { return fmax(r->angle_tolerance, min_angle_sd); }

// The angle's squared z-score against its tolerance.
static double angle_z2(const cal_friction_result *r, const cal_candidate *k)
{
    return squared_z(k->angle_deg, r->angle_target, cal_friction_angle_spread(r), 1);
}

// Speed i's CSA spread: the lab's (floored), and the tier's added in quadrature (tier_sd 0: the lab's alone).
static double csa_spread(const cal_friction_result *r, int i, double tier_sd)
{
    double lab = fmax(r->csa_data_sd[i], min_csa_sd);
    return sqrt(lab * lab + tier_sd * tier_sd);
}

double cal_friction_csa_spread(const cal_friction_result *r, int i) { return csa_spread(r, i, r->csa_tier_sd[i]); }

int cal_candidate_run_vector(const cal_friction_result *r, const cal_candidate *k, double *y, double *sd)
{
    for (int j = 0; j < 1 + r->n_rpm; ++j) {
        y[j] = j == 0 ? k->angle_deg : k->csa[j - 1], sd[j] = k->unsteady_sd[j];
        if (!isfinite(y[j])) return 1;
    }
    return 0;
}

int cal_candidate_vector(const cal_friction_result *r, const cal_candidate *k, double *y)
{
    double sd[CAL_MAX_RPM + 1];
    if (cal_candidate_run_vector(r, k, y, sd)) return 1;
    for (int i = 0; i < r->n_rpm; ++i)
        if (!k->usable[i]) return 1; // a speed not steady: not a point of any map
    return 0;
}

// Speed i's CSA squared z-score against the lab's spread alone (the search's
// misfit; the identified ranges add the tier's and the candidate's own).
static double csa_z2(const cal_friction_result *r, const cal_candidate *k, int i)
{
    return squared_z(k->csa[i], r->csa_data[i], csa_spread(r, i, 0), k->usable[i]);
}

void cal_candidate_score(const cal_friction_result *r, cal_candidate *k)
{
    k->angle_violation = isfinite(k->angle_deg) ? fabs(k->angle_deg - r->angle_target) - r->angle_tolerance : 90;
    double sum = 0;
    for (int i = 0; i < r->n_rpm; ++i) sum += csa_z2(r, k, i);
    k->misfit = r->n_rpm ? sum / r->n_rpm : 0;
    k->objective = r->angle_in_misfit ? (angle_z2(r, k) + sum) / (r->n_rpm + 1) : k->misfit;
}

// Speed j's measurement averaged over the candidate's beds (rec: beds ×
// n_sim records, by bed): the angle over the usable runs, the CSA over the
// usable and steady ones; NAN where none is.
typedef struct bed_mean {
    double angle, angle_sd, csa, csa_sd;
    int n_angle, n_csa;
    double csa_unsteady, csa_sd_unsteady; ///< the CSA and its spread over the usable runs, steady or not (NAN: none)
} bed_mean;

static bed_mean mean_over_beds(const search *s, const cal_record *rec, int j)
{
    bed_mean m = {0};
    double any = 0, any_sd = 0;
    for (int b = 0; b < s->beds; ++b) {
        const cal_record *x = &rec[b * s->n_sim + j];
        if (!cal_record_usable(x)) continue;
        m.angle += x->angle_deg, m.angle_sd += x->angle_sd_deg, m.n_angle++;
        any += x->csa_percent, any_sd += x->csa_sd_percent;
        if (x->steady) m.csa += x->csa_percent, m.csa_sd += x->csa_sd_percent, m.n_csa++;
    }
    m.csa_unsteady = m.n_angle ? any / m.n_angle : NAN, m.csa_sd_unsteady = m.n_angle ? any_sd / m.n_angle : NAN;
    m.angle = m.n_angle ? m.angle / m.n_angle : NAN, m.angle_sd = m.n_angle ? m.angle_sd / m.n_angle : NAN;
    m.csa = m.n_csa ? m.csa / m.n_csa : NAN, m.csa_sd = m.n_csa ? m.csa_sd / m.n_csa : NAN;
    return m;
}

// The candidate's measurements from its records (the mean over its beds), then its scores.
static void score(search *s, cal_candidate *k, const cal_record *rec)
{
    cal_friction_result *r = s->r;
    bed_mean a = mean_over_beds(s, rec, s->angle_index);
    k->angle_deg = a.angle, k->angle_sd_deg = a.angle_sd;
    k->unsteady_sd[0] = a.n_csa < a.n_angle ? a.angle_sd : 0; // a bed whose angle speed did not reach steady
    for (int i = 0; i < r->n_rpm; ++i) {
        int x = -1;
        for (int j = 0; j < s->n_sim; ++j)
            if (s->sim_rpm[j] == r->rpm[i]) x = j;
        bed_mean m = x >= 0 ? mean_over_beds(s, rec, x) : (bed_mean){NAN, NAN, NAN, NAN, 0, 0, NAN, NAN};
        k->usable[i] = m.n_csa > 0;
        k->unsteady_sd[1 + i] = k->usable[i] ? 0 : m.csa_sd_unsteady;
        // Not usable: the unsteady runs' mean, for its misfit (squared_z) and the report.
        k->csa[i] = k->usable[i] ? m.csa : m.csa_unsteady, k->csa_sd[i] = m.csa_sd;
    }
    cal_candidate_score(r, k);
}

// Candidates the stage evaluates at most: the grid, the corners, COBYLA's, the bound probes.
static int planned_candidates(const cal_tier *t)
{
    if (t->map_tier) // the two-tier loop's budget, the posterior's and the return's (its map tier plans its own)
        return t->max_evaluations + t->posterior_runs + t->return_runs;
    return t->grid * t->grid + (cal_tier_design_corners(t) ? 4 : 0) + t->max_evaluations + (cal_tier_bound_probes(t) ? 2 : 0);
}

// "candidate i of at most N" (or "candidates i-j"), with the time left at the
// cost of the candidates so far. That cost is their records' (as the whole
// calibration's ETA, cal_progress.h), not this process's clock: a resumed
// stage whose candidates came from the store has spent no time on them.
static void show_start(const search *s, const double (*mu)[2], int m)
{
    int planned = planned_candidates(s->t), done = s->r->n;
    int parallel = s->env->progress ? s->env->progress->parallel : s->env->workers;
    double core_s_each = done > 0 ? s->r->core_s / done : 0;
    char eta[48] = "", which[32];
    if (core_s_each > 0)
        snprintf(eta, sizeof eta, ", stage ETA %.0f s", core_s_each * fmax(0, planned - done) / fmax(1, parallel));
    if (m == 1) snprintf(which, sizeof which, "candidate %d", done + 1);
    else snprintf(which, sizeof which, "candidates %d-%d", done + 1, done + m);
    fprintf(stderr, "%s[%s] %s of at most %d: ", s->env->tty ? "\r\033[K" : "", s->env->stage, which, planned);
    for (int j = 0; j < m; ++j) fprintf(stderr, "%smu_s = %.4g, mu_r = %.4g", j ? "; " : "", mu[j][0], mu[j][1]);
    fprintf(stderr, " (%d speeds%s%s)%s", s->n_sim, m > 1 ? " each, side by side" : "", eta, s->env->tty ? "" : "\n");
}

static int same_value(double a, double b) { return fabs(a - b) <= 1e-12 * fmax(fabs(a), fabs(b)); }

// The candidate at (mu_s, mu_r) if evaluated before (COBYLA revisits, a probe at a grid point).
static cal_candidate *seen(cal_friction_result *r, double mu_s, double mu_r)
{
    for (int i = 0; i < r->n; ++i)
        if (same_value(r->cand[i].mu_s, mu_s) && same_value(r->cand[i].mu_r, mu_r)) return &r->cand[i];
    return NULL;
}

// A new candidate from its records (released here).
static void add_candidate(search *s, double mu_s, double mu_r, const char *origin, cal_record *rec, double elapsed,
                          int together)
{
    cal_friction_result *r = s->r;
    cal_candidate *k = &r->cand[r->n++];
    memset(k, 0, sizeof *k);
    k->mu_s = mu_s, k->mu_r = mu_r, k->origin = origin;
    score(s, k, rec);
    for (int i = 0; i < s->beds * s->n_sim; ++i) // turning, and settling where this candidate settled a bed
        k->wall_time_s += cal_record_cost_s(&rec[i]), cal_record_free(&rec[i]);
    r->simulations += s->beds * s->n_sim, r->core_s += k->wall_time_s;
    char with_angle[48] = "", took[48];
    if (r->angle_in_misfit) snprintf(with_angle, sizeof with_angle, ", with the angle %.3g", k->objective);
    if (together > 1) snprintf(took, sizeof took, "%.0f s for the %d together", elapsed, together);
    else snprintf(took, sizeof took, "%.0f s", elapsed);
    fprintf(stderr, "%s[%s] candidate %d: mu_s = %.4g, mu_r = %.4g: angle %.2f° (target %.2f ± %.2f), CSA misfit %.3g%s (%s)\n",
            s->env->tty ? "\r\033[K" : "", s->env->stage, r->n, mu_s, mu_r, k->angle_deg, r->angle_target,
            r->angle_tolerance, k->misfit, with_angle, took);
}

// Candidates at m (μs, μr) points, simulated together (the grid, the bound
// probes: independent points whose runs can share the workers). A point
// evaluated before, or twice in the list, is simulated once.
static void evaluate_points(search *s, const double (*mu)[2], int m, const char *origin)
{
    cal_friction_result *r = s->r;
    double(*fresh)[2] = calloc((size_t)m, sizeof *fresh);
    cal_drum_case *cases = calloc((size_t)(m * s->beds), sizeof *cases);
    cal_record *rec = calloc((size_t)(m * s->beds) * (size_t)s->n_sim, sizeof *rec);
    int n = 0;
    if (!fresh || !cases || !rec) s->failed = 1, exp_fail(s->err, s->len, "out of memory");
    for (int p = 0; p < m && !s->failed; ++p) {
        int again = seen(r, mu[p][0], mu[p][1]) != NULL;
        for (int q = 0; q < n; ++q) again |= same_value(fresh[q][0], mu[p][0]) && same_value(fresh[q][1], mu[p][1]);
        if (again || r->n + n >= CAL_MAX_EVALS) continue;
        fresh[n][0] = mu[p][0], fresh[n][1] = mu[p][1];
        for (int b = 0; b < s->beds; ++b) cases[n * s->beds + b] = cal_friction_case(s->c, s->t, r, mu[p][0], mu[p][1], b);
        n++;
    }
    if (n > 0 && !s->failed) {
        double t0 = exp_wall_seconds();
        show_start(s, (const double(*)[2])fresh, n);
        if (cal_drum_evaluate_many(s->env, cases, n * s->beds, s->sim_rpm, s->n_sim, rec, s->err, s->len)) s->failed = 1;
        double elapsed = exp_wall_seconds() - t0;
        for (int j = 0; j < n && !s->failed; ++j)
            add_candidate(s, fresh[j][0], fresh[j][1], origin, rec + j * s->beds * s->n_sim, elapsed, n);
    }
    free(fresh), free(cases), free(rec);
}

cal_drum_case cal_friction_case(const cal_config *c, const cal_tier *t, const cal_friction_result *r, double mu_s,
                                double mu_r, int bed)
{
    cal_drum_case d = r->material[0] ? cal_drum_case_wall(c, t, r->k_n, r->frozen_mu_s, r->frozen_mu_r, mu_s, mu_r)
                                     : cal_drum_case_granule(c, t, r->k_n, mu_s, mu_r);
    cal_drum_case_set_seed(&d, (uint64_t)(c->seed + bed)); // bed 0: the config's seed, a one-bed tier's run
    return d;
}

static cal_candidate *evaluate(search *s, double mu_s, double mu_r, const char *origin)
{
    const double point[1][2] = {{mu_s, mu_r}};
    evaluate_points(s, point, 1, origin);
    return seen(s->r, mu_s, mu_r);
}

// COBYLA's point of the unit square (μs linear, log10 μr).
static cal_candidate *evaluate_unit(search *s, const double *x, const char *origin)
{
    const cal_bounds *b = bounds_of(s);
    return evaluate(s, to_mu_s(b, x[0]), to_mu_r(b, x[1]), origin);
}

static double objective(unsigned n, const double *x, double *grad, void *ctx)
{
    (void)n, (void)grad;
    search *s = ctx;
    cal_candidate *k = evaluate_unit(s, x, "COBYLA");
    if (!k) return nlopt_force_stop(s->opt), HUGE_VAL;
    return k->objective;
}

static double angle_constraint(unsigned n, const double *x, double *grad, void *ctx)
{
    (void)n, (void)grad;
    search *s = ctx;
    cal_candidate *k = evaluate_unit(s, x, "COBYLA"); // the same point as the objective: from the list
    return k ? k->angle_violation : 0;
}

/// How many of its own standard deviations an unsteady angle is taken to be
/// off, at worst, when candidates are ranked: about a 95 % bound.
static const double unsteady_angle_sds = 2.0;

// The angle's violation as the ranking sees it: a mean that is not steady is
// known only to its own spread (unsteady_sd[0]), so it is ranked by how far
// it may be, not by where it happens to stand. The standard rerun's granule
// stage froze a run at 38.81 ± 4.64° (not steady) as "closest" to 34.60 ±
// 0.56°, against a steady run 3.74° off (results/calibration-standard-r2/).
static double ranked_violation(const cal_candidate *k)
{
    return k->angle_violation + unsteady_angle_sds * k->unsteady_sd[0];
}

int cal_candidate_angle_matched(const cal_candidate *k) { return ranked_violation(k) <= 0; }

// Feasible candidates first, by misfit; else the least violation (an
// unsteady angle's at worst). With the angle in the misfit: by that misfit
// alone (an unsteady angle already costs its penalty there).
static int better(const cal_friction_result *r, const cal_candidate *a, const cal_candidate *b)
{
    if (r->angle_in_misfit) return a->objective < b->objective;
    double va = ranked_violation(a), vb = ranked_violation(b);
    int fa = va <= 0, fb = vb <= 0;
    if (fa != fb) return fa;
    return fa ? a->misfit < b->misfit : va < vb;
}

int cal_friction_best(const cal_friction_result *r)
{
    int best = -1;
    for (int i = 0; i < r->n; ++i)
        if (!r->cand[i].predicted && isfinite(r->cand[i].angle_deg) && (best < 0 || better(r, &r->cand[i], &r->cand[best])))
            best = i;
    return best;
}

// ---- what the data identify ----------------------------------------------------

double cal_candidate_own_sd(const cal_candidate *k, int j) { return k->predicted ? k->predicted_sd[j] : k->unsteady_sd[j]; }

// χ² against every measurement, each by its whole spread: the angle by its
// tolerance (lab and tier), each CSA speed by the lab's and the tier's
// spreads, and the candidate's own uncertainty (cal_candidate_own_sd), in quadrature. A
// prediction is no measurement: counted as exact, the standard rerun's
// corrected map, far from its runs, read -44° at (0.325, 0.0047) where its
// own sd was 25°, and its guess of 30.97° at (0.775, 0.106) set the least χ²
// against which every run that measured was "told apart".
static double chi2_of(const cal_friction_result *r, const cal_candidate *k)
{
    double sum = squared_z(k->angle_deg, r->angle_target, hypot(cal_friction_angle_spread(r), cal_candidate_own_sd(k, 0)), 1);
    for (int i = 0; i < r->n_rpm; ++i)
        sum += squared_z(k->csa[i], r->csa_data[i], hypot(cal_friction_csa_spread(r, i), cal_candidate_own_sd(k, 1 + i)),
                         k->usable[i]);
    return sum;
}

// μs (rolling = 0) or μr over the identified candidates, and the nearest
// excluded value beyond each end; with `along`, only of excluded candidates
// whose other parameter lies inside the identified range of that other one.
static cal_range range_of(const cal_friction_result *r, int rolling, int along)
{
    cal_range g = {INFINITY, -INFINITY, NAN, NAN, NAN, NAN};
    double other_lo = INFINITY, other_hi = -INFINITY;
    for (int i = 0; i < r->n; ++i)
        if (r->cand[i].identified) {
            double v = rolling ? r->cand[i].mu_r : r->cand[i].mu_s, o = rolling ? r->cand[i].mu_s : r->cand[i].mu_r;
            g.lo = fmin(g.lo, v), g.hi = fmax(g.hi, v);
            other_lo = fmin(other_lo, o), other_hi = fmax(other_hi, o);
        }
    if (!(g.lo <= g.hi)) return CAL_NO_RANGE;
    for (int i = 0; i < r->n; ++i) {
        double v = rolling ? r->cand[i].mu_r : r->cand[i].mu_s, o = rolling ? r->cand[i].mu_s : r->cand[i].mu_r;
        if (r->cand[i].identified || (along && !(o >= other_lo && o <= other_hi))) continue;
        if (v < g.lo && !(v <= g.below)) g.below = v; // the largest value below
        if (v > g.hi && !(v >= g.above)) g.above = v; // the smallest above
    }
    return g;
}

void cal_range_bracket(cal_range *g, double bound_lo, double bound_hi)
{
    if (!isfinite(g->lo)) return;
    g->bracket_lo = isfinite(g->below) ? g->below : bound_lo;
    g->bracket_hi = isfinite(g->above) ? g->above : bound_hi;
}

void cal_friction_identify(cal_friction_result *r)
{
    r->chi2_threshold = gsl_cdf_chisq_Qinv(0.05, 1); // 3.84
    // The least χ² is a run's (a prediction's, where no run has one): a
    // prediction's χ² counts its own sd, so it may fit "better" than any
    // run only because the map does not know there; that widens what is not
    // excluded, and must not exclude the runs that measured.
    r->chi2_least = INFINITY;
    int runs = 0;
    for (int i = 0; i < r->n; ++i) r->cand[i].chi2 = chi2_of(r, &r->cand[i]), runs += !r->cand[i].predicted;
    for (int i = 0; i < r->n; ++i)
        if (!runs || !r->cand[i].predicted) r->chi2_least = fmin(r->chi2_least, r->cand[i].chi2);
    r->identified_count = 0;
    for (int i = 0; i < r->n; ++i) {
        r->cand[i].identified = r->cand[i].chi2 - r->chi2_least <= r->chi2_threshold;
        r->identified_count += r->cand[i].identified;
    }
    r->mu_s_range = range_of(r, 0, 0), r->mu_r_range = range_of(r, 1, 0);
}

cal_range cal_friction_range_along(const cal_friction_result *r, int rolling, const cal_bounds *b)
{
    cal_range g = range_of(r, rolling, 1);
    cal_range_bracket(&g, rolling ? b->mu_r_min : b->mu_s_min, rolling ? b->mu_r_max : b->mu_s_max);
    return g;
}

static const char *run_cobyla(search *s)
{
    int start = cal_friction_best(s->r);
    if (s->t->max_evaluations < 1) return "not run (max_evaluations = 0)";
    nlopt_opt opt = s->opt = nlopt_create(NLOPT_LN_COBYLA, 2);
    double lo[2] = {0, 0}, hi[2] = {1, 1}, x[2] = {0.5, 0.5}, fx;
    double step = s->t->grid > 1 ? 0.5 / s->t->grid : 0.25;
    double dx[2] = {step, step};
    if (start >= 0) cal_friction_to_unit(bounds_of(s), s->r->cand[start].mu_s, s->r->cand[start].mu_r, &x[0], &x[1]);
    nlopt_set_lower_bounds(opt, lo), nlopt_set_upper_bounds(opt, hi);
    nlopt_set_min_objective(opt, objective, s);
    if (!s->r->angle_in_misfit) nlopt_add_inequality_constraint(opt, angle_constraint, s, 0.0);
    nlopt_set_initial_step(opt, dx);
    nlopt_set_xtol_abs1(opt, 0.01); // 1 % of each range: finer than the drum can resolve at any tier
    nlopt_set_maxeval(opt, s->t->max_evaluations);
    nlopt_result res = nlopt_optimize(opt, x, &fx);
    nlopt_destroy(opt);
    switch (res) {
    case NLOPT_XTOL_REACHED: return "converged (step below 1 % of the ranges)";
    case NLOPT_MAXEVAL_REACHED: return "stopped at max_evaluations";
    case NLOPT_FORCED_STOP: return "stopped: a simulation could not be stored";
    default: return res > 0 ? "converged" : "NLopt failed";
    }
}

// The initial design: grid × grid points at the centres of the unit square's
// cells, simulated together.
static void evaluate_grid(search *s)
{
    int g = s->t->grid, m = 0;
    if (g < 1) return;
    double(*mu)[2] = calloc((size_t)(g * g), sizeof *mu);
    if (!mu) return (void)(s->failed = 1, exp_fail(s->err, s->len, "out of memory"));
    const cal_bounds *b = bounds_of(s);
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < g; ++j) mu[m][0] = to_mu_s(b, (i + 0.5) / g), mu[m++][1] = to_mu_r(b, (j + 0.5) / g);
    evaluate_points(s, (const double(*)[2])mu, m, "grid");
    free(mu);
}

// The search box's four corners (design_corners), simulated together: with
// them a map made from this tier's candidates spans the whole box.
static void evaluate_corners(search *s)
{
    const cal_bounds *b = bounds_of(s);
    const double corners[4][2] = {{b->mu_s_min, b->mu_r_min}, {b->mu_s_min, b->mu_r_max},
                                  {b->mu_s_max, b->mu_r_min}, {b->mu_s_max, b->mu_r_max}};
    evaluate_points(s, corners, 4, "corner");
}

// After the search, the best μs with μr at each search bound: whether the
// data bound μr on each side, or the identified range reaches the bound.
static void probe_bounds(search *s)
{
    int best = cal_friction_best(s->r);
    if (best < 0) return;
    const cal_bounds *b = bounds_of(s);
    double mu_s = s->r->cand[best].mu_s;
    const double probes[2][2] = {{mu_s, b->mu_r_min}, {mu_s, b->mu_r_max}};
    evaluate_points(s, probes, 2, "bound probe");
}

// Where a speed is in the tier's rpm list (0 when the tier takes every speed).
static unsigned tier_index_of(const cal_tier *t, double rpm)
{
    for (unsigned j = 0; j < t->rpm_count; ++j)
        if (t->rpm[j] == rpm) return j;
    return 0;
}

// The speeds to simulate, the targets and tolerances, from the data files.
static int set_targets(search *s, const cal_series *angles, const cal_series *areas)
{
    cal_friction_result *r = s->r;
    const cal_point *pts[64];
    size_t n = cal_series_select(angles, r->surface, pts, 64);
    if (n == 0) return exp_fail(s->err, s->len, "%s: no angle of repose for surface '%s'", angles->path, r->surface);
    // The data's angle as it is: a coarse tier's bias against the lab (its
    // granules pile steeper, Table B.1) is not corrected here by a number
    // measured at any known answer; the tier's table is the tier's.
    r->angle_target = pts[0]->value, r->angle_rpm = pts[0]->rpm;
    r->angle_source = (cal_provenance){angles->synthetic, angles->synthetic_lambda};
    r->csa_source = (cal_provenance){areas->synthetic, areas->synthetic_lambda};
    // The tier's spreads are one bed's; a candidate is the mean of its beds.
    double per_bed = 1 / sqrt(cal_tier_beds(s->t)), tier_angle_sd = s->t->angle_sd_deg * per_bed;
    r->angle_tolerance = sqrt(pts[0]->sd * pts[0]->sd + tier_angle_sd * tier_angle_sd);
    n = cal_series_select(areas, r->surface, pts, 64);
    if (n == 0) return exp_fail(s->err, s->len, "%s: no occupied area for surface '%s'", areas->path, r->surface);
    for (size_t i = 0; i < n; ++i) {
        int wanted = s->t->rpm_count == 0;
        for (unsigned j = 0; j < s->t->rpm_count; ++j) wanted |= s->t->rpm[j] == pts[i]->rpm;
        if (!wanted) continue;
        if (r->n_rpm == CAL_MAX_RPM) return exp_fail(s->err, s->len, "at most %d speeds", CAL_MAX_RPM);
        r->rpm[r->n_rpm] = pts[i]->rpm, r->csa_data[r->n_rpm] = pts[i]->value, r->csa_data_sd[r->n_rpm] = pts[i]->sd;
        r->csa_tier_sd[r->n_rpm] = cal_tier_csa_sd(s->t, tier_index_of(s->t, pts[i]->rpm)) * per_bed;
        s->sim_rpm[s->n_sim++] = pts[i]->rpm;
        r->n_rpm++;
    }
    if (r->n_rpm == 0) return exp_fail(s->err, s->len, "tier '%s': none of its speeds is in %s for '%s'", s->t->name, areas->path, r->surface);
    s->angle_index = -1;
    for (int j = 0; j < s->n_sim; ++j)
        if (s->sim_rpm[j] == r->angle_rpm) s->angle_index = j;
    if (s->angle_index < 0) s->angle_index = s->n_sim, s->sim_rpm[s->n_sim++] = r->angle_rpm;
    return 0;
}

int cal_friction_speeds(const cal_config *c, const cal_tier *t, const cal_series *angles, const cal_series *areas,
                        const cal_material *material, double rpm[CAL_MAX_RPM], double *angle_rpm, char *err, size_t len)
{
    cal_friction_result *r = calloc(1, sizeof *r);
    if (!r) return exp_fail(err, len, "out of memory"), -1;
    snprintf(r->surface, sizeof r->surface, "%s", material ? material->surface : c->granule_surface);
    search s = {.c = c, .t = t, .material = material, .r = r, .err = err, .len = len};
    int n = set_targets(&s, angles, areas) ? -1 : s.n_sim;
    for (int k = 0; k < n; ++k) rpm[k] = s.sim_rpm[k];
    if (n >= 0 && angle_rpm) *angle_rpm = r->angle_rpm;
    free(r);
    return n;
}

int cal_friction_planned_runs(const cal_config *c, const cal_tier *t, const cal_series *angles,
                              const cal_series *areas, const cal_material *material)
{
    double rpm[CAL_MAX_RPM];
    char err[512];
    int speeds = cal_friction_speeds(c, t, angles, areas, material, rpm, NULL, err, sizeof err);
    return speeds < 0 ? -1 : speeds * planned_candidates(t) * cal_tier_beds(t);
}

// The stage's search with its targets set: what a one-tier stage and the
// two-tier stage (cal_stage_two_tier.c) both start from.
cal_friction_search *cal_friction_begin(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                                        const cal_series *areas, double k_n, const cal_material *material,
                                        double gg_mu_s, double gg_mu_r, cal_friction_result *out, char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    snprintf(out->material, sizeof out->material, "%s", material ? material->name : "");
    snprintf(out->surface, sizeof out->surface, "%s", material ? material->surface : c->granule_surface);
    out->k_n = k_n, out->frozen_mu_s = gg_mu_s, out->frozen_mu_r = gg_mu_r;
    out->angle_in_misfit = cal_tier_angle_in_misfit(t);
    search *s = calloc(1, sizeof *s);
    if (!s) return exp_fail(err, len, "out of memory"), NULL;
    *s = (search){.env = env, .c = c, .t = t, .material = material, .r = out, .err = err, .len = len,
                  .started = exp_wall_seconds(), .beds = cal_tier_beds(t)};
    if (set_targets(s, angles, areas)) return free(s), NULL;
    return s;
}

cal_candidate *cal_friction_evaluate(cal_friction_search *s, double mu_s, double mu_r, const char *origin)
{
    return s->failed ? NULL : evaluate(s, mu_s, mu_r, origin);
}

const cal_bounds *cal_friction_bounds(const cal_friction_search *s) { return bounds_of(s); }

int cal_friction_finish(cal_friction_search *s)
{
    cal_friction_result *out = s->r;
    out->best = cal_friction_best(out);
    cal_friction_identify(out);
    const cal_bounds *b = bounds_of(s);
    cal_range_bracket(&out->mu_s_range, b->mu_s_min, b->mu_s_max);
    cal_range_bracket(&out->mu_r_range, b->mu_r_min, b->mu_r_max);
    out->best_feasible = out->best >= 0 && cal_candidate_angle_matched(&out->cand[out->best]);
    out->wall_time_s = exp_wall_seconds() - s->started;
    int failed = s->failed;
    if (!failed && out->best < 0) failed = exp_fail(s->err, s->len, "%s: every candidate failed; see simulations.csv", s->env->stage);
    free(s);
    return failed != 0;
}

int cal_stage_friction(cal_env *env, const cal_config *c, const cal_tier *t, const cal_series *angles,
                       const cal_series *areas, double k_n, const cal_material *material, double gg_mu_s,
                       double gg_mu_r, cal_friction_result *out, char *err, size_t len)
{
    cal_env_set_stage(env, material ? material->name : "granule");
    cal_progress_enter(env->progress, env->stage);
    search *s = cal_friction_begin(env, c, t, angles, areas, k_n, material, gg_mu_s, gg_mu_r, out, err, len);
    if (!s) return 1;
    evaluate_grid(s);
    if (cal_tier_design_corners(t)) evaluate_corners(s); // nothing runs once a batch failed (evaluate_points)
    out->nlopt_result = s->failed ? "not run" : run_cobyla(s);
    if (cal_tier_bound_probes(t)) probe_bounds(s);
    return cal_friction_finish(s);
}
