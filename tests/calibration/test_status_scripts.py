#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# The status rules as the two scripts that judge a committed table apply them from its CSV alone
# (check_outputs_say_what.py: the status each row's numbers call for; compare_table3.py: a row the data
# did not choose is scored by its status), on rows built by hand: the committed runs hold no bounded
# value, so without this their 'bounded' branches would run nowhere. The same cases as
# tests/unit/test_status.c, whose C rule they re-implement.
import os, sys, unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_outputs_say_what as says  # noqa: E402
import compare_table3 as compare  # noqa: E402


def row(parameter, value, not_excluded, credible=None, flags=''):
    lo, hi = not_excluded
    r = {'parameter': parameter, 'value': str(value), 'identified_min': str(value), 'identified_max': str(value),
         'not_excluded_min': str(lo), 'not_excluded_max': str(hi), 'credible_min': '', 'credible_max': '',
         'flags': flags}
    if credible:
        r['credible_min'], r['credible_max'] = str(credible[0]), str(credible[1])
    return r


class ExpectedStatus(unittest.TestCase):
    def test_runs_leaving_most_of_the_range_bound_it(self):
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.1016, 0.95)), 0.1, 1.0), 'bounded')
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.1016, 0.95), (0.25, 0.88)), 0.1, 1.0), 'bounded')
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.1016, 0.95), (0.40, 0.76)), 0.1, 1.0),
                         'calibrated')
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.40, 0.80)), 0.1, 1.0), 'calibrated')

    def test_the_scale_decides(self):
        # 0.01 - 0.3 is 0.31 of the decades 1e-5 - 0.5, 0.58 of the range read linearly.
        self.assertEqual(says.expected_status(row('mu_r', 0.05, (0.01, 0.3)), 1e-5, 0.5), 'calibrated')
        self.assertEqual(says.expected_status(row('mu_r', 0.05, (1e-4, 0.3)), 1e-5, 0.5), 'bounded')

    def test_a_wide_posterior_does_not_close_a_side(self):
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.102, 1.0), (0.30, 0.93)), 0.1, 1.0), 'one-sided')
        self.assertEqual(says.expected_status(row('mu_s', 0.569, (0.102, 1.0), (0.40, 0.85)), 0.1, 1.0), 'calibrated')

    def test_a_posterior_taking_its_correction_as_exact_decides_nothing(self):
        # The standard twin's PP μs: the same narrow posterior closes the open side only with a variance
        # model behind its correction; without one the runs' interval decides alone.
        exact = 'not_excluded_to_upper_bound;credible_correction_exact'
        self.assertEqual(says.expected_status(row('mu_s', 0.4435, (0.325, 1.0), (0.378, 0.565)), 0.1, 1.0),
                         'calibrated')
        self.assertEqual(says.expected_status(row('mu_s', 0.4435, (0.325, 1.0), (0.378, 0.565), exact), 0.1, 1.0),
                         'one-sided')
        self.assertEqual(says.expected_status(row('mu_s', 0.7, (0.5, 0.9), (0.1, 0.3), 'credible_correction_exact'),
                                              0.1, 1.0), 'calibrated')

    def test_outside_a_narrow_posterior_is_not_a_result(self):
        self.assertEqual(says.expected_status(row('mu_s', 0.9, (0.1016, 0.95), (0.40, 0.76)), 0.1, 1.0),
                         'not a result')


class Table3Verdict(unittest.TestCase):
    def test_a_bounded_row_is_judged_by_its_interval(self):
        got = row('mu_s', 0.569, (0.1016, 0.95))
        got['status'] = 'bounded'
        verdict, measured = compare.judge_status('abs', 0.8, got)
        self.assertEqual(verdict, 'bounded')
        self.assertIn('agrees with', measured)
        verdict, measured = compare.judge_status('abs', 0.98, got)
        self.assertEqual(verdict, 'bounded')
        self.assertIn('lies outside', measured)


if __name__ == '__main__':
    unittest.main()
