// SPDX-License-Identifier: MIT
// The two-fidelity friction search (cal_multifidelity.h): GSL fits the cheap
// map, NLopt finds the corrected map's optimum, and the expensive tier is run
// only there.
#include "cal_multifidelity.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit.h>
#include <math.h>
#include <nlopt.h>
#include <string.h>

// The regressors 1, u, v, u², uv, v² at (u, v).
static void terms(double u, double v, double *x) { x[0] = 1, x[1] = u, x[2] = v, x[3] = u * u, x[4] = u * v, x[5] = v * v; }

// Row i of the design at (u, v), each entry over s (1: unweighted; x / 1 is
// x exactly, so an unweighted fit is the plain least squares bit for bit).
static void design_row(gsl_matrix *X, int i, int p, double u, double v, double s)
{
    double x[CAL_MF_TERMS];
    terms(u, v, x);
    for (int j = 0; j < p; ++j) gsl_matrix_set(X, (size_t)i, (size_t)j, x[j] / s);
}

int cal_mf_fit(const cal_mf_point *pts, int n, int n_y, cal_mf_map *map) { return cal_mf_fit_weighted(pts, NULL, n, n_y, map); }

int cal_mf_fit_weighted(const cal_mf_point *pts, const double (*sd)[CAL_MF_MAX_Y], int n, int n_y, cal_mf_map *map)
{
    memset(map, 0, sizeof *map);
    int p = n >= 8 ? 6 : n >= 3 ? 3 : 0;
    if (p == 0 || n_y < 1 || n_y > CAL_MF_MAX_Y) return 1;
    gsl_matrix *X = gsl_matrix_alloc((size_t)n, (size_t)p), *cov = gsl_matrix_alloc((size_t)p, (size_t)p);
    gsl_vector *y = gsl_vector_alloc((size_t)n), *c = gsl_vector_alloc((size_t)p);
    gsl_multifit_linear_workspace *work = gsl_multifit_linear_alloc((size_t)n, (size_t)p);
    int bad = !X || !cov || !y || !c || !work;
    for (int i = 0; i < n && !bad && !sd; ++i) design_row(X, i, p, pts[i].u, pts[i].v, 1);
    for (int k = 0; k < n_y && !bad; ++k) {
        double weights = 0; // Σ 1/sd²: the weighted rms is sqrt(χ² / Σ 1/sd²)
        for (int i = 0; i < n; ++i) {
            double s = sd ? sd[i][k] : 1;
            if (sd) design_row(X, i, p, pts[i].u, pts[i].v, s);
            gsl_vector_set(y, (size_t)i, pts[i].y[k] / s), weights += 1 / (s * s);
        }
        double chisq;
        size_t rank;
        // Truncated SVD: directions the points do not span (a nearly
        // singular design) are dropped rather than inverted into noise; a
        // design of rank below 3 (points on a line) is refused.
        bad = gsl_multifit_linear_tsvd(X, y, 1e-10, c, cov, &chisq, &rank, work) != 0 || rank < 3;
        for (int j = 0; j < p && !bad; ++j) map->coef[k][j] = gsl_vector_get(c, (size_t)j);
        map->rms[k] = sd ? sqrt(chisq / weights) : sqrt(chisq / n);
    }
    gsl_matrix_free(X), gsl_matrix_free(cov), gsl_vector_free(y), gsl_vector_free(c);
    if (work) gsl_multifit_linear_free(work);
    if (bad) return memset(map, 0, sizeof *map), 1;
    map->n_y = n_y, map->n_terms = p;
    return 0;
}

const char *cal_mf_correction_name(cal_mf_correction_kind kind) { return kind == CAL_MF_AFFINE ? "affine" : "kriging"; }

static double kernel(double u1, double v1, double u2, double v2)
{
    const double l = CAL_MF_KRIGING_LENGTH;
    return exp(-((u1 - u2) * (u1 - u2) + (v1 - v2) * (v1 - v2)) / (2 * l * l));
}

// The correction's plane (its affine part) for measurement k at (u, v).
static double plane_at(const cal_mf_correction *c, int k, double u, double v)
{
    return c->at[k] + c->du[k] * (u - c->u0) + c->dv[k] * (v - c->v0);
}

