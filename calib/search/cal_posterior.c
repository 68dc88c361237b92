// SPDX-License-Identifier: MIT
// The posterior of a friction stage's (μs, log10 μr) by MCMC on its map (see cal_posterior.h).
#include "cal_posterior.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sort.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"

// Metropolis on the unit square: CAL_POSTERIOR_CHAINS chains from spread-out
// starts, each BURN_IN steps (the step size tuned toward ~30 % acceptance)
// then STEPS kept every THIN-th. 4 × 12 000 evaluations of a quadratic map
// and a 2–4-run kriging: well under a second.
enum { BURN_IN = 3000, STEPS = 12000, THIN = 4, TUNE_EVERY = 100 };
static const unsigned long seed = 20190517; // fixed: the report is the same on every derivation
static const double bound_margin = 0.03;    // of the search range: an interval "reaches" a bound

typedef struct model {
    const cal_friction_result *r;
    cal_mf_map map;
    const cal_mf_correction *correction; ///< NULL: a one-tier map
    double target[CAL_MF_MAX_Y], data_sd[CAL_MF_MAX_Y];
} model;

// The model's measurements at (u, v), and each one's spread there (data, map, kriging).
static void predict(const model *m, double u, double v, double *y, double *sd)
{
    cal_mf_predict(&m->map, u, v, y);
    cal_mf_correct(m->correction, m->map.n_y, u, v, y);
    for (int k = 0; sd && k < m->map.n_y; ++k) {
        double krig = cal_mf_correction_sd(m->correction, k, u, v);
        sd[k] = sqrt(m->data_sd[k] * m->data_sd[k] + m->map.rms[k] * m->map.rms[k] + krig * krig);
    }
}

// log of the likelihood at (u, v); -inf outside the square (the flat prior's support).
static double log_posterior(const model *m, double u, double v)
{
    if (u < 0 || u > 1 || v < 0 || v > 1) return -INFINITY;
    double y[CAL_MF_MAX_Y], sd[CAL_MF_MAX_Y], sum = 0;
    predict(m, u, v, y, sd);
    for (int k = 0; k < m->map.n_y; ++k) {
        double z = (y[k] - m->target[k]) / sd[k];
        sum += -0.5 * z * z - log(sd[k]);
    }
    return sum;
}

// A one-tier stage's own map: least squares through its usable candidates.
static int fit_own_map(const cal_friction_result *r, const cal_bounds *b, cal_mf_map *map)
{
    cal_mf_point *pts = calloc((size_t)r->n + 1, sizeof *pts);
    if (!pts) return 1;
    int n = 0;
    for (int i = 0; i < r->n; ++i)
        if (!r->cand[i].predicted && !cal_candidate_vector(r, &r->cand[i], pts[n].y))
            cal_friction_to_unit(b, r->cand[i].mu_s, r->cand[i].mu_r, &pts[n].u, &pts[n].v), n++;
    int bad = cal_mf_fit(pts, n, 1 + r->n_rpm, map);
    free(pts);
    return bad;
}

static int build_model(const cal_friction_result *r, const cal_bounds *b, model *m, cal_posterior *out)
{
    memset(m, 0, sizeof *m);
    m->r = r;
    if (r->has_map) {
        m->map = r->cheap_map, m->correction = &r->discrepancy;
        out->correction_unmodelled = cal_mf_correction_unmodelled(
            m->correction, m->map.n_y, r->map_correction && strcmp(r->map_correction, "kriging") == 0);
        out->model = r->n_levels > 1 ? "the corrected map of the multilevel search (the quadratic map through the "
                                       "map tier's runs and predictions, each weighed by its spread, plus the "
                                       "discrepancy measured at this tier's runs)"
                                     : "the corrected map of the two-tier search (the map tier's quadratic map plus "
                                       "the discrepancy measured at this tier's runs)";
    } else {
        if (fit_own_map(r, b, &m->map)) return 1;
        out->model = m->map.n_terms == CAL_MF_TERMS ? "a quadratic map through this tier's own candidates"
                                                    : "a plane through this tier's own candidates (too few for a "
                                                      "quadratic)";
    }
    out->n_y = m->map.n_y;
    m->target[0] = r->angle_target, m->data_sd[0] = cal_friction_angle_spread(r);
    snprintf(out->observable[0], sizeof out->observable[0], "angle at %g rpm", r->angle_rpm);
    for (int i = 0; i < r->n_rpm; ++i) {
        m->target[1 + i] = r->csa_data[i], m->data_sd[1 + i] = cal_friction_csa_spread(r, i);
        snprintf(out->observable[1 + i], sizeof out->observable[1 + i], "CSA at %g rpm", r->rpm[i]);
    }
    memcpy(out->data_sd, m->data_sd, sizeof out->data_sd);
    return 0;
}

