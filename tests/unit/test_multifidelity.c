// SPDX-License-Identifier: MIT
// The two-fidelity search (calib/methods/cal_multifidelity.c) on analytic responses,
// where the expensive tier's optimum is known exactly: an "angle" and two
// "CSA" values, smooth in (u, v), the cheap tier the same plus a bias it
// cannot know. The objective is the friction stage's form: squared z-scores
// against targets. Independent of any drum.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "cal_multifidelity.h"

enum { N_Y = 3 };
static const double target[N_Y] = {34.6, 46.0, 60.0}, spread[N_Y] = {0.5, 0.6, 1.2};

// The expensive tier's response: angle rising with both frictions, the CSA
// curve steeper with μs at one speed and with μr at the other, one cross term.
static void expensive_response(double u, double v, double *y)
{
    y[0] = 28 + 9 * u + 6 * v;
    y[1] = 43 + 4 * u - 1.5 * v + 2 * u * u;
    y[2] = 55 + 3 * u + 5 * v - 2 * u * v;
}

typedef struct twin {
    double bias[N_Y];      ///< cheap - expensive, constant
    double bias_slope_u;   ///< and a part linear in u, added to the angle
    double bias_slope_v;   ///< and one linear in v, added to every measurement
    double bias_curve_v;   ///< and one quadratic in v, (v - 1/2)², added to the angle
    int runs, fail_at;     ///< expensive runs made; fail on this one (0: never)
} twin;
#define TWIN(b0, b1, b2, slope_u, slope_v, fail) {{b0, b1, b2}, slope_u, slope_v, 0, 0, fail}

static void cheap_response(const twin *t, double u, double v, double *y)
{
    expensive_response(u, v, y);
    for (int k = 0; k < N_Y; ++k) y[k] += t->bias[k] + t->bias_slope_v * v;
    y[0] += t->bias_slope_u * u + t->bias_curve_v * (v - 0.5) * (v - 0.5);
}

static double objective(const double *y, const double *sd, void *ctx)
{
    (void)sd, (void)ctx;
    double sum = 0;
    for (int k = 0; k < N_Y; ++k) sum += (y[k] - target[k]) * (y[k] - target[k]) / (spread[k] * spread[k]);
    return sum / N_Y;
}

static int run_expensive(double u, double v, cal_mf_point *run, void *ctx)
{
    twin *t = ctx;
    if (++t->runs == t->fail_at) return 1;
    expensive_response(u, v, run->y);
    return 0;
}

// The cheap map from a g × g grid of cell centres.
static void map_of(const twin *t, int g, cal_mf_map *map)
{
    cal_mf_point pts[64];
    int n = 0;
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < g; ++j) {
            pts[n].u = (i + 0.5) / g, pts[n].v = (j + 0.5) / g;
            cheap_response(t, pts[n].u, pts[n].v, pts[n].y);
            n++;
        }
    assert_int_equal(cal_mf_fit(pts, n, N_Y, map), 0);
}

static cal_mf_problem problem_of(twin *t, int budget)
{
    static const double noise[N_Y] = {0.5, 0.6, 1.2};
    return (cal_mf_problem){.n_y = N_Y, .objective = objective, .run_expensive = run_expensive, .noise = noise,
                            .max_expensive = budget, .ctx = t, .correction = CAL_MF_KRIGING};
}

// The expensive optimum, by brute force on a fine grid then the same polish.
static void true_optimum(double *u, double *v)
{
    twin none = TWIN(0, 0, 0, 0, 0, 0);
    cal_mf_map exact;
    map_of(&none, 4, &exact); // quadratic responses: the quadratic map is exact
    cal_mf_problem p = problem_of(&none, 0);
    cal_mf_optimum(&exact, NULL, &p, u, v);
}

