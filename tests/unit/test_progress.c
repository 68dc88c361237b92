// SPDX-License-Identifier: MIT
// A calibration's progress (calib/runs/cal_progress.c): the counts over stages, the
// time left from the measured cost per kind of simulation, worked by hand.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "cal_progress.h"

// Stiffness (4 cylinders), granule (10 drum runs), PTFE (10 drum runs), 2 at once.
static void plan_three(cal_progress *p)
{
    cal_progress_init(p, 2);
    assert_int_equal(cal_progress_plan(p, "stiffness", CAL_RUN_CYLINDER, 4), 0);
    assert_int_equal(cal_progress_plan(p, "granule", CAL_RUN_DRUM, 10), 0);
    assert_int_equal(cal_progress_plan(p, "PTFE", CAL_RUN_DRUM, 10), 0);
}

static void test_no_time_left_before_a_cost(void **state)
{
    (void)state;
    cal_progress p;
    char text[200];
    plan_three(&p);
    assert_true(isnan(cal_progress_eta_s(&p)));
    assert_int_equal(cal_progress_enter(&p, "stiffness"), 0);
    cal_progress_count(&p, CAL_RUN_CYLINDER, 10);
    // Cylinders have a cost now, drum runs not yet: still no time left to give.
    assert_true(isnan(cal_progress_eta_s(&p)));
    cal_progress_describe(&p, text, sizeof text);
    assert_string_equal(text, "step 1 of 3 (stiffness), 1 of ≤ 24 simulations, time left after the first drum run");
}

static void test_time_left_from_measured_costs(void **state)
{
    (void)state;
    cal_progress p;
    char text[200];
    plan_three(&p);
    cal_progress_enter(&p, "stiffness");
    for (int k = 0; k < 4; ++k) cal_progress_count(&p, CAL_RUN_CYLINDER, 10 + 2 * k); // mean 13 s
    cal_progress_enter(&p, "granule");
    cal_progress_count(&p, CAL_RUN_DRUM, 100);
    cal_progress_count(&p, CAL_RUN_DRUM, 300); // mean 200 s
    // Left: 8 granule + 10 PTFE drum runs at 200 s, two at once.
    assert_float_equal(cal_progress_eta_s(&p), 18 * 200.0 / 2, 1e-9);
    cal_progress_describe(&p, text, sizeof text);
    assert_string_equal(text, "step 2 of 3 (granule), 6 of ≤ 24 simulations, ≤ 30 min left");
    // A run with no record (a killed process) counts as done, not as a cost.
    cal_progress_count(&p, CAL_RUN_DRUM, NAN);
    assert_float_equal(cal_progress_eta_s(&p), 17 * 200.0 / 2, 1e-9);
}

// A two-tier stage: the map tier's runs cost their own (10 s), the tier's
// own runs theirs (300 s); one cost for both would put the ETA 30x off.
static void test_map_tier_runs_have_their_own_cost(void **state)
{
    (void)state;
    cal_progress p;
    char text[200];
    cal_progress_init(&p, 1);
    assert_int_equal(cal_progress_plan(&p, "granule (map)", CAL_RUN_MAP_DRUM, 20), 0);
    assert_int_equal(cal_progress_plan(&p, "granule", CAL_RUN_DRUM, 6), 0);
    cal_progress_enter(&p, "granule (map)");
    for (int k = 0; k < 20; ++k) cal_progress_count(&p, CAL_RUN_MAP_DRUM, 10);
    assert_true(isnan(cal_progress_eta_s(&p))); // the tier's own runs have no cost yet
    cal_progress_describe(&p, text, sizeof text);
    assert_string_equal(text, "step 1 of 2 (granule (map)), 20 of ≤ 26 simulations, time left after the first drum run");
    cal_progress_enter(&p, "granule");
    cal_progress_count(&p, CAL_RUN_DRUM, 300);
    assert_float_equal(cal_progress_eta_s(&p), 5 * 300.0, 1e-9);
}

static void test_a_stage_ended_early_leaves_nothing(void **state)
{
    (void)state;
    cal_progress p;
    plan_three(&p);
    cal_progress_enter(&p, "granule");
    cal_progress_count(&p, CAL_RUN_DRUM, 50);
    cal_progress_enter(&p, "PTFE"); // COBYLA converged after one candidate
    cal_progress_count(&p, CAL_RUN_DRUM, 50);
    assert_float_equal(cal_progress_eta_s(&p), 9 * 50.0 / 2, 1e-9);
    for (int k = 0; k < 12; ++k) cal_progress_count(&p, CAL_RUN_DRUM, 50); // past its plan: none left
    assert_float_equal(cal_progress_eta_s(&p), 0, 0);
}

// The plan's expected counts beside the bound: granule and PTFE expected to run 6 of their 10.
static void test_expected_time_beside_the_bound(void **state)
{
    (void)state;
    cal_progress p;
    char text[200];
    plan_three(&p);
    assert_int_equal(cal_progress_expect(&p, "granule", 6), 0);
    assert_int_equal(cal_progress_expect(&p, "PTFE", 6), 0);
    assert_int_equal(cal_progress_expect(&p, "aluminium", 6), 1); // not planned
    assert_int_equal(cal_progress_expect(&p, "stiffness", 40), 0); // never above the plan's bound
    cal_progress_enter(&p, "granule");
    for (int k = 0; k < 2; ++k) cal_progress_count(&p, CAL_RUN_DRUM, 600);
    // Left: at most 8 + 10, expected 4 + 6, at 600 s, two at once.
    assert_float_equal(cal_progress_eta_s(&p), 18 * 600.0 / 2, 1e-9);
    assert_float_equal(cal_progress_expected_eta_s(&p), 10 * 600.0 / 2, 1e-9);
    cal_progress_describe(&p, text, sizeof text);
    assert_string_equal(text, "step 2 of 3 (granule), 2 of ≤ 24 simulations, ~50 min left expected, ≤ 1.5 h");
    // A stage past its expected count has no expected runs left, only its bound's.
    for (int k = 0; k < 5; ++k) cal_progress_count(&p, CAL_RUN_DRUM, 600);
    assert_float_equal(cal_progress_expected_eta_s(&p), 6 * 600.0 / 2, 1e-9);
    assert_float_equal(cal_progress_eta_s(&p), 13 * 600.0 / 2, 1e-9);
}

static void test_unplanned_and_null(void **state)
{
    (void)state;
    cal_progress p;
    char text[8] = "x";
    plan_three(&p);
    assert_int_equal(cal_progress_enter(&p, "aluminium"), 1);
    cal_progress_count(NULL, CAL_RUN_DRUM, 1);
    assert_int_equal(cal_progress_enter(NULL, "granule"), 0);
    cal_progress_describe(NULL, text, sizeof text);
    assert_string_equal(text, "");
    cal_progress_init(&p, 0);
    for (int k = 0; k < CAL_PROGRESS_MAX_STAGES; ++k) assert_int_equal(cal_progress_plan(&p, "s", CAL_RUN_DRUM, 1), 0);
    assert_int_equal(cal_progress_plan(&p, "one too many", CAL_RUN_DRUM, 1), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_no_time_left_before_a_cost),
                                       cmocka_unit_test(test_time_left_from_measured_costs),
        cmocka_unit_test(test_map_tier_runs_have_their_own_cost),
                                       cmocka_unit_test(test_a_stage_ended_early_leaves_nothing),
                                       cmocka_unit_test(test_expected_time_beside_the_bound),
                                       cmocka_unit_test(test_unplanned_and_null)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
