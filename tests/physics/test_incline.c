// SPDX-License-Identifier: MIT
// A sphere let go on an inclined plane (experiments/incline/) against the
// textbook answer, which the engine does not contain: a solid sphere
// (I = 2/5 m R²) with sliding friction μs and rolling friction μr (torque
// limit μr R N) stays at rest while tan θ ≤ μr, rolls without slip at
// a = (5/7) g (sin θ − μr cos θ) while tan θ ≤ (7/2) μs − (5/2) μr, and slides
// at a = g (sin θ − μs cos θ) beyond. Rolling, the engine's lever arm R − h
// (docs/model.md, `contact_point`) lowers a by ~(4/7)(h/R) ≈ 1e-4 here, so
// rolling is held to 1e-3; sliding, the Coulomb limit is exact and so is a.
// Also: the shipped config loads, and a bad value is named by file and line
// or by its --set.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "exp_incline.h"
#include "config_variant.h"
#include "exp_incline_config.h"

static void shipped_config(char *path, size_t len)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, len, "%s/configs/incline.yaml", src ? src : ".");
}

// The shipped config with `sets` applied, run; the result.
static exp_incline_result run(int n_sets, char **sets)
{
    char path[1024], err[1024];
    shipped_config(path, sizeof path);
    exp_incline_def d;
    if (exp_incline_load(path, n_sets, sets, &d, err, sizeof err)) fail_msg("%s", err);
    exp_incline_result r;
    dem_world *w = exp_incline_run(&d, &r, err, sizeof err);
    if (!w) fail_msg("%s", err);
    dem_world_destroy(w);
    printf("--set %s %s: %s (analytic %s), a = %.6g m/s2 (analytic %.6g, relative error %.2g), slip %.3g m/s\n",
           n_sets > 0 ? sets[0] : "", n_sets > 1 ? sets[1] : "", exp_incline_regime_name(r.regime),
           exp_incline_regime_name(r.analytic.regime), r.acceleration, r.analytic.acceleration, r.relative_error,
           r.slip_speed);
    return r;
}

static void test_rolls_at_five_sevenths(void **state)
{
    (void)state;
    exp_incline_result r = run(0, NULL); // 20°, μs 0.5, μr 0
    assert_int_equal(r.analytic.regime, EXP_INCLINE_ROLLING);
    assert_int_equal(r.regime, EXP_INCLINE_ROLLING);
    assert_true(fabs(r.analytic.acceleration - 5.0 / 7.0 * 9.81 * sin(20 * DEM_PI / 180)) < 1e-12);
    assert_true(fabs(r.relative_error) < 1e-3);
    // Without slip the contact point's rolling speed grows with the centre's.
    assert_true(fabs(r.spin_acceleration / r.acceleration - 1) < 1e-3);
}

static void test_rolling_friction_slows_the_roll(void **state)
{
    (void)state;
    char *sets[] = {"mu_r=0.1"};
    exp_incline_result r = run(1, sets);
    assert_int_equal(r.regime, EXP_INCLINE_ROLLING);
    assert_true(fabs(r.analytic.acceleration - 5.0 / 7.0 * 9.81 * (sin(20 * DEM_PI / 180) - 0.1 * cos(20 * DEM_PI / 180))) <
                1e-12);
    assert_true(fabs(r.relative_error) < 1e-3);
}

static void test_slides_at_coulomb(void **state)
{
    (void)state;
    char *sets[] = {"angle_deg=40", "mu_s=0.1"};
    exp_incline_result r = run(2, sets);
    assert_int_equal(r.analytic.regime, EXP_INCLINE_SLIDING);
    assert_int_equal(r.regime, EXP_INCLINE_SLIDING);
    assert_true(fabs(r.relative_error) < 1e-6);
    // Sliding, friction spins the sphere up at (5/2) μs g cos θ, slower than the centre runs.
    assert_true(fabs(r.spin_acceleration - 2.5 * 0.1 * 9.81 * cos(40 * DEM_PI / 180)) < 1e-3 * r.spin_acceleration);
}

static void test_rolling_friction_holds_it(void **state)
{
    (void)state;
    char *sets[] = {"angle_deg=5", "mu_r=0.1"}; // tan 5° = 0.087 < μr
    exp_incline_result r = run(2, sets);
    assert_int_equal(r.analytic.regime, EXP_INCLINE_REST);
    assert_int_equal(r.regime, EXP_INCLINE_REST);
    assert_true(fabs(r.travel) < 1e-3 * 0.002); // it rocks on its springs, by under a thousandth of its diameter
}

// The two sides of tan θ = (7/2) μs (60.26° at μs 0.5).
static void test_roll_slide_boundary(void **state)
{
    (void)state;
    char *below[] = {"angle_deg=59", "mu_s=0.5"}, *above[] = {"angle_deg=62", "mu_s=0.5"};
    exp_incline_result a = run(2, below), b = run(2, above);
    assert_int_equal(a.analytic.regime, EXP_INCLINE_ROLLING);
    assert_int_equal(a.regime, EXP_INCLINE_ROLLING);
    assert_true(fabs(a.relative_error) < 1e-3);
    assert_int_equal(b.analytic.regime, EXP_INCLINE_SLIDING);
    assert_int_equal(b.regime, EXP_INCLINE_SLIDING);
    assert_true(fabs(b.relative_error) < 1e-6);
}

static void test_bad_input_is_named(void **state)
{
    (void)state;
    char path[1024], tmp[] = "/tmp/granucal_incline_XXXXXX", err[1024];
    shipped_config(path, sizeof path);
    int bad_line = config_variant(path, "mu_s:", "mu_s: -1", tmp);
    assert_true(bad_line > 0);
    exp_incline_def d;
    assert_int_not_equal(exp_incline_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    char want[64];
    snprintf(want, sizeof want, "%s:%d: mu_s", tmp, bad_line);
    printf("%s\n", err);
    assert_non_null(strstr(err, want));
    char *set = "angle_deg=95";
    assert_int_not_equal(exp_incline_load(path, 1, &set, &d, err, sizeof err), 0);
    printf("%s\n", err);
    assert_non_null(strstr(err, "--set angle_deg=95"));
    remove(tmp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rolls_at_five_sevenths), cmocka_unit_test(test_rolling_friction_slows_the_roll),
        cmocka_unit_test(test_slides_at_coulomb),      cmocka_unit_test(test_rolling_friction_holds_it),
        cmocka_unit_test(test_roll_slide_boundary),    cmocka_unit_test(test_bad_input_is_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