static void a_quadratic_is_fitted_exactly(void **state)
{
    (void)state;
    twin t = TWIN(1.5, -2.0, 0.7, 0, 0, 0);
    cal_mf_map map;
    map_of(&t, 3, &map);
    assert_int_equal(map.n_terms, 6);
    for (double u = 0; u <= 1; u += 0.25)
        for (double v = 0; v <= 1; v += 0.25) {
            double want[N_Y], got[N_Y];
            cheap_response(&t, u, v, want);
            cal_mf_predict(&map, u, v, got);
            for (int k = 0; k < N_Y; ++k) assert_true(fabs(want[k] - got[k]) < 1e-9);
        }
}

static void too_few_points_are_refused(void **state)
{
    (void)state;
    cal_mf_point pts[2] = {{.u = 0.1, .v = 0.1, .y = {1, 2, 3}}, {.u = 0.9, .v = 0.9, .y = {2, 3, 4}}};
    cal_mf_map map;
    assert_int_equal(cal_mf_fit(pts, 2, N_Y, &map), 1);
}

// The weighted fit (a level's map on the level below's runs and predictions):
// equal spreads give the plain fit bit for bit; a point with a large spread
// barely moves the map, the same point trusted drags it.
static void a_weighted_fit_trusts_each_point_by_its_spread(void **state)
{
    (void)state;
    twin t = TWIN(1.5, -2.0, 0.7, 0, 0, 0);
    cal_mf_point pts[10];
    double sd[10][CAL_MF_MAX_Y];
    for (int i = 0; i < 9; ++i) {
        pts[i].u = (i / 3 + 0.5) / 3, pts[i].v = (i % 3 + 0.5) / 3;
        cheap_response(&t, pts[i].u, pts[i].v, pts[i].y);
    }
    pts[9] = pts[4], pts[9].y[0] += 10; // an outlier on the centre
    for (int i = 0; i < 10; ++i)
        for (int k = 0; k < CAL_MF_MAX_Y; ++k) sd[i][k] = 1;
    cal_mf_map plain, equal, doubted, trusted;
    assert_int_equal(cal_mf_fit(pts, 10, N_Y, &plain), 0);
    assert_int_equal(cal_mf_fit_weighted(pts, (const double(*)[CAL_MF_MAX_Y])sd, 10, N_Y, &equal), 0);
    assert_memory_equal(&plain, &equal, sizeof plain);
    sd[9][0] = 100;
    assert_int_equal(cal_mf_fit_weighted(pts, (const double(*)[CAL_MF_MAX_Y])sd, 10, N_Y, &doubted), 0);
    sd[9][0] = 0.01;
    assert_int_equal(cal_mf_fit_weighted(pts, (const double(*)[CAL_MF_MAX_Y])sd, 10, N_Y, &trusted), 0);
    double want[N_Y], y_doubted[N_Y], y_trusted[N_Y];
    cheap_response(&t, pts[4].u, pts[4].v, want);
    cal_mf_predict(&doubted, pts[4].u, pts[4].v, y_doubted), cal_mf_predict(&trusted, pts[4].u, pts[4].v, y_trusted);
    assert_true(fabs(y_doubted[0] - want[0]) < 0.01); // 10 at a spread of 100 against nine at 1
    assert_true(fabs(y_trusted[0] - want[0]) > 9);     // followed within its spread of 0.01
}

// A constant bias between the tiers: the first expensive run measures it
// exactly, the corrected map is the expensive response, and the second run
// lands on the expensive optimum and agrees with its prediction.
static void a_constant_bias_is_measured_and_removed(void **state)
{
    (void)state;
    twin t = TWIN(7.6, 1.5, -2.0, 0, 0, 0);
    cal_mf_map map;
    map_of(&t, 3, &map);
    cal_mf_problem p = problem_of(&t, 6);
    cal_mf_result r;
    assert_int_equal(cal_mf_search(&map, &p, &r), 0);
    double u, v;
    true_optimum(&u, &v);
    // The test can fail: the cheap map's own optimum is far from the truth.
    assert_true(hypot(r.u_uncorrected - u, r.v_uncorrected - v) > 0.1);
    assert_false(r.failed);
    assert_true(r.agreed);
    assert_int_equal(r.n, 2);
    assert_true(fabs(r.run[r.n - 1].u - u) < 1e-3 && fabs(r.run[r.n - 1].v - v) < 1e-3);
    for (int k = 0; k < N_Y; ++k) assert_true(fabs(r.delta[k] + t.bias[k]) < 1e-6);
}

