#!/usr/bin/env python3
"""Mean simulated time and particle-steps of the drum records of a store, by speed (issue 37.1; a measurement,
nothing simulated). Only keys holding every SUBSTRING are read; 4 rpm runs under MSER from a level bed are left out.

    usage: candidate_costs.py STORE_DIR SUBSTRING...   (prints: rpm, runs, mean s simulated, mean particle-steps)
"""
import glob, re, sys
from collections import defaultdict
run, sel = sys.argv[1], sys.argv[2:]          # store folder; substrings every key must hold
by = defaultdict(list)
for f in glob.glob(run + '/*.yaml'):
    t = open(f).read(); key = re.search(r"^key: '(.*)'$", t, re.M).group(1)
    if not key.startswith('drum ') or not all(s in key for s in sel): continue
    if ' rpm=4 ' in key and 'start=turned' not in key and 'steady=mser' in key: continue
    g = lambda k: float(re.search(r'^%s: (\S+)$' % k, t, re.M).group(1))
    by[re.search(r' rpm=(\S+) max_time', key).group(1)].append((g('simulated_time_s'), g('particle_steps')))
for rpm in sorted(by, key=float):
    v = by[rpm]; print(rpm, len(v), round(sum(a for a, _ in v) / len(v), 2), '%.3g' % (sum(b for _, b in v) / len(v)))
