#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Issue 5, "the same for a whole calibration at each tier": how far each tier's
# calibrated (mu_s, mu_r) land from Table 3 (the paper's calibration at
# lambda = 64, the finest answer there is) and what each cost.
#
#   tier_table.py results/paper_table3.csv LABEL=RUN_DIR [LABEL=RUN_DIR ...] > table.md
#
# RUN_DIR is a `granucal calibrate --out` directory (calibrated_parameters.csv,
# simulations.csv, report.md). Cost: the single-core seconds of its distinct
# simulations (a record shared by two stages counted once, fills included) and
# the run's wall time from report.md. mu_s deviations are differences; mu_r
# deviations are in decades (log10), as the wall mu_r spans decades.
import csv, math, re, sys

def table(path):
    return {(r['contact'], r['material'], r['parameter']): float(r['value']) for r in csv.DictReader(open(path))}

def cost(run):
    seen, total = set(), 0.0
    for r in csv.DictReader(open(run + '/simulations.csv')):
        if r['record'] in seen: continue
        seen.add(r['record'])
        total += sum(float(r[k]) for k in ('wall_time_s', 'fill_wall_time_s') if r.get(k) not in (None, ''))
    return len(seen), total

def header(run):
    text = open(run + '/report.md').read()
    tier = re.search(r"tier `([^`]*)` \(drum λ = (\d+)", text)
    wall = re.search(r"([0-9.]+) s wall", text)
    return (tier.group(1), tier.group(2)) if tier else ('?', '?'), float(wall.group(1)) if wall else float('nan')

paper = table(sys.argv[1])
entries = [(c, m, p) for (c, m, p) in paper if p in ('mu_s', 'mu_r') or (p == 'k_n' and c == 'granule-granule')]
def name(e): return ('%s %s' % (e[1] or 'granule', e[2])).replace('granule-granule', '')
print('| tier (run) | λ | simulations | single-core s | wall s | ' + ' | '.join(name(e) for e in entries) + ' |')
print('|---|---|---|---|---|' + '---|' * len(entries))
print('| Table 3 (paper) | 64 | | | | ' + ' | '.join('%.4g' % paper[e] for e in entries) + ' |')
for arg in sys.argv[2:]:
    label, run = arg.split('=', 1)
    (tier, lam), wall = header(run)
    n, single = cost(run)
    got = table(run + '/calibrated_parameters.csv')
    cells = []
    for e in entries:
        v, p = got[e], paper[e]
        if e[2] == 'mu_s': cells.append('%.3g (%+.2f)' % (v, v - p))
        else: cells.append('%.3g (%+.2f dec)' % (v, math.log10(v / p)))
    print('| %s (%s) | %s | %d | %.0f | %.0f | %s |' % (tier, label, lam, n, single, wall, ' | '.join(cells)))
