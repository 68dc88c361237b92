#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Every output of a calibration says what it is (calib/outputs/cal_status.h):
#   check_outputs_say_what.py RUN_DIR --tier T --purpose calibration|demonstration --data "angle lab / CSA synthetic"
# - calibrated_parameters.csv: every row carries tier, lambda, data and purpose as given, and a status;
#   every friction row's status follows from its own numbers (value, identified range, not-excluded
#   interval, the posterior's 95 % credible interval, the search bounds read from the run's config.yaml):
#   a value on a bound is never 'calibrated', a value outside its own interval is 'not a result', and so is
#   one outside its credible interval unless beyond an end that runs to within 3 % of the search range
#   (μs linear, μr in log10) of its bound; a posterior closes a side the runs leave open only where it is
#   held off that bound and spans at most half the search range; runs that close both sides but leave
#   more than half the range, with no posterior narrower than that, make it 'bounded'; a posterior
#   flagged credible_correction_exact (its correction has no variance model) decides none of this;
# - calibrated_parameters.md, report.md, liggghts_parameters.in, lammps_parameters.in: the banner
#   (DEMONSTRATION or CALIBRATION, the tier, the data's provenance); the two .in files list every
#   friction the data did not choose (and the stiffness where stage 1 did not choose it) on a
#   'NOT CALIBRATED:' line, and no other.
# Exit 1 on any failure, naming it.
import csv, math, sys

import yaml  # python3-yaml (.ci/setup)

FRICTION_STATUSES = {'calibrated', 'one-sided', 'bounded', 'not identified', 'not a result', 'stage not run'}


def bounds(run_dir):
    """The search bounds the run used: its config.yaml's granule: and wall: mappings."""
    with open(run_dir + '/config.yaml') as f:
        config = yaml.safe_load(f)
    return {(block, k): float(v) for block in ('granule', 'wall') for k, v in config[block].items()}


def search_scale(parameter):
    """The search's own scale: mu_r in log10, mu_s linear."""
    return math.log10 if parameter == 'mu_r' else (lambda x: x)


def reaches_bounds(parameter, lo, hi, lo_bound, hi_bound):
    """Whether an interval [lo, hi] runs to within 3 % of the search range (mu_r in log10) of each bound:
    (reaches the lower, reaches the upper). Also twin_coverage.py's rule."""
    unit = search_scale(parameter)
    span = unit(hi_bound) - unit(lo_bound)
    return ((unit(lo) - unit(lo_bound)) / span <= 0.03 + 1e-6, (unit(hi_bound) - unit(hi)) / span <= 0.03 + 1e-6)


def range_fraction(parameter, lo, hi, lo_bound, hi_bound):
    """The width of [lo, hi] as a fraction of the search range (mu_r in log10)."""
    unit = search_scale(parameter)
    return (unit(hi) - unit(lo)) / (unit(hi_bound) - unit(lo_bound))


def posterior_decides(r):
    """A posterior decides a status where there is one and it does not take its correction as exact
    (flag credible_correction_exact: a correction measured at one run, or fitted as a plane, has no
    variance model, so the posterior's width says nothing of how well the runs measured it)."""
    return r.get('credible_min', '') != '' and 'credible_correction_exact' not in r['flags'].split(';')


def outside_credible(r, v, lo_bound, hi_bound, outside):
    """Outside the posterior's 95 % credible interval, and not beyond an end that reaches its bound."""
    if not posterior_decides(r):
        return False
    clo, chi = float(r['credible_min']), float(r['credible_max'])
    reaches_lower, reaches_upper = reaches_bounds(r['parameter'], clo, chi, lo_bound, hi_bound)
    if not outside(clo, chi):
        return False
    return not ((v > chi and reaches_upper) or (v < clo and reaches_lower))


def expected_status(r, lo_bound, hi_bound):
    if r['identified_min'] == '':
        return 'stage not run'
    v = float(r['value'])
    lo, hi = float(r['identified_min']), float(r['identified_max'])
    blo, bhi = float(r['not_excluded_min']), float(r['not_excluded_max'])
    slack = 1e-6
    outside = lambda a, b: v < a * (1 - slack) or v > b * (1 + slack)
    near = lambda a, b: abs(a - b) <= 1e-9 * abs(b)
    if outside(lo, hi) or outside(blo, bhi) or outside_credible(r, v, lo_bound, hi_bound, outside):
        return 'not a result'
    if near(blo, lo_bound) and near(bhi, hi_bound):
        return 'not identified'
    if near(v, lo_bound) or near(v, hi_bound):
        return 'one-sided'
    # Off the bounds, the interval no run excludes open to one of them: one side only is known, unless a
    # posterior is held off that bound (it closes the side the runs' cut leaves open).
    open_lo, open_hi = near(blo, lo_bound), near(bhi, hi_bound)
    if open_lo or open_hi:
        if not posterior_decides(r):
            return 'one-sided'
        clo, chi = float(r['credible_min']), float(r['credible_max'])
        reaches_lower, reaches_upper = reaches_bounds(r['parameter'], clo, chi, lo_bound, hi_bound)
        if reaches_upper if open_hi else reaches_lower:
            return 'one-sided'
        if range_fraction(r['parameter'], clo, chi, lo_bound, hi_bound) > 0.5 + 1e-6:
            return 'one-sided'  # held off the bound, but the posterior still spans most of the range
        return 'calibrated'
    # Closed on both sides by the runs: calibrated where they, or a posterior, leave at most half the range.
    if range_fraction(r['parameter'], blo, bhi, lo_bound, hi_bound) > 0.5 + 1e-6:
        if not posterior_decides(r) or range_fraction(r['parameter'], float(r['credible_min']),
                                                              float(r['credible_max']), lo_bound, hi_bound) > 0.5 + 1e-6:
            return 'bounded'
    return 'calibrated'