// A bias that varies over the square: the additive correction is exact only
// where it was measured, so the loop needs more runs; it must still end
// within the noise of the truth's objective, inside its budget.
static void a_varying_bias_converges_within_noise(void **state)
{
    (void)state;
    twin t = TWIN(7.6, 1.5, -2.0, 3.0, 0, 0);
    cal_mf_map map;
    map_of(&t, 4, &map);
    cal_mf_problem p = problem_of(&t, 8);
    cal_mf_result r;
    cal_mf_search(&map, &p, &r);
    assert_false(r.failed);
    assert_true(r.agreed || r.settled);
    assert_true(r.n <= 8);
    double u, v, best[N_Y], got[N_Y];
    true_optimum(&u, &v);
    expensive_response(u, v, best);
    expensive_response(r.run[r.n - 1].u, r.run[r.n - 1].v, got);
    // Within one unit of the objective (one standard deviation in the mean
    // squared z-score) of the best the expensive tier can do.
    assert_true(objective(got, NULL, NULL) - objective(best, NULL, NULL) < 1.0);
}

// A bias that varies along v (log μr), as λ 4096 against the ci map did
// (results/calibration-standard-L4096/): linear in the plane, so once three runs
// span v the fitted plane is exact along it. The affine correction then ends
// agreeing with its prediction at the expensive optimum. Kriging, whose trend
// is that plane, may agree sooner, from an interpolation of two runs: it must
// end agreeing, within the noise of the truth's objective.
static void a_bias_along_mu_r_is_fitted(void **state)
{
    (void)state;
    double u, v, best[N_Y];
    true_optimum(&u, &v);
    expensive_response(u, v, best);
    for (int kind = 0; kind < 2; ++kind) {
        twin t = TWIN(-6.0, 0.5, -1.0, 0, 4.0, 0);
        cal_mf_map map;
        map_of(&t, 4, &map);
        cal_mf_problem p = problem_of(&t, 8);
        p.correction = kind ? CAL_MF_AFFINE : CAL_MF_KRIGING;
        cal_mf_result r;
        cal_mf_search(&map, &p, &r);
        const double lu = r.run[r.n - 1].u, lv = r.run[r.n - 1].v;
        printf("%s: %d runs, last at (%.4f, %.4f), truth (%.4f, %.4f), slope along v %.3f\n",
               cal_mf_correction_name(p.correction), r.n, lu, lv, u, v, r.correction.dv[0]);
        assert_false(r.failed);
        assert_true(r.agreed);
        double got[N_Y];
        expensive_response(lu, lv, got);
        if (kind) assert_true(fabs(lu - u) < 0.01 && fabs(lv - v) < 0.01);
        else assert_true(objective(got, NULL, NULL) - objective(best, NULL, NULL) < 1.0);
    }
}

