// SPDX-License-Identifier: MIT
// What each value of a calibrated table is (calib/outputs/cal_status.c): a value the
// data did not choose is never called calibrated. Each case is built by hand
// from the definitions (a search bound, an identified range, the interval no
// candidate excludes), including the standard run's own rows.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "cal_status.h"

// The search bounds of the cases below, the shipped config's: the walls' (μr from 1e-5) and the
// granule's (μr from 1e-3), which the standard run's granule rows use.
static const cal_bounds box = {0.1, 1.0, 1e-5, 0.5}, granule_box = {0.1, 1.0, 1e-3, 0.5};

// A range: identified [lo, hi], not excluded [bracket_lo, bracket_hi].
static cal_range range(double lo, double hi, double bracket_lo, double bracket_hi)
{
    return (cal_range){lo, hi, NAN, NAN, bracket_lo, bracket_hi};
}

static void test_inside_and_off_the_bounds_is_calibrated(void **state)
{
    (void)state;
    // The ci twin's PP μs: 0.775, identified at itself, not excluded 0.55 – 0.9 (bounds 0.1, 1).
    cal_verdict v = cal_verdict_friction(0.775, range(0.775, 0.775, 0.55, 0.9), &box, 0, 1);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_string_equal(v.flags, "");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.775, &v), "0.775");
}

static void test_an_interval_open_to_a_bound_is_one_sided(void **state)
{
    (void)state;
    char text[48];
    // The quick tier's granule μs: the search ended at 0.775, but no run excludes any value from 0.325 up
    // to the bound 1: only μs ≥ 0.325 is known, whatever point the search stopped at.
    cal_verdict v = cal_verdict_friction(0.775, range(0.775, 0.775, 0.325, 1.0), &box, 0, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, +1), assert_int_equal(v.on_bound, 0);
    assert_float_equal(v.known, 0.325, 1e-12);
    assert_string_equal(v.flags, "not_excluded_to_upper_bound");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.775, &v), "≥ 0.325");
    // Its posterior runs to the same bound (0.585 - 0.993): still one-sided.
    cal_credible to_upper = {1, 0.585, 0.993, 0, 1, 0.453, 0};
    cal_verdict_credible(&v, 0.775, &to_upper);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    // A posterior held off that bound closes the side: calibrated, the open interval's flag gone.
    // (The standard run's granule μr: 0.1918, not excluded 0.106 - 0.5, credible 0.098 - 0.33.)
    v = cal_verdict_friction(0.191835, range(0.191835, 0.191835, 0.105737, 0.5), &granule_box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    cal_credible held_off = {1, 0.0983423, 0.329743, 0, 0, 0.195, 0};
    cal_verdict_credible(&v, 0.191835, &held_off);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_int_equal(v.side, 0);
    assert_string_equal(v.flags, "");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.191835, &v), "0.1918");
    // The mirror: the ci-lab run's PP μr 1.5e-4, not excluded from the bound 1e-5 up to 0.0334.
    v = cal_verdict_friction(0.000149535, range(0.000149535, 0.000149535, 1e-5, 0.033437), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, -1);
    assert_string_equal(v.flags, "not_excluded_to_lower_bound");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.000149535, &v), "≤ 0.0334");
    // Other flags stay where the open one goes (the angle not matched).
    v = cal_verdict_friction(0.191835, range(0.191835, 0.191835, 0.105737, 0.5), &granule_box, 1, 0);
    assert_string_equal(v.flags, "angle_not_matched;not_excluded_to_upper_bound");
    cal_verdict_credible(&v, 0.191835, &held_off);
    assert_string_equal(v.flags, "angle_not_matched");
}

static void test_a_bound_is_one_sided(void **state)
{
    (void)state;
    // The standard run's granule μs: the search's upper bound 1, not excluded 0.775 – 1: only μs ≥ 0.775 is known.
    cal_verdict v = cal_verdict_friction(1.0, range(1.0, 1.0, 0.775, 1.0), &box, 0, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, +1);
    assert_float_equal(v.known, 0.775, 1e-12);
    assert_string_equal(v.flags, "at_upper_bound");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1.0, &v), "≥ 0.775");
    // The mirror: μr on its lower bound, not excluded up to 3e-4.
    v = cal_verdict_friction(1e-5, range(1e-5, 2e-4, 1e-5, 3e-4), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, -1);
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1e-5, &v), "≤ 0.0003");
}

