#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# A calibrated table's Markdown warns exactly where a value lies outside its identified range
# (a two-tier search chooses among its own runs, while the range also holds the map tier's
# corrected candidates, so the chosen value can fall outside it).
#   check_value_in_range.py RUN_DIR [--expect-outside]
# Checks every friction row of RUN_DIR/calibrated_parameters.csv against its row in
# calibrated_parameters.md: the warning is there if and only if value < identified_min or
# value > identified_max. With --expect-outside it also fails when no row lies outside (the
# run it checks is known to have one, so the check exercises both branches).
import csv, sys

WARNING = 'the value lies outside it'


def md_row(md_lines, r):
    symbol = {'mu_s': 'μs', 'mu_r': 'μr'}[r['parameter']]
    if r['contact'] == 'granule-granule':
        needle = '%s,g-g |' % symbol
    else:
        needle = '%s,g-s | %s |' % (symbol, r['material'])
    found = [line for line in md_lines if needle in line]
    if len(found) != 1:
        raise ValueError('%d Markdown rows for %s' % (len(found), needle))
    return found[0]


def main():
    run_dir = sys.argv[1]
    expect_outside = '--expect-outside' in sys.argv[2:]
    with open(run_dir + '/calibrated_parameters.md') as f:
        md = f.readlines()
    with open(run_dir + '/calibrated_parameters.csv') as f:
        rows = [r for r in csv.DictReader(f) if r['parameter'] in ('mu_s', 'mu_r') and r['identified_min']]
    fails, outside = 0, 0
    for r in rows:
        value, lo, hi = float(r['value']), float(r['identified_min']), float(r['identified_max'])
        out = value < lo or value > hi
        outside += out
        warned = WARNING in md_row(md, r)
        name = '%s %s %s' % (r['contact'], r['material'], r['parameter'])
        if out != warned:
            print('FAIL: %s = %g, identified %g – %g, warning %s' % (name, value, lo, hi, 'shown' if warned else 'missing'))
            fails += 1
        else:
            print('ok   %s = %g, identified %g – %g%s' % (name, value, lo, hi, ' (outside: warned)' if out else ''))
    if expect_outside and not outside:
        print('FAIL: no value lies outside its range, so the warning was not exercised')
        fails += 1
    return 1 if fails or not rows else 0


if __name__ == '__main__':
    sys.exit(main())