// A discrepancy that curves along v (log μr) with μs on its bound, as in the
// standard calibration's granule stage (results/calibration-standard-affine/): the
// λ 1000 angle rose 5.1° from μr 0.011 to 0.13 and 6.7° from there to 0.35,
// far more steeply than the ci map. Here the expensive angle is 20 + 4u + 22v²,
// the cheap map's 26 + 4u + 8v; one CSA rises with u only and its target lies
// beyond the bound, so the optimum is on u = 1 where the angle meets 34.6:
// v = sqrt(10.6 / 22). A plane fitted to the runs' discrepancies misses it
// between them; kriging passes through the runs. Within the standard tier's
// budget of 4 runs, kriging must end agreeing with its prediction at the
// optimum (within the angle's noise), and the affine correction, which the
// same runs leave off, must not: the test shows the difference, not just one.
static void bound_expensive(double u, double v, double *y) { y[0] = 20 + 4 * u + 22 * v * v, y[1] = 45 + 2 * u; }
static void bound_cheap(double u, double v, double *y) { y[0] = 26 + 4 * u + 8 * v, y[1] = 45 + 2 * u; }
static double bound_objective(const double *y, const double *sd, void *ctx)
{
    (void)sd, (void)ctx;
    return (y[0] - 34.6) * (y[0] - 34.6) / 0.25 + (y[1] - 48.0) * (y[1] - 48.0);
}
static int bound_run(double u, double v, cal_mf_point *run, void *ctx)
{
    ++*(int *)ctx;
    bound_expensive(u, v, run->y);
    return 0;
}

static void a_curved_bias_along_mu_r_is_followed(void **state)
{
    (void)state;
    cal_mf_point pts[16];
    for (int i = 0; i < 16; ++i) {
        pts[i].u = (i / 4 + 0.5) / 4, pts[i].v = (i % 4 + 0.5) / 4;
        bound_cheap(pts[i].u, pts[i].v, pts[i].y);
    }
    cal_mf_map map;
    assert_int_equal(cal_mf_fit(pts, 16, 2, &map), 0);
    const double noise[2] = {0.5, 0.5}, v_true = sqrt(10.6 / 22);
    double miss[2];
    for (int kind = 0; kind < 2; ++kind) {
        int runs = 0;
        cal_mf_problem p = {.n_y = 2, .objective = bound_objective, .run_expensive = bound_run, .noise = noise,
                            .max_expensive = 4, .ctx = &runs, .correction = kind ? CAL_MF_AFFINE : CAL_MF_KRIGING};
        cal_mf_result r;
        cal_mf_search(&map, &p, &r);
        printf("%s:", kind ? "affine" : "kriging");
        for (int i = 0; i < r.n; ++i)
            printf(" (%.3f, %.3f) %.2f° [%.2f° predicted]", r.run[i].u, r.run[i].v, r.run[i].y[0], r.predicted[i][0]);
        printf(" -> %s\n", r.agreed ? "agreed" : r.settled ? "settled" : "budget spent");
        assert_false(r.failed);
        miss[kind] = fabs(r.run[r.n - 1].v - v_true);
        if (kind == 0) {
            assert_true(r.agreed);
            assert_true(fabs(r.run[r.n - 1].u - 1) < 1e-3);
            assert_true(fabs(r.run[r.n - 1].y[0] - 34.6) <= noise[0]);
        } else {
            assert_false(r.agreed);
        }
    }
    printf("last run's v from the truth %.4f: kriging %.4f, affine %.4f\n", v_true, miss[0], miss[1]);
    assert_true(miss[0] < miss[1]);
}

static void a_failed_run_stops_the_loop(void **state)
{
    (void)state;
    twin t = TWIN(7.6, 1.5, -2.0, 0, 0, 1);
    cal_mf_map map;
    map_of(&t, 3, &map);
    cal_mf_problem p = problem_of(&t, 6);
    cal_mf_result r;
    cal_mf_search(&map, &p, &r);
    assert_true(r.failed);
    assert_int_equal(r.n, 0);
    assert_int_equal(t.runs, 1);
}

// cal_mf_refine's stand-in for the posterior: asks for the points of its list, then declines.
typedef struct asks {
    double u[4], v[4];
    int n, given;
} asks;

static int next_of_list(const cal_mf_correction *c, double *u, double *v, void *ctx)
{
    (void)c;
    asks *a = ctx;
    if (a->given == a->n) return 1;
    *u = a->u[a->given], *v = a->v[a->given], a->given++;
    return 0;
}