def check_csv(run_dir, want, fails):
    b = bounds(run_dir)
    with open(run_dir + '/calibrated_parameters.csv') as f:
        rows = list(csv.DictReader(f))
    if not rows:
        fails.append('calibrated_parameters.csv: no rows')
    not_chosen = []
    for r in rows:
        name = ' '.join(x for x in (r['contact'], r['material'], r['parameter']) if x)
        for field in ('tier', 'data', 'purpose'):
            if r.get(field) != want[field]:
                fails.append('csv %s: %s is %r, expected %r' % (name, field, r.get(field), want[field]))
        if not r.get('status'):
            fails.append('csv %s: no status' % name)
        if r['parameter'] not in ('mu_s', 'mu_r'):
            if r['status'] == 'stage not run' and r['parameter'] == 'k_n' and r['contact'] == 'granule-granule':
                not_chosen.append((r, name))  # the config's stiffness: the exports must say so too
            continue
        block = 'granule' if r['contact'] == 'granule-granule' else 'wall'
        p = r['parameter']
        expected = expected_status(r, b[(block, p + '_min')], b[(block, p + '_max')])
        if r['status'] != expected:
            fails.append('csv %s: status %r, its numbers say %r' % (name, r['status'], expected))
        if r['status'] != 'calibrated':
            not_chosen.append((r, name))
    return not_chosen


def check_banner(path, want, fails):
    with open(path) as f:
        text = f.read()
    head = 'DEMONSTRATION - not a calibration of this powder' if want['purpose'] == 'demonstration' else 'CALIBRATION at'
    for needle in (head, "tier '%s'" % want['tier']):
        if needle not in text:
            fails.append('%s: no %r' % (path, needle))
    angle_synthetic, csa_synthetic = ('angle synthetic' in want['data']), ('CSA synthetic' in want['data'])
    data_line = [l for l in text.splitlines() if 'Data: repose angle' in l]
    if len(data_line) != 1:
        fails.append('%s: %d data provenance lines' % (path, len(data_line)))
    else:
        said = data_line[0].split('occupied area')
        if ('SYNTHETIC' in said[0]) != angle_synthetic or ('SYNTHETIC' in said[1]) != csa_synthetic:
            fails.append('%s: the data line says %r for data %r' % (path, data_line[0], want['data']))
    return text


def check_exports(run_dir, want, not_chosen, fails):
    for name in ('liggghts_parameters.in', 'lammps_parameters.in'):
        path = run_dir + '/' + name
        text = check_banner(path, want, fails)
        lines = [l for l in text.splitlines() if l.startswith('# NOT CALIBRATED: ')]
        for r, row_name in not_chosen:
            hits = [l for l in lines if l.startswith('# NOT CALIBRATED: %s = ' % row_name) and r['status'] in l]
            if len(hits) != 1:
                fails.append('%s: %d NOT CALIBRATED lines for %s (%s)' % (name, len(hits), row_name, r['status']))
        if len(lines) != len(not_chosen):
            fails.append('%s: %d NOT CALIBRATED lines for %d values' % (name, len(lines), len(not_chosen)))


def main():
    args = sys.argv[1:]
    if len(args) != 7 or args[1::2] != ['--tier', '--purpose', '--data']:
        print(__doc__ or 'usage: check_outputs_say_what.py RUN_DIR --tier T --purpose P --data D', file=sys.stderr)
        return 2
    run_dir = args[0]
    want = {'tier': args[2], 'purpose': args[4], 'data': args[6]}
    fails = []
    not_chosen = check_csv(run_dir, want, fails)
    for name in ('calibrated_parameters.md', 'report.md'):
        check_banner(run_dir + '/' + name, want, fails)
    check_exports(run_dir, want, not_chosen, fails)
    for f in fails:
        print('FAIL: ' + f)
    if fails:
        print('%d failure(s)' % len(fails))
    else:
        print('ok   every output says what it is (%s, tier %s, %s); %d value(s) the data did not choose, '
              'each marked' % (want['purpose'], want['tier'], want['data'], len(not_chosen)))
    return 1 if fails else 0


if __name__ == '__main__':
    sys.exit(main())
