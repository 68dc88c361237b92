#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# The ci tier's own spread (issue 5; protocol in table3_tolerances.h): the same
# calibration at several config seeds, each entry's values, their sample
# standard deviation (mu_s as a value, mu_r and k_n in decades) and the
# tolerance the protocol gives: the larger of the search resolution and twice
# that spread.
#
#   spread_table.py results/paper_table3.csv RUN_DIR [RUN_DIR ...] > spread.md
import csv, math, statistics, sys

RESOLUTION = {('granule-granule', 'mu_s'): 0.225, ('granule-granule', 'mu_r'): 0.68, ('granule-granule', 'k_n'): 0.302,
              ('granule-boundary', 'mu_s'): 0.225, ('granule-boundary', 'mu_r'): 1.17}

def table(path):
    return {(r['contact'], r['material'], r['parameter']): float(r['value']) for r in csv.DictReader(open(path))}

paper = table(sys.argv[1])
runs = [table(d + '/calibrated_parameters.csv') for d in sys.argv[2:]]
print('| entry | Table 3 | ' + ' | '.join('run %d' % (i + 1) for i in range(len(runs))) +
      ' | spread (sd) | resolution | tolerance | run 1 deviation | verdict |')
print('|---|---|' + '---|' * len(runs) + '---|---|---|---|---|')
for key in paper:
    contact, material, parameter = key
    if (contact, parameter) not in RESOLUTION: continue
    log = parameter in ('mu_r', 'k_n')
    scale = (lambda v: math.log10(v)) if log else (lambda v: v)
    values = [r[key] for r in runs]
    sd = statistics.stdev([scale(v) for v in values]) if len(values) > 1 else 0.0
    tol = max(RESOLUTION[(contact, parameter)], 2 * sd)
    dev = scale(values[0]) - scale(paper[key])
    unit = ' dec' if log else ''
    print('| %s %s %s | %.4g | %s | %.3g%s | %.3g%s | %.3g%s | %+.3g%s | %s |' % (
        contact, material or '', parameter, paper[key], ' | '.join('%.4g' % v for v in values), sd, unit,
        RESOLUTION[(contact, parameter)], unit, tol, unit, dev, unit, 'ok' if abs(dev) <= tol else 'OUTSIDE'))