// After the loop, the runs the stage asks for are made where it asks, each
// refits the correction (a bias linear in v, measured first at one point, is
// exact everywhere once runs span v), and the reason it stopped is said.
static void runs_after_the_loop_go_where_asked_and_correct_the_map(void **state)
{
    (void)state;
    twin t = TWIN(1.0, 0.5, -0.5, 0, 2.0, 0);
    cal_mf_map map;
    map_of(&t, 4, &map);
    cal_mf_problem p = problem_of(&t, 1); // one loop run: the correction is a constant, wrong away from it
    cal_mf_result r;
    cal_mf_search(&map, &p, &r);
    assert_int_equal(r.n, 1);
    double far_u = 0.5, far_v = fabs(r.run[0].v - 0.9) > 0.3 ? 0.9 : 0.1, y[N_Y], truth[N_Y];
    cal_mf_predict(&map, far_u, far_v, y), cal_mf_correct(&r.correction, N_Y, far_u, far_v, y);
    expensive_response(far_u, far_v, truth);
    assert_true(fabs(y[0] - truth[0]) > 0.5); // the test can fail: the one-run correction misses there
    asks a = {{0.2, 0.8, 0.5}, {0.1, 0.9, 0.5}, 3, 0};
    const char *why = cal_mf_refine(&map, &p, 2, next_of_list, &a, &r);
    assert_string_equal(why, "stopped at posterior_runs");
    assert_int_equal(r.n, 3);
    assert_int_equal(t.runs, 3);
    assert_float_equal(r.run[1].u, 0.2, 0), assert_float_equal(r.run[1].v, 0.1, 0);
    assert_float_equal(r.run[2].u, 0.8, 0), assert_float_equal(r.run[2].v, 0.9, 0);
    cal_mf_predict(&map, far_u, far_v, y), cal_mf_correct(&r.correction, N_Y, far_u, far_v, y);
    for (int k = 0; k < N_Y; ++k) assert_float_equal(y[k], truth[k], 1e-6); // three runs: the plane is exact
    // Declined: nothing run. Asked for a point already run: nothing run.
    asks none = {{0}, {0}, 0, 0}, again = {{0.2}, {0.1}, 1, 0};
    assert_string_equal(cal_mf_refine(&map, &p, 2, next_of_list, &none, &r), "stopped: the stage asked for no more runs");
    assert_string_equal(cal_mf_refine(&map, &p, 2, next_of_list, &again, &r), "stopped: the point asked for was already run");
    assert_string_equal(cal_mf_refine(&map, &p, 0, next_of_list, &none, &r), "not asked for (posterior_runs 0)");
    assert_int_equal(r.n, 3);
    assert_int_equal(t.runs, 3);
}

// After the posterior's runs moved the correction, the loop resumes at the
// corrected optimum (cal_mf_return): its first run is where the corrected map
// now puts the optimum, which neither the loop's run nor the posterior's
// stood at; with the correction exact there it agrees, and the resumed loop
// ends. A failed run before, or no run asked, resumes nothing.
static void the_loop_returns_to_the_optimum_the_posterior_runs_moved(void **state)
{
    (void)state;
    twin t = TWIN(1.0, 0.5, -0.5, 0, 2.0, 0);
    cal_mf_map map;
    map_of(&t, 4, &map);
    cal_mf_problem p = problem_of(&t, 1);
    cal_mf_result r;
    cal_mf_search(&map, &p, &r);
    asks a = {{0.2, 0.8}, {0.1, 0.9}, 2, 0};
    cal_mf_refine(&map, &p, 2, next_of_list, &a, &r);
    assert_int_equal(r.n, 3);
    double u, v;
    cal_mf_optimum(&map, &r.correction, &p, &u, &v);
    for (int i = 0; i < r.n; ++i) // the test can fail: no run stands at the moved optimum yet
        assert_true(hypot(r.run[i].u - u, r.run[i].v - v) > 0.05);
    assert_int_equal(cal_mf_return(&map, &p, 0, &r), 0);
    assert_int_equal(t.runs, 3);
    assert_int_equal(cal_mf_return(&map, &p, 2, &r), 1);
    assert_int_equal(r.n, 4);
    assert_int_equal(t.runs, 4);
    assert_float_equal(r.run[3].u, u, 1e-12), assert_float_equal(r.run[3].v, v, 1e-12);
    assert_true(r.agreed);
    assert_false(r.settled);
    // Its own optimum again: settled, nothing run.
    assert_int_equal(cal_mf_return(&map, &p, 2, &r), 0);
    assert_true(r.settled);
    r.failed = 1;
    assert_int_equal(cal_mf_return(&map, &p, 2, &r), 0);
    assert_int_equal(t.runs, 4);
}

