// SPDX-License-Identifier: MIT
// The two-fidelity friction search (cal_multifidelity.h): GSL fits the cheap
// map, NLopt finds the corrected map's optimum, and the expensive tier is run
// only there.
#include "cal_multifidelity.h"

#include <gsl/gsl_multifit.h>
#include <math.h>
#include <nlopt.h>
#include <string.h>

// The regressors 1, u, v, u², uv, v² at (u, v).
static void terms(double u, double v, double *x) { x[0] = 1, x[1] = u, x[2] = v, x[3] = u * u, x[4] = u * v, x[5] = v * v; }

int cal_mf_fit(const cal_mf_point *pts, int n, int n_y, cal_mf_map *map)
{
    memset(map, 0, sizeof *map);
    int p = n >= 8 ? 6 : n >= 3 ? 3 : 0;
    if (p == 0 || n_y < 1 || n_y > CAL_MF_MAX_Y) return 1;
    gsl_matrix *X = gsl_matrix_alloc((size_t)n, (size_t)p), *cov = gsl_matrix_alloc((size_t)p, (size_t)p);
    gsl_vector *y = gsl_vector_alloc((size_t)n), *c = gsl_vector_alloc((size_t)p);
    gsl_multifit_linear_workspace *work = gsl_multifit_linear_alloc((size_t)n, (size_t)p);
    int bad = !X || !cov || !y || !c || !work;
    for (int i = 0; i < n && !bad; ++i) {
        double x[CAL_MF_TERMS];
        terms(pts[i].u, pts[i].v, x);
        for (int j = 0; j < p; ++j) gsl_matrix_set(X, (size_t)i, (size_t)j, x[j]);
    }
    for (int k = 0; k < n_y && !bad; ++k) {
        for (int i = 0; i < n; ++i) gsl_vector_set(y, (size_t)i, pts[i].y[k]);
        double chisq;
        size_t rank;
        // Truncated SVD: directions the points do not span (a nearly
        // singular design) are dropped rather than inverted into noise; a
        // design of rank below 3 (points on a line) is refused.
        bad = gsl_multifit_linear_tsvd(X, y, 1e-10, c, cov, &chisq, &rank, work) != 0 || rank < 3;
        for (int j = 0; j < p && !bad; ++j) map->coef[k][j] = gsl_vector_get(c, (size_t)j);
        map->rms[k] = sqrt(chisq / n);
    }
    gsl_matrix_free(X), gsl_matrix_free(cov), gsl_vector_free(y), gsl_vector_free(c);
    if (work) gsl_multifit_linear_free(work);
    if (bad) return memset(map, 0, sizeof *map), 1;
    map->n_y = n_y, map->n_terms = p;
    return 0;
}

void cal_mf_predict(const cal_mf_map *map, const double *delta, double u, double v, double *y)
{
    double x[CAL_MF_TERMS];
    terms(u, v, x);
    for (int k = 0; k < map->n_y; ++k) {
        double sum = delta ? delta[k] : 0;
        for (int j = 0; j < map->n_terms; ++j) sum += map->coef[k][j] * x[j];
        y[k] = sum;
    }
}

typedef struct corrected {
    const cal_mf_map *map;
    const double *delta;
    const cal_mf_problem *p;
} corrected;

static double corrected_objective(unsigned n, const double *x, double *grad, void *ctx)
{
    (void)n, (void)grad;
    const corrected *c = ctx;
    double y[CAL_MF_MAX_Y];
    cal_mf_predict(c->map, c->delta, x[0], x[1], y);
    return c->p->objective(y, c->p->ctx);
}

void cal_mf_optimum(const cal_mf_map *map, const double *delta, const cal_mf_problem *p, double *u, double *v)
{
    corrected c = {map, delta, p};
    enum { SCAN = 41 };
    double x[2] = {0.5, 0.5}, best = INFINITY;
    // The map is a smooth surface but the objective of it need not be convex
    // (the iso-angle band is a valley): scan first, then polish.
    for (int i = 0; i < SCAN; ++i)
        for (int j = 0; j < SCAN; ++j) {
            double at[2] = {(double)i / (SCAN - 1), (double)j / (SCAN - 1)};
            double f = corrected_objective(2, at, NULL, &c);
            if (f < best) best = f, x[0] = at[0], x[1] = at[1];
        }
    nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, 2);
    double lo[2] = {0, 0}, hi[2] = {1, 1}, step[2] = {0.5 / (SCAN - 1), 0.5 / (SCAN - 1)}, f;
    nlopt_set_lower_bounds(opt, lo), nlopt_set_upper_bounds(opt, hi);
    nlopt_set_min_objective(opt, corrected_objective, &c);
    nlopt_set_initial_step(opt, step);
    nlopt_set_xtol_abs1(opt, 1e-6);
    nlopt_set_maxeval(opt, 2000);
    double polished[2] = {x[0], x[1]};
    if (nlopt_optimize(opt, polished, &f) > 0 && f <= best) x[0] = polished[0], x[1] = polished[1];
    nlopt_destroy(opt);
    *u = x[0], *v = x[1];
}

static int agrees(const double *measured, const double *predicted, const cal_mf_problem *p)
{
    for (int k = 0; k < p->n_y; ++k)
        if (!(fabs(measured[k] - predicted[k]) <= p->noise[k])) return 0;
    return 1;
}

static int already_run(const cal_mf_result *r, double u, double v)
{
    for (int i = 0; i < r->n; ++i)
        if (fabs(r->run[i].u - u) <= 0.01 && fabs(r->run[i].v - v) <= 0.01) return 1;
    return 0;
}

static int measured(const cal_mf_point *p, int n_y)
{
    for (int k = 0; k < n_y; ++k)
        if (!isfinite(p->y[k])) return 0;
    return 1;
}

// The correction: the mean over the expensive runs that measured everything
// of (run - cheap map); a run with a missing measurement says nothing of it.
static void update_delta(const cal_mf_map *cheap, cal_mf_result *r, int n_y)
{
    double sum[CAL_MF_MAX_Y] = {0};
    int m = 0;
    for (int i = 0; i < r->n; ++i) {
        if (!measured(&r->run[i], n_y)) continue;
        double y[CAL_MF_MAX_Y];
        cal_mf_predict(cheap, NULL, r->run[i].u, r->run[i].v, y);
        for (int k = 0; k < n_y; ++k) sum[k] += r->run[i].y[k] - y[k];
        m++;
    }
    for (int k = 0; k < n_y; ++k) r->delta[k] = m ? sum[k] / m : 0;
}

int cal_mf_search(const cal_mf_map *cheap, const cal_mf_problem *p, cal_mf_result *out)
{
    memset(out, 0, sizeof *out);
    cal_mf_optimum(cheap, NULL, p, &out->u_uncorrected, &out->v_uncorrected);
    int budget = p->max_expensive < CAL_MF_MAX_FINE ? p->max_expensive : CAL_MF_MAX_FINE;
    while (out->n < budget) {
        double u, v;
        cal_mf_optimum(cheap, out->delta, p, &u, &v);
        if (already_run(out, u, v)) return out->settled = 1, 0;
        cal_mf_point *run = &out->run[out->n];
        run->u = u, run->v = v;
        cal_mf_predict(cheap, out->delta, u, v, out->predicted[out->n]);
        if (p->run_expensive(u, v, run->y, p->ctx)) return out->failed = 1, 0;
        out->agreed = agrees(run->y, out->predicted[out->n], p);
        out->n++;
        update_delta(cheap, out, p->n_y);
        if (out->agreed) return 0;
    }
    return 0;
}
