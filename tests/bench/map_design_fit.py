#!/usr/bin/env python3
"""How well the ci tier's 4 rpm angle map predicts the lambda 1000 drum, from a store, no simulation.

    python3 tests/bench/map_design_fit.py results/calibration-standard-r2/store

Reads the granule-lined drum records at 4 rpm and k_n 200 N/m: the ci tier's (lambda 32768, the mean
of its beds per pair) and the lambda 1000 runs started from a turned bed (the standard tier's 4 rpm
runs now; a store seeded from older runs also holds level-start ones, left out). Fits the ci angles over (u, v), the search box
(mu_s 0.1-1, log mu_r 0.001-0.5) mapped to the unit square, as the two-tier stage does
(cal_mf_fit): a plane through the grid's candidates (mu_s >= 0.325, the ci tier's design without
corners) and a quadratic through all of them (with the corners, ci-map's design). Prints each
lambda 1000 run beside both maps' predictions there and the discrepancy (lambda 1000 minus map).
Plain least squares, unweighted; a check on the design, not the stage's own kriged map.
"""
import glob
import math
import re
import sys
from collections import defaultdict

MU_S = (0.1, 1.0)
MU_R = (0.001, 0.5)


def unit(mu_s, mu_r):
    return ((mu_s - MU_S[0]) / (MU_S[1] - MU_S[0]),
            (math.log(mu_r) - math.log(MU_R[0])) / (math.log(MU_R[1]) - math.log(MU_R[0])))


def records(store):
    """{lambda: {(mu_s, mu_r): [angle, ...]}} for granule-lined 4 rpm drums at k_n 200."""
    out = defaultdict(lambda: defaultdict(list))
    for path in glob.glob(f"{store}/*.yaml"):
        text = open(path).read()
        key = re.search(r"^key: '(.*)'", text, re.M)
        angle = re.search(r"^angle_deg: ([-0-9.e]+)", text, re.M)
        if not key or not angle or " rpm=4 " not in key.group(1) or "filled_with_wall[same]" not in key.group(1):
            continue
        lam = re.search(r" lambda=(\d+) ", key.group(1))
        g = re.search(r"granule\[k=200,200,200 xi=0\.7 mu=([0-9.e-]+),([0-9.e-]+) ", key.group(1))
        w = re.search(r"wall\[k=400,400,400 xi=0\.7 mu=([0-9.e-]+),([0-9.e-]+) ", key.group(1))
        if lam and int(lam.group(1)) == 1000 and "start=turned" not in key.group(1):
            continue
        if lam and g and w and g.groups() == w.groups():
            out[int(lam.group(1))][(float(g.group(1)), float(g.group(2)))].append(float(angle.group(1)))
    return out


def features(mu_s, mu_r, quadratic):
    u, v = unit(mu_s, mu_r)
    return [1, u, v] + ([u * u, u * v, v * v] if quadratic else [])


def least_squares(rows, y):
    n = len(rows[0])
    a = [[sum(r[i] * r[j] for r in rows) for j in range(n)] for i in range(n)]
    b = [sum(r[i] * yk for r, yk in zip(rows, y)) for i in range(n)]
    for i in range(n):  # Gauss-Jordan with partial pivoting on the normal equations
        p = max(range(i, n), key=lambda k: abs(a[k][i]))
        a[i], a[p], b[i], b[p] = a[p], a[i], b[p], b[i]
        for k in range(n):
            if k != i:
                f = a[k][i] / a[i][i]
                a[k] = [x - f * z for x, z in zip(a[k], a[i])]
                b[k] -= f * b[i]
    return [b[i] / a[i][i] for i in range(n)]


def fit(points, quadratic):
    pairs = sorted(points)
    coef = least_squares([features(s, r, quadratic) for s, r in pairs], [points[p] for p in pairs])
    return lambda s, r: sum(c * x for c, x in zip(coef, features(s, r, quadratic)))


def main():
    recs = records(sys.argv[1])
    ci = {p: sum(v) / len(v) for p, v in recs[32768].items()}
    grid = {p: a for p, a in ci.items() if p[0] >= 0.3}
    plane, quadratic = fit(grid, False), fit(ci, True)
    print(f"ci candidates: {len(grid)} without corners (plane), {len(ci)} with (quadratic)")
    print("| mu_s | mu_r | lambda 1000 (deg) | plane | lambda 1000 - plane | quadratic | lambda 1000 - quadratic |")
    print("|---|---|---|---|---|---|---|")
    for (s, r), v in sorted(recs[1000].items()):
        a = sum(v) / len(v)
        print(f"| {s:.4g} | {r:.4g} | {a:.2f} | {plane(s, r):.1f} | {a - plane(s, r):+.1f} | {quadratic(s, r):.1f} "
              f"| {a - quadratic(s, r):+.1f} |")


if __name__ == "__main__":
    main()