void cal_mf_correct(const cal_mf_correction *c, int n_y, double u, double v, double *y)
{
    if (!c) return;
    double k_at[CAL_MF_MAX_FINE];
    for (int i = 0; i < c->n_runs; ++i) k_at[i] = kernel(u, v, c->run_u[i], c->run_v[i]);
    for (int k = 0; k < n_y; ++k) {
        double sum = plane_at(c, k, u, v);
        for (int i = 0; i < c->n_runs; ++i) sum += c->weight[k][i] * k_at[i];
        y[k] += sum;
    }
}

// Whether measurement k's correction has the kriging's variance model.
static int has_variance(const cal_mf_correction *c, int k) { return c && c->n_runs >= 2 && c->scale[k] > 0; }

const char *cal_mf_correction_unmodelled(const cal_mf_correction *c, int n_y, int kriging)
{
    if (!kriging) return "an affine correction";
    if (!c || c->n_runs < 2) return "one run at this tier (kriging needs two)";
    for (int k = 0; k < n_y; ++k)
        if (!has_variance(c, k)) return "a kriging GSL could not factor";
    return NULL;
}

double cal_mf_correction_sd(const cal_mf_correction *c, int k, double u, double v)
{
    if (!has_variance(c, k)) return 0;
    const size_t m = (size_t)c->n_runs;
    gsl_matrix *K = gsl_matrix_alloc(m, m);
    gsl_vector *kx = gsl_vector_alloc(m), *a = gsl_vector_alloc(m);
    double var = 1; // the kernel at zero distance
    if (K && kx && a) {
        for (size_t i = 0; i < m; ++i) {
            gsl_vector_set(kx, i, kernel(u, v, c->run_u[i], c->run_v[i]));
            for (size_t j = 0; j < m; ++j)
                gsl_matrix_set(K, i, j, kernel(c->run_u[i], c->run_v[i], c->run_u[j], c->run_v[j]) + (i == j ? c->nugget[k][i] : 0));
        }
        gsl_error_handler_t *old = gsl_set_error_handler_off();
        if (!gsl_linalg_cholesky_decomp1(K) && !gsl_linalg_cholesky_solve(K, kx, a))
            for (size_t i = 0; i < m; ++i) var -= gsl_vector_get(kx, i) * gsl_vector_get(a, i);
        gsl_set_error_handler(old);
    }
    gsl_matrix_free(K), gsl_vector_free(kx), gsl_vector_free(a);
    return c->scale[k] * sqrt(fmax(var, 0));
}

void cal_mf_predict(const cal_mf_map *map, double u, double v, double *y)
{
    double x[CAL_MF_TERMS];
    terms(u, v, x);
    for (int k = 0; k < map->n_y; ++k) {
        double sum = 0;
        for (int j = 0; j < map->n_terms; ++j) sum += map->coef[k][j] * x[j];
        y[k] = sum;
    }
}

// The expensive runs' noise for measurement k (cal_mf_problem.run_noise; NULL: 0).
static double tier_noise(const double *run_noise, int k) { return run_noise ? run_noise[k] : 0; }

typedef struct corrected {
    const cal_mf_map *map;
    const cal_mf_correction *correction;
    const cal_mf_problem *p;
} corrected;

static double corrected_objective(unsigned n, const double *x, double *grad, void *ctx)
{
    (void)n, (void)grad;
    const corrected *c = ctx;
    double y[CAL_MF_MAX_Y], sd[CAL_MF_MAX_Y];
    cal_mf_predict(c->map, x[0], x[1], y);
    cal_mf_correct(c->correction, c->map->n_y, x[0], x[1], y);
    if (!c->p->objective_uses_sd) return c->p->objective(y, NULL, c->p->ctx);
    for (int k = 0; k < c->map->n_y; ++k)
        sd[k] = hypot(tier_noise(c->p->run_noise, k), cal_mf_correction_sd(c->correction, k, x[0], x[1]));
    return c->p->objective(y, sd, c->p->ctx);
}