static void test_outside_its_own_interval_is_not_a_result(void **state)
{
    (void)state;
    // The standard run's PTFE μr: 0.0025, identified 1.5e-4 only, not excluded 8.6e-5 – 1.9e-3, angle not matched.
    cal_verdict v = cal_verdict_friction(0.00249958, range(0.000149535, 0.000149535, 8.58566e-05, 0.00192339), &box,
                                         1, 0);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_string_equal(v.flags, "outside_identified;outside_not_excluded;angle_not_matched");
    // On a bound and outside: not a result wins over one-sided (the aluminium μr: 1e-5, identified 0.033).
    v = cal_verdict_friction(1e-5, range(0.033437, 0.033437, 0.000149535, 0.5), &box, 1, 0);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_int_equal(v.side, 0);
    // A value written at an end of its range to 6 digits stays inside it.
    v = cal_verdict_friction(0.1918351, range(0.191835, 0.191835, 0.105737, 0.3), &granule_box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
}

static void test_nothing_excluded_is_not_identified(void **state)
{
    (void)state;
    // The twin's aluminium μr: every μr of the search range fits the data.
    cal_verdict v = cal_verdict_friction(1e-5, range(1e-5, 0.5, 1e-5, 0.5), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_NOT_IDENTIFIED);
    assert_string_equal(v.flags, "at_lower_bound;not_identified");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1e-5, &v), "not identified");
}

static void test_outside_its_credible_interval_is_not_a_result(void **state)
{
    (void)state;
    // A value the Δχ² cut keeps (identified at itself, not excluded 1.5e-4 - 0.5) but the posterior puts
    // outside its 95 % credible interval 1.2e-5 - 0.02: not a result, whatever the runs' cut says.
    cal_verdict v = cal_verdict_friction(0.0334, range(0.0334, 0.0334, 1.5e-4, 0.5), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED); // by the runs' cut alone: open to the upper bound
    cal_credible narrow = {1, 1.2e-5, 0.02, 1, 0, 0.686, 0};
    cal_verdict_credible(&v, 0.0334, &narrow);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_string_equal(v.flags, "outside_credible");
    // Inside a posterior held off the upper bound (1e-3 - 0.2, 0.49 of the log range: calibrated), then
    // with no posterior (a stage read from a stage file), nothing changes.
    v = cal_verdict_friction(0.0334, range(0.0334, 0.0334, 1.5e-4, 0.5), &box, 1, 1);
    cal_credible held_off_narrow = {1, 1e-3, 0.2, 0, 0, 0.490, 0}, none = {0};
    cal_verdict_credible(&v, 0.0334, &held_off_narrow);
    cal_verdict_credible(&v, 0.0334, &none);
    cal_verdict_credible(&v, 0.0334, NULL);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_string_equal(v.flags, "");
    // The standard run's granule μs on its upper bound 1.0, credible 0.663 - 0.996 running to that bound: the
    // 97.5 % point of a posterior sits below the bound by construction, so it stays one-sided.
    v = cal_verdict_friction(1.0, range(1.0, 1.0, 0.775, 1.0), &box, 0, 1);
    cal_credible to_upper = {1, 0.662998, 0.995937, 0, 1, 0.370, 0};
    cal_verdict_credible(&v, 1.0, &to_upper);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_string_equal(v.flags, "at_upper_bound");
    // The same bound with a posterior held off it (credible 0.3 - 0.7): the data say the bound is wrong.
    cal_credible held_off = {1, 0.3, 0.7, 0, 0, 0.444, 0};
    cal_verdict_credible(&v, 1.0, &held_off);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_int_equal(v.side, 0);
    assert_string_equal(v.flags, "at_upper_bound;outside_credible");
}