// An expensive run that is biased by offset[i] on its i-th call (all
// measurements), with its own error sd[i] (0: steady), or measures nothing.
typedef struct scripted {
    double offset[4], sd[4];
    int nothing, runs;
} scripted;

static int scripted_run(double u, double v, cal_mf_point *run, void *ctx)
{
    scripted *s = ctx;
    int i = s->runs++;
    expensive_response(u, v, run->y);
    for (int k = 0; k < N_Y; ++k) run->y[k] = s->nothing ? NAN : run->y[k] + s->offset[i], run->sd[k] = s->sd[i];
    return 0;
}

static const double tier_noise[N_Y] = {0.25, 0.25, 0.25};

static cal_mf_problem scripted_problem(scripted *s, int budget, cal_mf_correction_kind kind)
{
    cal_mf_problem p = problem_of(NULL, budget);
    p.run_expensive = scripted_run, p.run_noise = tier_noise, p.ctx = s, p.correction = kind;
    return p;
}

// A run that is not steady measures, but cannot agree: where the map is
// exact, the steady run agrees at once; the same run with its own spread
// does not, and the loop, whose correction it leaves at 0, comes back to it
// and says so. A run that measures nothing is never called settled.
static void a_run_not_steady_cannot_agree_and_one_unmeasured_is_not_settled(void **state)
{
    (void)state;
    twin exact = TWIN(0, 0, 0, 0, 0, 0);
    cal_mf_map map;
    map_of(&exact, 4, &map);
    cal_mf_result r;
    scripted steady = {{0}, {0}, 0, 0}, unsteady = {{0}, {3.0}, 0, 0}, nothing = {{0}, {0}, 1, 0};
    cal_mf_problem p = scripted_problem(&steady, 4, CAL_MF_KRIGING);
    cal_mf_search(&map, &p, &r);
    assert_true(r.agreed), assert_int_equal(r.n, 1);
    p = scripted_problem(&unsteady, 4, CAL_MF_KRIGING);
    cal_mf_search(&map, &p, &r);
    assert_false(r.agreed), assert_int_equal(r.n, 1);
    assert_true(r.settled && r.settled_noisy && !r.unmeasured);
    p = scripted_problem(&nothing, 4, CAL_MF_KRIGING);
    cal_mf_search(&map, &p, &r);
    assert_false(r.agreed), assert_int_equal(r.n, 1);
    assert_true(r.settled && r.unmeasured);
}