void cal_mf_optimum(const cal_mf_map *map, const cal_mf_correction *correction, const cal_mf_problem *p, double *u,
                    double *v)
{
    corrected c = {map, correction, p};
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

// The run's noise for measurement k: the problem's, or the run's own where larger.
static double run_error(const cal_mf_problem *p, const cal_mf_point *run, int k)
{
    return fmax(tier_noise(p->run_noise, k), run->sd[k]);
}

// A run with an error of its own above the problem's run noise (not steady).
static int noisy(const cal_mf_problem *p, const cal_mf_point *run)
{
    for (int k = 0; k < p->n_y; ++k)
        if (run->sd[k] > tier_noise(p->run_noise, k)) return 1;
    return 0;
}

// Agreement within the data's noise. A noisy run cannot show it: its own
// error is larger than the tier's, so a match within the noise says little.
static int agrees(const cal_mf_point *run, const double *predicted, const cal_mf_problem *p)
{
    if (noisy(p, run)) return 0;
    for (int k = 0; k < p->n_y; ++k)
        if (!(fabs(run->y[k] - predicted[k]) <= p->noise[k])) return 0;
    return 1;
}

// The run within 0.01 of (u, v), or NULL.
static const cal_mf_point *already_run(const cal_mf_result *r, double u, double v)
{
    for (int i = 0; i < r->n; ++i)
        if (fabs(r->run[i].u - u) <= 0.01 && fabs(r->run[i].v - v) <= 0.01) return &r->run[i];
    return NULL;
}

static int measured(const cal_mf_point *p, int n_y)
{
    for (int k = 0; k < n_y; ++k)
        if (!isfinite(p->y[k])) return 0;
    return 1;
}

// Kriging of what the plane leaves at the runs, per measurement: weights w
// solving (K + R) w = residuals, K the kernel between the runs and R the
// diagonal of each run's noise over the residuals' scale, (err_i / max(rms,
// noise))²: near 0 (interpolation) when the residuals stand well above the
// noise, 1 (a smoothed fit) when they are noise, more for a run whose own
// error (not steady) exceeds the tier's noise; at least 1e-9, to keep K + R
// positive definite. The weights stay 0 for a measurement whose system GSL
// cannot factor.
static void krige_residuals(cal_mf_correction *c, double d[][CAL_MF_MAX_Y], const double *u, const double *v, int m,
                            int n_y, const double *run_noise, double err[][CAL_MF_MAX_Y])
{
    c->n_runs = m;
    for (int i = 0; i < m; ++i) c->run_u[i] = u[i], c->run_v[i] = v[i];
    gsl_matrix *K = gsl_matrix_alloc((size_t)m, (size_t)m);
    gsl_vector *r = gsl_vector_alloc((size_t)m), *w = gsl_vector_alloc((size_t)m);
    for (int k = 0; K && r && w && k < n_y; ++k) {
        double ss = 0;
        for (int i = 0; i < m; ++i) {
            double e = d[i][k] - plane_at(c, k, u[i], v[i]);
            gsl_vector_set(r, (size_t)i, e), ss += e * e;
        }
        double noise = tier_noise(run_noise, k), scale = fmax(sqrt(ss / m), noise);
        for (int i = 0; i < m; ++i) {
            double e = err[i][k], ratio = scale > 0 ? e * e / (scale * scale) : 1;
            c->nugget[k][i] = fmax(ratio, 1e-9);
        }
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < m; ++j)
                gsl_matrix_set(K, (size_t)i, (size_t)j, kernel(u[i], v[i], u[j], v[j]) + (i == j ? c->nugget[k][i] : 0));
        gsl_error_handler_t *old = gsl_set_error_handler_off();
        int bad = gsl_linalg_cholesky_decomp1(K) || gsl_linalg_cholesky_solve(K, r, w);
        gsl_set_error_handler(old);
        for (int i = 0; i < m; ++i) c->weight[k][i] = bad ? 0 : gsl_vector_get(w, (size_t)i);
        c->scale[k] = bad ? 0 : scale;
    }
    gsl_matrix_free(K), gsl_vector_free(r), gsl_vector_free(w);
}

// A least-squares slope from the centred sums of squares and cross products.
static double slope(double sxx, double sxd) { return sxx > 0 ? sxd / sxx : 0; }