static void test_a_posterior_taking_its_correction_as_exact_decides_nothing(void **state)
{
    (void)state;
    char text[48];
    // The standard twin's PP μs: one λ 1000 run at 0.4435, the runs' interval 0.4435 - 1 (not excluded
    // 0.325 - 1) open to the bound; a posterior 0.378 - 0.565, held off 1 and spanning 0.21 of the range,
    // closed that side and called 0.4435 calibrated (the truth was 0.9). With one run the correction has
    // no variance model, so that width counts nothing of how well it was measured: only μs ≥ 0.325 is known.
    cal_credible one_run = {1, 0.378, 0.565, 0, 0, (0.565 - 0.378) / 0.9, 1};
    cal_verdict v = cal_verdict_friction(0.4435, range(0.4435, 1.0, 0.325, 1.0), &box, 0, 1);
    cal_verdict_credible(&v, 0.4435, &one_run);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, +1);
    assert_float_equal(v.known, 0.325, 1e-12);
    assert_string_equal(v.flags, "not_excluded_to_upper_bound;credible_correction_exact");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.4435, &v), "≥ 0.325");
    assert_string_equal(cal_verdict_posterior_clause(&v),
                        "; its posterior takes a correction with no variance model as exact, and decides nothing");
    // The same posterior with a variance model behind it closes the side, as the rule says.
    cal_credible modelled = one_run;
    modelled.correction_exact = 0;
    v = cal_verdict_friction(0.4435, range(0.4435, 1.0, 0.325, 1.0), &box, 0, 1);
    cal_verdict_credible(&v, 0.4435, &modelled);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    // Nor does it throw out what the runs keep: a value the runs call calibrated, outside that posterior.
    v = cal_verdict_friction(0.7, range(0.6, 0.8, 0.5, 0.9), &box, 0, 1);
    cal_verdict_credible(&v, 0.7, &one_run);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_string_equal(v.flags, "credible_correction_exact");
}

static void test_a_wide_posterior_does_not_close_a_side(void **state)
{
    (void)state;
    char text[48];
    // The standard rerun's granule μs once read: 0.569, no run excluding anything from 0.102 up to the
    // bound 1 (of 0.1 - 1). A posterior 0.30 - 0.93 is held off 1, but spans 0.70 of the range: it does not
    // close that side; only μs ≥ 0.102 is known.
    cal_verdict v = cal_verdict_friction(0.569, range(0.569, 0.569, 0.102, 1.0), &box, 0, 1);
    cal_credible wide = {1, 0.30, 0.93, 0, 0, (0.93 - 0.30) / 0.9, 0};
    cal_verdict_credible(&v, 0.569, &wide);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, +1);
    assert_float_equal(v.known, 0.102, 1e-12);
    assert_string_equal(v.flags, "not_excluded_to_upper_bound;credible_wide");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.569, &v), "≥ 0.102");
    assert_true(cal_verdict_has_flag(&v, "credible_wide"));
    assert_false(cal_verdict_has_flag(&v, "credible")); // a whole flag, not a part of one
    assert_false(cal_verdict_has_flag(&v, "wide"));
    // The same in log μr: 1.2e-5 - 0.2 held off 0.5 spans 0.90 of the decades 1e-5 - 0.5.
    v = cal_verdict_friction(0.0334, range(0.0334, 0.0334, 1.5e-4, 0.5), &box, 1, 1);
    cal_credible wide_log = {1, 1.2e-5, 0.2, 1, 0, 0.898, 0};
    cal_verdict_credible(&v, 0.0334, &wide_log);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_string_equal(v.flags, "not_excluded_to_upper_bound;credible_wide");
    // At the rule's edge: half the range closes the side, a hair more does not.
    v = cal_verdict_friction(0.569, range(0.569, 0.569, 0.102, 1.0), &box, 0, 1);
    cal_credible half = {1, 0.40, 0.85, 0, 0, CAL_CALIBRATED_MAX_WIDTH, 0};
    cal_verdict_credible(&v, 0.569, &half);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    v = cal_verdict_friction(0.569, range(0.569, 0.569, 0.102, 1.0), &box, 0, 1);
    half.width = CAL_CALIBRATED_MAX_WIDTH + 1e-3;
    cal_verdict_credible(&v, 0.569, &half);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    // A value outside a wide posterior is still no result.
    v = cal_verdict_friction(0.95, range(0.95, 0.95, 0.102, 1.0), &box, 0, 1);
    cal_verdict_credible(&v, 0.95, &wide);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
}