// One chain from (u, v): burn-in with the step tuned, then STEPS/THIN samples into su, sv.
static long run_chain(const model *m, gsl_rng *rng, double u, double v, double *su, double *sv)
{
    double step = 0.1, lp = log_posterior(m, u, v);
    long accepted = 0, tried = 0, n = 0, window = 0;
    for (int it = 0; it < BURN_IN + STEPS; ++it) {
        double nu = u + gsl_ran_gaussian(rng, step), nv = v + gsl_ran_gaussian(rng, step);
        double nlp = log_posterior(m, nu, nv);
        int take = nlp - lp >= log(gsl_rng_uniform_pos(rng));
        if (take) u = nu, v = nv, lp = nlp;
        if (it < BURN_IN) {
            window += take;
            if ((it + 1) % TUNE_EVERY == 0) { // toward ~30 % acceptance
                step *= window > 0.3 * TUNE_EVERY ? 1.3 : 0.77;
                step = fmin(fmax(step, 1e-3), 0.5);
                window = 0;
            }
            continue;
        }
        accepted += take, tried++;
        if ((it - BURN_IN) % THIN == 0) su[n] = u, sv[n] = v, n++;
    }
    return tried ? accepted : 0;
}

static double median_of(double *x, size_t n)
{
    gsl_sort(x, 1, n);
    return gsl_stats_median_from_sorted_data(x, 1, n);
}

// Median, 95 % interval and bound contact of parameter p from the unit-square samples x.
static void summarise(cal_posterior *out, int p, double *x, const cal_bounds *b)
{
    size_t n = (size_t)out->n;
    gsl_sort(x, 1, n);
    double q[3] = {gsl_stats_quantile_from_sorted_data(x, 1, n, 0.025), gsl_stats_median_from_sorted_data(x, 1, n),
                   gsl_stats_quantile_from_sorted_data(x, 1, n, 0.975)};
    double mu[3];
    for (int k = 0; k < 3; ++k) {
        double mu_s, mu_r;
        cal_friction_to_mu(b, q[k], q[k], &mu_s, &mu_r);
        mu[k] = p == 0 ? mu_s : mu_r;
    }
    out->lo[p] = mu[0], out->median[p] = mu[1], out->hi[p] = mu[2];
    out->reaches_lower[p] = q[0] <= bound_margin, out->reaches_upper[p] = q[2] >= 1 - bound_margin;
    out->width[p] = q[2] - q[0];
}

// How far each measurement moves across each parameter's whole range, the other at (u, v).
static void sensitivities(const model *m, double u, double v, cal_posterior *out)
{
    double y0[CAL_MF_MAX_Y], y1[CAL_MF_MAX_Y];
    for (int p = 0; p < 2; ++p) {
        predict(m, p == 0 ? 0 : u, p == 1 ? 0 : v, y0, NULL);
        predict(m, p == 0 ? 1 : u, p == 1 ? 1 : v, y1, NULL);
        for (int k = 0; k < m->map.n_y; ++k) out->sensitivity[k][p] = (y1[k] - y0[k]) / m->data_sd[k];
    }
}

// The chains' starts: the stage's chosen pair and three spread points.
static void starts(const cal_friction_result *r, const cal_bounds *b, double u[], double v[])
{
    const double spread[CAL_POSTERIOR_CHAINS - 1][2] = {{0.2, 0.2}, {0.8, 0.8}, {0.2, 0.8}};
    u[0] = v[0] = 0.5;
    if (r->best >= 0) cal_friction_to_unit(b, r->cand[r->best].mu_s, r->cand[r->best].mu_r, &u[0], &v[0]);
    u[0] = fmin(fmax(u[0], 0), 1), v[0] = fmin(fmax(v[0], 0), 1);
    for (int c = 1; c < CAL_POSTERIOR_CHAINS; ++c) u[c] = spread[c - 1][0], v[c] = spread[c - 1][1];
}