// The plane of measurement k's discrepancies d by weighted least squares
// (GSL), each run weighed by 1/err²: the mean at (u0, v0) and the slopes
// along the directions kept. For runs of unequal errors (one not steady).
static void weighted_plane(cal_mf_correction *c, int k, double d[][CAL_MF_MAX_Y], double err[][CAL_MF_MAX_Y],
                           const double *u, const double *v, int m, int use_u, int use_v)
{
    const size_t n = (size_t)m, p = (size_t)(1 + use_u + use_v);
    gsl_matrix *X = gsl_matrix_alloc(n, p), *cov = gsl_matrix_alloc(p, p);
    gsl_vector *w = gsl_vector_alloc(n), *y = gsl_vector_alloc(n), *b = gsl_vector_alloc(p);
    gsl_multifit_linear_workspace *work = gsl_multifit_linear_alloc(n, p);
    if (X && cov && w && y && b && work) {
        for (size_t i = 0; i < n; ++i) {
            size_t j = 0;
            gsl_matrix_set(X, i, j++, 1);
            if (use_u) gsl_matrix_set(X, i, j++, u[i] - c->u0);
            if (use_v) gsl_matrix_set(X, i, j++, v[i] - c->v0);
            gsl_vector_set(w, i, 1 / fmax(err[i][k] * err[i][k], 1e-300)), gsl_vector_set(y, i, d[i][k]);
        }
        double chisq;
        gsl_error_handler_t *old = gsl_set_error_handler_off();
        if (!gsl_multifit_wlinear(X, w, y, b, cov, &chisq, work)) {
            c->at[k] = gsl_vector_get(b, 0);
            if (use_u) c->du[k] = gsl_vector_get(b, 1);
            if (use_v) c->dv[k] = gsl_vector_get(b, (size_t)use_u + 1);
        }
        gsl_set_error_handler(old);
    }
    gsl_matrix_free(X), gsl_matrix_free(cov), gsl_vector_free(w), gsl_vector_free(y), gsl_vector_free(b);
    if (work) gsl_multifit_linear_free(work);
}

// The correction: the discrepancy (run - cheap map) of the runs that measured
// everything, its mean at their centre and, with three runs or more, its
// slopes along each direction they span (least squares on the centred
// coordinates: both at once where both are spanned); with kriging and two
// runs or more, what that plane leaves at the runs is kriged on top. A run
// with an error of its own (not steady) counts by it: the plane is then
// weighted least squares, and its kriging nugget is its own.
static void update_correction(const cal_mf_map *cheap, cal_mf_result *r, const cal_mf_problem *p)
{
    const int n_y = p->n_y;
    enum { MIN_RUNS_FOR_SLOPES = 3 };
    const double min_span = 0.05;
    double d[CAL_MF_MAX_FINE][CAL_MF_MAX_Y], err[CAL_MF_MAX_FINE][CAL_MF_MAX_Y], u[CAL_MF_MAX_FINE], v[CAL_MF_MAX_FINE];
    int m = 0, any_noisy = 0;
    for (int i = 0; i < r->n; ++i) {
        if (!measured(&r->run[i], n_y)) continue;
        double y[CAL_MF_MAX_Y];
        cal_mf_predict(cheap, r->run[i].u, r->run[i].v, y);
        for (int k = 0; k < n_y; ++k) d[m][k] = r->run[i].y[k] - y[k], err[m][k] = run_error(p, &r->run[i], k);
        any_noisy |= noisy(p, &r->run[i]);
        u[m] = r->run[i].u, v[m] = r->run[i].v, m++;
    }
    cal_mf_correction *c = &r->correction;
    memset(c, 0, sizeof *c);
    if (m == 0) return;
    double u_lo = u[0], u_hi = u[0], v_lo = v[0], v_hi = v[0];
    for (int i = 0; i < m; ++i) {
        c->u0 += u[i] / m, c->v0 += v[i] / m;
        u_lo = fmin(u_lo, u[i]), u_hi = fmax(u_hi, u[i]), v_lo = fmin(v_lo, v[i]), v_hi = fmax(v_hi, v[i]);
    }
    int use_u = m >= MIN_RUNS_FOR_SLOPES && u_hi - u_lo >= min_span;
    int use_v = m >= MIN_RUNS_FOR_SLOPES && v_hi - v_lo >= min_span;
    double suu = 0, svv = 0, suv = 0;
    for (int i = 0; i < m; ++i) {
        double x = u[i] - c->u0, z = v[i] - c->v0;
        suu += x * x, svv += z * z, suv += x * z;
    }
    double det = suu * svv - suv * suv;
    if (use_u && use_v && !(det > 1e-12 * suu * svv)) use_u = use_v = 0; // runs on a slanted line: the mean only
    for (int k = 0; k < n_y && any_noisy; ++k) weighted_plane(c, k, d, err, u, v, m, use_u, use_v);
    // Runs of equal errors: the plain least squares on the centred coordinates
    // (what the weighted one reduces to, kept literal: earlier calibrations
    // re-derive bit for bit).
    for (int k = 0; k < n_y && !any_noisy; ++k) {
        double sd = 0, sud = 0, svd = 0;
        for (int i = 0; i < m; ++i) sd += d[i][k];
        c->at[k] = sd / m;
        for (int i = 0; i < m; ++i) sud += (u[i] - c->u0) * (d[i][k] - c->at[k]), svd += (v[i] - c->v0) * (d[i][k] - c->at[k]);
        if (use_u && use_v) c->du[k] = (svv * sud - suv * svd) / det, c->dv[k] = (suu * svd - suv * sud) / det;
        else if (use_u) c->du[k] = slope(suu, sud);
        else if (use_v) c->dv[k] = slope(svv, svd);
    }
    if (p->correction == CAL_MF_KRIGING && m >= 2) krige_residuals(c, d, u, v, m, n_y, p->run_noise, err);
}

