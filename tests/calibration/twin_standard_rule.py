#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The standard-tier twin's rule (issue 35, item 5), applied to a calibration of twin data.

usage: twin_standard_rule.py CALIBRATION_DIR TRUTH_CSV [--expect FILE]

The twin's data were made at Table 3's pairs (TRUTH_CSV: results/paper_table3.csv) on beds the
candidates do not use; the calibration must find them again. For every friction (granule mu_s and
mu_r, each wall's mu_s and mu_r):

  1. coverage: the true value lies inside both of the table's 95 % intervals: the posterior's
     credible interval (credible_min/max) and the interval no evaluated candidate excludes by
     delta chi^2 > 3.84 (not_excluded_min/max);
  2. width: where the stage's sensitivity table (report.md, "What each measurement can tell") says
     some measurement moves by one data spread or more across that parameter's search range, the
     credible interval spans at most half of that range, in the coordinate the posterior samples
     (mu_s linear, log10 mu_r). A posterior the data do not shape spans 0.95 of it; half says the data
     removed more of the range than they left. Where no measurement moves, the data cannot tell the
     parameter, and only coverage is asked.

Written before the twin's calibration had any posterior (its granule stage had 3 lambda 1000 runs), so
that no part of it is fitted to the result. The search ranges are read from the calibration's own
config.yaml. The verdicts are printed as a Markdown table; exit 0 only if every friction passes. With
--expect FILE (CI, on the committed twin): exit 0 when the verdicts regenerated equal that committed file,
whatever they are, 1 when they differ (as compare_table3.py does): a verdict changes only in a commit
that says so.
"""
import csv
import math
import re
import sys

import yaml


def frictions(path):
    with open(path) as f:
        return [r for r in csv.DictReader(f) if r["parameter"] in ("mu_s", "mu_r")]


def truth_of(path):
    with open(path) as f:
        return {(r["contact"], r["material"], r["parameter"]): float(r["value"])
                for r in csv.DictReader(f) if r["parameter"] in ("mu_s", "mu_r")}


def sensitivities(report):
    """Per stage heading (granule-granule, aluminium, ...): the largest |change| across mu_s and mu_r."""
    out = {}
    for section in re.split(r"^## ", report, flags=re.M)[1:]:
        stage = section.split(" ", 1)[0].strip()
        table = section.split("What each measurement can tell", 1)
        if len(table) < 2:
            continue
        # the table right after that heading, up to the blank line that ends it
        body = table[1].split("\n\n")[1] if "\n\n" in table[1] else ""
        rows = re.findall(r"^\| [^|]+ \| [^|]+ \| ([-+]?[\d.]+) \| ([-+]?[\d.]+) \|$", body, re.M)
        if rows:
            out[stage] = {"mu_s": max(abs(float(a)) for a, _ in rows), "mu_r": max(abs(float(b)) for _, b in rows)}
    return out


def coordinate(parameter, x):
    return math.log10(x) if parameter == "mu_r" else x


def inside(x, lo, hi):
    return lo * (1 - 1e-6) <= x <= hi * (1 + 1e-6)  # the CSV's six significant digits


def judge(row, truth, bounds, moved):
    p = row["parameter"]
    lo, hi = float(row["credible_min"]), float(row["credible_max"])
    ne_lo, ne_hi = float(row["not_excluded_min"]), float(row["not_excluded_max"])
    b_lo, b_hi = bounds[p + "_min"], bounds[p + "_max"]
    share = (coordinate(p, hi) - coordinate(p, lo)) / (coordinate(p, b_hi) - coordinate(p, b_lo))
    fails = []
    if not inside(truth, lo, hi):
        fails.append("outside the credible interval")
    if not inside(truth, ne_lo, ne_hi):
        fails.append("outside the interval not excluded")
    told = moved is not None and moved >= 1
    if told and share > 0.5:
        fails.append(f"credible interval {share:.2f} of the range where the data can tell it")
    if moved is None:
        fails.append("no sensitivity table for its stage")
    return fails, share, told


def main(argv):
    if len(argv) not in (3, 5) or (len(argv) == 5 and argv[3] != "--expect"):
        sys.exit(__doc__)
    folder, truth_csv = argv[1], argv[2]
    truth = truth_of(truth_csv)
    with open(f"{folder}/config.yaml") as f:
        config = yaml.safe_load(f)
    report = sensitivities(open(f"{folder}/report.md").read())
    lines = ["| contact | material | parameter | Table 3 | value (status) | 95 % credible | not excluded | "
             "share of range | data can tell it | verdict |", "|---|---|---|---|---|---|---|---|---|---|"]
    failed = 0
    for row in frictions(f"{folder}/calibrated_parameters.csv"):
        key = (row["contact"], row["material"], row["parameter"])
        stage = row["material"] or "granule-granule"
        bounds = config["granule" if row["contact"] == "granule-granule" else "wall"]
        moved = report.get(stage, {}).get(row["parameter"])
        fails, share, told = judge(row, truth[key], bounds, moved)
        failed += bool(fails)
        lines.append(f"| {row['contact']} | {row['material'] or '-'} | {row['parameter']} | {truth[key]:g} | "
                     f"{float(row['value']):g} ({row['status']}) | {float(row['credible_min']):.3g} – "
                     f"{float(row['credible_max']):.3g} | {float(row['not_excluded_min']):.3g} – "
                     f"{float(row['not_excluded_max']):.3g} | {share:.2f} | "
                     f"{'yes' if told else 'no'} ({moved if moved is not None else '-'} spreads) | "
                     f"{'FAIL: ' + '; '.join(fails) if fails else 'pass'} |")
    verdict = "\n".join(lines) + "\n"
    sys.stdout.write(verdict)
    print(f"{failed} of {len(lines) - 2} friction(s) fail the twin's rule", file=sys.stderr)
    if len(argv) == 5:
        same = open(argv[4]).read() == verdict
        print(f"{'the same as' if same else 'DIFFERS from'} the committed {argv[4]}", file=sys.stderr)
        return 0 if same else 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