int cal_posterior_sample(const cal_friction_result *r, const cal_bounds *b, cal_posterior *out, char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    model m;
    if (build_model(r, b, &m, out))
        return exp_fail(err, len, "no map to sample: fewer than three candidates measured everything");
    const long per_chain = STEPS / THIN;
    double *su = malloc(sizeof(double) * (size_t)(per_chain * CAL_POSTERIOR_CHAINS));
    double *sv = malloc(sizeof(double) * (size_t)(per_chain * CAL_POSTERIOR_CHAINS));
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!su || !sv || !rng) return free(su), free(sv), gsl_rng_free(rng), exp_fail(err, len, "out of memory");
    gsl_rng_set(rng, seed);
    double u0[CAL_POSTERIOR_CHAINS], v0[CAL_POSTERIOR_CHAINS], med_u[CAL_POSTERIOR_CHAINS], med_v[CAL_POSTERIOR_CHAINS];
    starts(r, b, u0, v0);
    long accepted = 0;
    double tmp[STEPS / THIN];
    for (int c = 0; c < CAL_POSTERIOR_CHAINS; ++c) {
        double *cu = su + c * per_chain, *cv = sv + c * per_chain;
        accepted += run_chain(&m, rng, u0[c], v0[c], cu, cv);
        memcpy(tmp, cu, sizeof tmp), med_u[c] = median_of(tmp, (size_t)per_chain);
        memcpy(tmp, cv, sizeof tmp), med_v[c] = median_of(tmp, (size_t)per_chain);
    }
    gsl_rng_free(rng);
    out->n = (int)(per_chain * CAL_POSTERIOR_CHAINS);
    out->acceptance = (double)accepted / ((double)STEPS * CAL_POSTERIOR_CHAINS);
    out->chain_spread[0] = gsl_stats_max(med_u, 1, CAL_POSTERIOR_CHAINS) - gsl_stats_min(med_u, 1, CAL_POSTERIOR_CHAINS);
    out->chain_spread[1] = gsl_stats_max(med_v, 1, CAL_POSTERIOR_CHAINS) - gsl_stats_min(med_v, 1, CAL_POSTERIOR_CHAINS);
    // The samples in μ, then the summaries (which sort copies in the unit square).
    out->mu_s = malloc(sizeof(double) * (size_t)out->n), out->mu_r = malloc(sizeof(double) * (size_t)out->n);
    if (!out->mu_s || !out->mu_r) return free(su), free(sv), cal_posterior_free(out), exp_fail(err, len, "out of memory");
    for (int i = 0; i < out->n; ++i) cal_friction_to_mu(b, su[i], sv[i], &out->mu_s[i], &out->mu_r[i]);
    summarise(out, 0, su, b);
    summarise(out, 1, sv, b);
    double um, vm;
    cal_friction_to_unit(b, out->median[0], out->median[1], &um, &vm);
    sensitivities(&m, um, vm, out);
    double y[CAL_MF_MAX_Y];
    predict(&m, um, vm, y, out->spread);
    for (int k = 0; k < m.map.n_y; ++k)
        out->map_rms[k] = m.map.rms[k], out->kriging_sd[k] = cal_mf_correction_sd(m.correction, k, um, vm);
    free(su), free(sv);
    return 0;
}

// Measurement k's kriging variance as a share of its whole variance at (u, v).
static double map_share(const model *m, int k, double u, double v)
{
    double krig = cal_mf_correction_sd(m->correction, k, u, v);
    double rest = m->data_sd[k] * m->data_sd[k] + m->map.rms[k] * m->map.rms[k];
    return krig * krig / (rest + krig * krig);
}

// Whether measurement k moves by one data spread across the range of a parameter the data can tell.
static int tells(const cal_posterior *p, int k)
{
    for (int q = 0; q < 2; ++q)
        if (!cal_posterior_blind(p, q) && fabs(p->sensitivity[k][q]) >= 1) return 1;
    return 0;
}

int cal_posterior_map_bound(const cal_posterior *p)
{
    for (int k = 0; k < p->n_y; ++k)
        if (tells(p, k) && p->map_rms[k] > p->data_sd[k]) return 1;
    return 0;
}

int cal_posterior_next_run(const cal_friction_result *r, const cal_bounds *b, const cal_posterior *p, double *u,
                           double *v, cal_posterior_need *need)
{
    need->measurement = -1, need->share = 0;
    model m;
    cal_posterior scratch;
    if (!r->has_map || p->n == 0 || build_model(r, b, &m, &scratch)) return 1;
    // One pass over the samples: each told measurement's summed share, and the sample where it is largest.
    double sum[CAL_MF_MAX_Y] = {0}, most[CAL_MF_MAX_Y], at_u[CAL_MF_MAX_Y], at_v[CAL_MF_MAX_Y];
    int told[CAL_MF_MAX_Y];
    for (int k = 0; k < p->n_y; ++k) told[k] = tells(p, k), most[k] = -1;
    for (int i = 0; i < p->n; ++i) {
        double su, sv;
        cal_friction_to_unit(b, p->mu_s[i], p->mu_r[i], &su, &sv);
        for (int k = 0; k < p->n_y; ++k) {
            if (!told[k]) continue;
            double share = map_share(&m, k, su, sv);
            sum[k] += share;
            if (share > most[k]) most[k] = share, at_u[k] = su, at_v[k] = sv;
        }
    }
    for (int k = 0; k < p->n_y; ++k)
        if (told[k] && (need->measurement < 0 || sum[k] / p->n > need->share))
            need->share = sum[k] / p->n, need->measurement = k;
    if (need->measurement < 0 || need->share < CAL_POSTERIOR_MAP_SHARE) return 1;
    *u = at_u[need->measurement], *v = at_v[need->measurement];
    return 0;
}

const char *cal_posterior_reach_text(const cal_posterior *p, int k)
{
    if (p->reaches_lower[k] && p->reaches_upper[k]) return " (both bounds)";
    if (p->reaches_lower[k]) return " (to the lower bound)";
    return p->reaches_upper[k] ? " (to the upper bound)" : "";
}

int cal_posterior_blind(const cal_posterior *p, int parameter)
{
    for (int k = 0; k < p->n_y; ++k)
        if (fabs(p->sensitivity[k][parameter]) >= 1) return 0;
    return 1;
}

void cal_posterior_free(cal_posterior *p)
{
    free(p->mu_s), free(p->mu_r);
    p->mu_s = p->mu_r = NULL, p->n = 0;
}