// One expensive run at (u, v): what the corrected map predicted there, the
// run, whether it agreed, and the correction refitted with it. 1: the run
// could not be done (out->failed set).
static int run_at(const cal_mf_map *cheap, const cal_mf_problem *p, cal_mf_result *out, double u, double v)
{
    cal_mf_point *run = &out->run[out->n];
    memset(run, 0, sizeof *run);
    run->u = u, run->v = v;
    cal_mf_predict(cheap, u, v, out->predicted[out->n]);
    cal_mf_correct(&out->correction, p->n_y, u, v, out->predicted[out->n]);
    if (p->run_expensive(u, v, run, p->ctx)) return out->failed = 1, 1;
    out->agreed = agrees(run, out->predicted[out->n], p);
    out->n++;
    update_correction(cheap, out, p);
    memset(out->delta, 0, sizeof out->delta);
    cal_mf_correct(&out->correction, p->n_y, u, v, out->delta);
    return 0;
}

static int budget_of(const cal_mf_problem *p) { return p->max_expensive < CAL_MF_MAX_FINE ? p->max_expensive : CAL_MF_MAX_FINE; }

// The loop from where out stands: a run at the corrected optimum, until one
// agrees, the optimum comes back to a point already run, a run fails, or
// out->n reaches budget.
static void search_until(const cal_mf_map *cheap, const cal_mf_problem *p, cal_mf_result *out, int budget)
{
    while (out->n < budget) {
        double u, v;
        cal_mf_optimum(cheap, &out->correction, p, &u, &v);
        const cal_mf_point *again = already_run(out, u, v);
        if (again) {
            out->settled = 1, out->unmeasured = !measured(again, p->n_y), out->settled_noisy = noisy(p, again);
            return;
        }
        if (run_at(cheap, p, out, u, v)) return;
        if (out->agreed) return;
    }
}

int cal_mf_search(const cal_mf_map *cheap, const cal_mf_problem *p, cal_mf_result *out)
{
    memset(out, 0, sizeof *out);
    cal_mf_optimum(cheap, NULL, p, &out->u_uncorrected, &out->v_uncorrected);
    search_until(cheap, p, out, budget_of(p));
    return 0;
}

int cal_mf_return(const cal_mf_map *cheap, const cal_mf_problem *p, int more, cal_mf_result *out)
{
    if (out->failed || more <= 0) return 0;
    int before = out->n, budget = out->n + more < CAL_MF_MAX_FINE ? out->n + more : CAL_MF_MAX_FINE;
    out->agreed = out->settled = out->settled_noisy = out->unmeasured = 0; // they speak of the resumed loop now
    search_until(cheap, p, out, budget);
    return out->n - before;
}

const char *cal_mf_refine(const cal_mf_map *cheap, const cal_mf_problem *p, int more, cal_mf_next_point next, void *ctx,
                          cal_mf_result *out)
{
    if (out->failed) return "not tried: the search's last run failed";
    for (int k = 0; k < more; ++k) {
        if (out->n >= CAL_MF_MAX_FINE) return "stopped: no room for another run";
        double u, v;
        if (next(&out->correction, &u, &v, ctx)) return "stopped: the stage asked for no more runs";
        if (already_run(out, u, v)) return "stopped: the point asked for was already run";
        if (run_at(cheap, p, out, u, v)) return "stopped: a simulation could not be stored";
    }
    return more > 0 ? "stopped at posterior_runs" : "not asked for (posterior_runs 0)";
}
