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

// A range: identified [lo, hi], not excluded [bracket_lo, bracket_hi].
static cal_range range(double lo, double hi, double bracket_lo, double bracket_hi)
{
    return (cal_range){lo, hi, NAN, NAN, bracket_lo, bracket_hi};
}

static void test_inside_and_off_the_bounds_is_calibrated(void **state)
{
    (void)state;
    // The standard run's granule μr: 0.1918, identified at itself, not excluded 0.106 – 0.5 (bounds 1e-5, 0.5).
    cal_verdict v = cal_verdict_friction(0.191835, range(0.191835, 0.191835, 0.105737, 0.5), 1e-5, 0.5, 1);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
    assert_string_equal(v.flags, "");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 0.191835, &v), "0.1918");
}

static void test_a_bound_is_one_sided(void **state)
{
    (void)state;
    // The standard run's granule μs: the search's upper bound 1, not excluded 0.775 – 1: only μs ≥ 0.775 is known.
    cal_verdict v = cal_verdict_friction(1.0, range(1.0, 1.0, 0.775, 1.0), 0.1, 1.0, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, +1);
    assert_float_equal(v.known, 0.775, 1e-12);
    assert_string_equal(v.flags, "at_upper_bound");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1.0, &v), "≥ 0.775");
    // The mirror: μr on its lower bound, not excluded up to 3e-4.
    v = cal_verdict_friction(1e-5, range(1e-5, 2e-4, 1e-5, 3e-4), 1e-5, 0.5, 1);
    assert_int_equal(v.status, CAL_VALUE_ONE_SIDED);
    assert_int_equal(v.side, -1);
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1e-5, &v), "≤ 0.0003");
}

static void test_outside_its_own_interval_is_not_a_result(void **state)
{
    (void)state;
    // The standard run's PTFE μr: 0.0025, identified 1.5e-4 only, not excluded 8.6e-5 – 1.9e-3, angle not matched.
    cal_verdict v = cal_verdict_friction(0.00249958, range(0.000149535, 0.000149535, 8.58566e-05, 0.00192339), 1e-5,
                                         0.5, 0);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_string_equal(v.flags, "outside_identified;outside_not_excluded;angle_not_matched");
    // On a bound and outside: not a result wins over one-sided (the aluminium μr: 1e-5, identified 0.033).
    v = cal_verdict_friction(1e-5, range(0.033437, 0.033437, 0.000149535, 0.5), 1e-5, 0.5, 0);
    assert_int_equal(v.status, CAL_VALUE_NOT_A_RESULT);
    assert_int_equal(v.side, 0);
    // A value written at an end of its range to 6 digits stays inside it.
    v = cal_verdict_friction(0.1918351, range(0.191835, 0.191835, 0.105737, 0.5), 1e-5, 0.5, 1);
    assert_int_equal(v.status, CAL_VALUE_CALIBRATED);
}

static void test_nothing_excluded_is_not_identified(void **state)
{
    (void)state;
    // The twin's aluminium μr: every μr of the search range fits the data.
    cal_verdict v = cal_verdict_friction(1e-5, range(1e-5, 0.5, 1e-5, 0.5), 1e-5, 0.5, 1);
    assert_int_equal(v.status, CAL_VALUE_NOT_IDENTIFIED);
    assert_string_equal(v.flags, "at_lower_bound;not_identified");
    char text[48];
    assert_string_equal(cal_verdict_value_text(text, sizeof text, 1e-5, &v), "not identified");
}

static void test_a_stage_not_run_is_not_calibrated(void **state)
{
    (void)state;
    cal_verdict v = cal_verdict_friction(0.8, CAL_NO_RANGE, 0.1, 1.0, -1);
    assert_int_equal(v.status, CAL_VALUE_NOT_RUN);
    assert_string_equal(v.flags, "stage_not_run");
    assert_string_equal(cal_value_status_name(v.status), "stage not run");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_inside_and_off_the_bounds_is_calibrated),
        cmocka_unit_test(test_a_bound_is_one_sided),
        cmocka_unit_test(test_outside_its_own_interval_is_not_a_result),
        cmocka_unit_test(test_nothing_excluded_is_not_identified),
        cmocka_unit_test(test_a_stage_not_run_is_not_calibrated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
