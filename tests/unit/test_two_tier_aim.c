// SPDX-License-Identifier: MIT
// Where the two-tier loop aims (cal_two_tier_objective, the tier key
// angle_aim_sd) on an analytic corrected map whose optimum is known in closed
// form: the angle and the CSA both rise along u, and the CSA's target lies
// past the angle band's upper edge, so the CSA pulls the optimum to that edge.
// With the soft penalty alone the optimum stands just outside the band (the
// standard rerun's loop aimed 0.01-0.04° outside it); narrowed by z sd it
// stands that far inside, and never past the band's centre. Also: the sd the
// loop hands its objective is the run noise and the kriging's sd, in
// quadrature.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>

#include <cmocka.h>

#include "cal_multifidelity.h"
#include "cal_stages.h"

// Target 34.6 ± 0.56° (the standard rerun's granule band), one CSA speed at
// 48 ± 1 %; angle = 30 + 8u, CSA = 40 + 10u (v blind). CSA = 48 at u = 0.8,
// angle 36.4: past the band's upper edge, 35.16°.
enum { N_Y = 2 };

// In doubles (cmocka's assert_float_equal compares floats), saying what differed.
static void assert_near(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol)) {
        print_error("got %.9g, want %.9g (± %.3g)\n", got, want, tol);
        fail();
    }
}
static const double target = 34.6, tolerance = 0.56, run_angle_sd = 0.25;

static cal_friction_result *stage(void)
{
    cal_friction_result *r = calloc(1, sizeof *r);
    r->angle_target = target, r->angle_tolerance = tolerance, r->angle_rpm = 4;
    r->n_rpm = 1, r->csa_data[0] = 48, r->csa_data_sd[0] = 1;
    return r;
}

static cal_mf_map linear_map(void)
{
    cal_mf_map map = {.n_y = N_Y, .n_terms = 3};
    map.coef[0][0] = 30, map.coef[0][1] = 8;  // angle: 1, u
    map.coef[1][0] = 40, map.coef[1][1] = 10; // CSA
    return map;
}

typedef struct aim {
    const cal_friction_result *r;
    double z;
} aim;

static double aimed(const double *y, const double *sd, void *ctx)
{
    const aim *a = ctx;
    return cal_two_tier_objective(a->r, y, sd, a->z);
}

// The corrected map's optimum for z, as the predicted angle there.
static double angle_aimed_at(double z)
{
    cal_friction_result *r = stage();
    cal_mf_map map = linear_map();
    double noise[N_Y] = {tolerance, 1}, run_noise[N_Y] = {run_angle_sd, 0.5};
    aim a = {r, z};
    cal_mf_problem p = {.n_y = N_Y, .objective = aimed, .objective_uses_sd = 1, .noise = noise, .run_noise = run_noise, .ctx = &a};
    double u, v, y[N_Y];
    cal_mf_optimum(&map, NULL, &p, &u, &v);
    cal_mf_predict(&map, u, v, y);
    free(r);
    return y[0];
}

// Where the penalty's slope meets the CSA misfit's at edge e, the optimum
// stands past it by δ = -(d misfit / d angle)·tol² / (2·100): misfit
// (1.25a - 45.5)² per angle a, so δ = -2.5(1.25e - 45.5)·tol²/200.
static double overshoot(double edge) { return -2.5 * (1.25 * edge - 45.5) * tolerance * tolerance / 200; }

static void test_the_band_alone_aims_just_outside_its_edge(void **state)
{
    (void)state;
    double edge = target + tolerance, a = angle_aimed_at(0);
    assert_true(a > edge); // the defect the key answers: outside the band
    assert_near(a, edge + overshoot(edge), 1e-4);
}

static void test_one_sd_aims_one_sd_inside(void **state)
{
    (void)state;
    double edge = target + tolerance - run_angle_sd, a = angle_aimed_at(1);
    assert_near(a, edge + overshoot(edge), 1e-4);
    assert_true(a < target + tolerance - 0.9 * run_angle_sd);
}

static void test_a_margin_wider_than_the_band_aims_at_its_centre(void **state)
{
    (void)state;
    double a = angle_aimed_at(3); // 0.75° > 0.56°: capped at the centre
    assert_near(a, target + overshoot(target), 1e-4);
}

// Under angle_rule misfit the angle is a term of the misfit: no band to narrow.
static void test_the_misfit_rule_ignores_the_margin(void **state)
{
    (void)state;
    cal_friction_result *r = stage();
    r->angle_in_misfit = 1;
    double y[N_Y] = {35.0, 47.0}, sd[N_Y] = {0.4, 0.5};
    assert_near(cal_two_tier_objective(r, y, sd, 2), cal_two_tier_objective(r, y, sd, 0), 0);
    free(r);
}

// The sd each call receives: hypot(run noise, kriging sd) at the point. The
// map returns (u, v) themselves, so the objective knows where it is asked.
typedef struct witness {
    const cal_mf_correction *c;
    const double *run_noise;
    int calls, wrong;
} witness;

static double check_sd(const double *y, const double *sd, void *ctx)
{
    witness *w = ctx;
    w->calls++;
    for (int k = 0; k < N_Y; ++k)
        if (fabs(sd[k] - hypot(w->run_noise[k], cal_mf_correction_sd(w->c, k, y[0], y[1]))) > 1e-12) w->wrong++;
    return (y[0] - 0.3) * (y[0] - 0.3) + (y[1] - 0.6) * (y[1] - 0.6);
}

static void test_the_objective_gets_the_run_noise_and_the_kriging_sd(void **state)
{
    (void)state;
    cal_mf_map map = {.n_y = N_Y, .n_terms = 3};
    map.coef[0][1] = 1, map.coef[1][2] = 1; // y = (u, v)
    cal_mf_correction c = {.n_runs = 2, .run_u = {0.2, 0.8}, .run_v = {0.5, 0.5}};
    for (int k = 0; k < N_Y; ++k) c.scale[k] = 1.5, c.nugget[k][0] = c.nugget[k][1] = 0.01; // weights 0: y unmoved
    double noise[N_Y] = {1, 1}, run_noise[N_Y] = {0.25, 0.5};
    witness w = {&c, run_noise, 0, 0};
    cal_mf_problem p = {.n_y = N_Y, .objective = check_sd, .objective_uses_sd = 1, .noise = noise, .run_noise = run_noise, .ctx = &w};
    double u, v;
    cal_mf_optimum(&map, &c, &p, &u, &v);
    assert_true(w.calls > 41 * 41);
    assert_int_equal(w.wrong, 0);
    // and the kriging's share is real: at a run its sd is small, far from both it is the scale
    assert_true(cal_mf_correction_sd(&c, 0, 0.2, 0.5) < 0.3);
    assert_true(cal_mf_correction_sd(&c, 0, 0.5, 0.0) > 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_the_band_alone_aims_just_outside_its_edge),
        cmocka_unit_test(test_one_sd_aims_one_sd_inside),
        cmocka_unit_test(test_a_margin_wider_than_the_band_aims_at_its_centre),
        cmocka_unit_test(test_the_misfit_rule_ignores_the_margin),
        cmocka_unit_test(test_the_objective_gets_the_run_noise_and_the_kriging_sd),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