static void test_runs_that_leave_most_of_the_range_bound_it(void **state)
{
    (void)state;
    char text[48];
    // Runs excluded at μs 0.1016 and 0.95 (bounds 0.1 - 1), every run between kept: closed on both sides,
    // but 0.94 of the range left: bounded, not calibrated.
    cal_verdict v = cal_verdict_friction(0.569, range(0.569, 0.569, 0.1016, 0.95), &box, 0, 1);
    assert_int_equal(v.status, CAL_VALUE_BOUNDED);
    assert_string_equal(v.flags, "not_excluded_wide");
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.569, &v), "0.102 – 0.95");
    assert_string_equal(cal_value_status_name(v.status), "bounded");
    // A posterior that spans 0.70 of the range leaves it bounded; one of 0.40 holding the value pins it.
    cal_credible wide = {1, 0.25, 0.88, 0, 0, 0.70, 0}, narrow = {1, 0.40, 0.76, 0, 0, 0.40, 0};
    cal_verdict_credible(&v, 0.569, &wide);
    assert_int_equal(v.status, CAL_VALUE_BOUNDED);
    assert_string_equal(v.flags, "not_excluded_wide;credible_wide");
    v = cal_verdict_friction(0.569, range(0.569, 0.569, 0.1016, 0.95), &box, 0, 1);
    cal_verdict_credible(&v, 0.569, &narrow);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_string_equal(v.flags, "");
    // A narrow posterior that excludes the value: not a result, whatever the runs left.
    v = cal_verdict_friction(0.9, range(0.9, 0.9, 0.1016, 0.95), &box, 0, 1);
    cal_verdict_credible(&v, 0.9, &narrow);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_string_equal(v.flags, "outside_credible");
    // In log10 μr: 1e-4 - 0.3 of 1e-5 - 0.5 is 0.74 of the decades: bounded; 0.01 - 0.3 (0.31): calibrated.
    v = cal_verdict_friction(0.05, range(0.05, 0.05, 1e-4, 0.3), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_BOUNDED);
    v = cal_verdict_friction(0.05, range(0.05, 0.05, 0.01, 0.3), &box, 1, 1);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    // The same interval read on a linear scale would be 0.58 of the range: the scale decides.
    const cal_bounds linear = {1e-5, 0.5, 1e-5, 0.5};
    v = cal_verdict_friction(0.05, range(0.05, 0.05, 0.01, 0.3), &linear, 0, 1);
    assert_int_equal(v.status, CAL_VALUE_BOUNDED);
}

static void test_a_stage_not_run_is_not_calibrated(void **state)
{
    (void)state;
    cal_verdict v = cal_verdict_friction(0.8, CAL_NO_RANGE, &box, 0, -1);
    assert_int_equal(v.status, CAL_VALUE_NOT_RUN);
    assert_string_equal(v.flags, "stage_not_run");
    assert_string_equal(cal_value_status_name(v.status), "stage not run");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_inside_and_off_the_bounds_is_calibrated),
        cmocka_unit_test(test_an_interval_open_to_a_bound_is_one_sided),
        cmocka_unit_test(test_a_bound_is_one_sided),
        cmocka_unit_test(test_outside_its_own_interval_is_not_a_result),
        cmocka_unit_test(test_nothing_excluded_is_not_identified),
        cmocka_unit_test(test_outside_its_credible_interval_is_not_a_result),
        cmocka_unit_test(test_a_wide_posterior_does_not_close_a_side),
        cmocka_unit_test(test_a_posterior_taking_its_correction_as_exact_decides_nothing),
        cmocka_unit_test(test_runs_that_leave_most_of_the_range_bound_it),
        cmocka_unit_test(test_a_stage_not_run_is_not_calibrated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