// Two runs, a steady one 9 below the map and one not steady (its own spread
// 5, the tier's noise 0.25) 3 below: the affine correction's mean weighs them
// by 1/error², (-9·16 - 3·0.04) / 16.04, not the plain -6; kriging then pulls
// the correction only part of the way to the unsteady run's -3 and keeps
// more of its own variance there than at the steady run.
static void a_run_not_steady_counts_by_its_own_spread(void **state)
{
    (void)state;
    twin exact = TWIN(0, 0, 0, 0, 0, 0);
    cal_mf_map map;
    map_of(&exact, 4, &map);
    const double weighted = (-9 / (0.25 * 0.25) - 3 / 25.0) / (1 / (0.25 * 0.25) + 1 / 25.0);
    for (int kind = 0; kind < 2; ++kind) {
        scripted s = {{-9, -3}, {0, 5}, 0, 0};
        cal_mf_problem p = scripted_problem(&s, 0, kind ? CAL_MF_AFFINE : CAL_MF_KRIGING);
        cal_mf_result r;
        cal_mf_search(&map, &p, &r);
        asks a = {{0.2, 0.8}, {0.5, 0.5}, 2, 0};
        cal_mf_refine(&map, &p, 2, next_of_list, &a, &r);
        assert_int_equal(r.n, 2);
        assert_false(r.agreed);
        double at_a[N_Y] = {0}, at_b[N_Y] = {0};
        cal_mf_correct(&r.correction, N_Y, 0.2, 0.5, at_a), cal_mf_correct(&r.correction, N_Y, 0.8, 0.5, at_b);
        printf("%s: correction %.4f at the steady run, %.4f at the unsteady one (plane mean %.4f)\n",
               kind ? "affine" : "kriging", at_a[0], at_b[0], r.correction.at[0]);
        // Two runs: the kriging has its variance model; a plane never has one.
        const char *unmodelled = cal_mf_correction_unmodelled(&r.correction, N_Y, !kind);
        if (kind) assert_string_equal(unmodelled, "an affine correction");
        else assert_null(unmodelled);
        for (int k = 0; k < N_Y; ++k) {
            assert_float_equal(r.correction.at[k], weighted, 1e-9);
            if (kind) continue;
            assert_float_equal(at_a[k], -9, 0.05);
            assert_true(at_b[k] > weighted + 1 && at_b[k] < -3 - 1);
            assert_true(cal_mf_correction_sd(&r.correction, k, 0.8, 0.5) > 10 * cal_mf_correction_sd(&r.correction, k, 0.2, 0.5));
        }
    }
}

// A correction measured at one run is a single difference: no variance
// model, which the posterior must know (it then takes the correction as exact).
static void one_run_leaves_the_correction_without_a_variance_model(void **state)
{
    (void)state;
    cal_mf_correction one = {0};
    one.at[0] = -0.15; // the plane alone, its mean: kriging needs two runs
    assert_string_equal(cal_mf_correction_unmodelled(&one, N_Y, 1), "one run at this tier (kriging needs two)");
    assert_float_equal(cal_mf_correction_sd(&one, 0, 0.5, 0.5), 0, 0);
    cal_mf_correction two = {0};
    two.n_runs = 2;
    for (int k = 0; k < N_Y; ++k) two.scale[k] = 1;
    assert_null(cal_mf_correction_unmodelled(&two, N_Y, 1));
    two.scale[N_Y - 1] = 0; // GSL could not factor that measurement's system
    assert_string_equal(cal_mf_correction_unmodelled(&two, N_Y, 1), "a kriging GSL could not factor");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_quadratic_is_fitted_exactly),
        cmocka_unit_test(one_run_leaves_the_correction_without_a_variance_model),
        cmocka_unit_test(too_few_points_are_refused),
        cmocka_unit_test(a_weighted_fit_trusts_each_point_by_its_spread),
        cmocka_unit_test(a_constant_bias_is_measured_and_removed),
        cmocka_unit_test(a_varying_bias_converges_within_noise),
        cmocka_unit_test(a_bias_along_mu_r_is_fitted),
        cmocka_unit_test(a_curved_bias_along_mu_r_is_followed),
        cmocka_unit_test(a_failed_run_stops_the_loop),
        cmocka_unit_test(runs_after_the_loop_go_where_asked_and_correct_the_map),
        cmocka_unit_test(the_loop_returns_to_the_optimum_the_posterior_runs_moved),
        cmocka_unit_test(a_run_not_steady_cannot_agree_and_one_unmeasured_is_not_settled),
        cmocka_unit_test(a_run_not_steady_counts_by_its_own_spread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
