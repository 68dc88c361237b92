#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# A twin's coverage (issue 35, item 5): a calibration on data made by its own drum at known pairs must
# find them. For every friction of RESULTS_DIR/calibrated_parameters.csv:
#  - covered: the true value (the pairs named in the data file's "# Made by: granucal synthesize" line)
#    lies inside the posterior's 95 % credible interval (credible_min - credible_max);
#  - narrowed, where the data can tell the parameter (report.md's table "What each measurement can
#    tell" for that stage: some measurement moves by one data spread or more across the parameter's
#    range): the interval does not run to both search bounds (3 % of the range, mu_r in log10, as
#    cal_posterior.c's "reaches"), i.e. the data exclude part of the range at 95 %.
# Prints a Markdown table (friction, truth, value, status, interval, covered, told, narrowed) and exits
# 1 when a friction is not covered, or is told but not narrowed.
#   usage: twin_coverage.py RESULTS_DIR [--report-only]
import csv, os, re, sys

import yaml  # python3-yaml (.ci/setup)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_outputs_say_what import reaches_bounds  # noqa: E402  (one home for the 3 % rule)


def truths(results):
    made = next(l for l in open(f"{results}/repose_angle.csv") if l.startswith("# Made by: granucal synthesize"))
    pairs = {"": tuple(map(float, re.search(r"--granule (\S+)", made).group(1).split(",")))}
    for name, mu in re.findall(r"--wall (\S+?)=(\S+)", made):
        pairs[name] = tuple(map(float, mu.split(",")))
    return pairs


def told(results):
    """Per stage heading ('' the granule stage) and parameter: some measurement moves >= 1 data spread."""
    out, stage = {}, None
    for line in open(f"{results}/report.md"):
        h = re.match(r"^## (\S+) \(surface", line)
        if h:
            stage = "" if h.group(1) == "granule-granule" else h.group(1)
        row = re.match(r"^\| (angle|CSA) at [0-9.]+ rpm \| [0-9.e+-]+ \| ([+-]?[0-9.e+-]+) \| ([+-]?[0-9.e+-]+) \|$", line)
        if row and stage is not None:
            s = out.setdefault(stage, {"mu_s": False, "mu_r": False})
            s["mu_s"] |= abs(float(row.group(2))) >= 1
            s["mu_r"] |= abs(float(row.group(3))) >= 1
    return out


def main():
    results = sys.argv[1]
    report_only = "--report-only" in sys.argv
    config = yaml.safe_load(open(f"{results}/config.yaml"))
    truth, can_tell = truths(results), told(results)
    fails = []
    print("| friction | truth | value | status | 95 % credible | covered | data tell it | narrowed |")
    print("|---|---:|---:|---|---|---|---|---|")
    for r in csv.DictReader(open(f"{results}/calibrated_parameters.csv")):
        p = r["parameter"]
        if p not in ("mu_s", "mu_r") or r["material"] not in truth:
            continue
        t = truth[r["material"]][0 if p == "mu_s" else 1]
        name = f"{r['material'] or 'granule'} {p}"
        if r["credible_min"] == "":
            fails.append(f"{name}: no posterior")
            print(f"| {name} | {t:g} | {r['value']} | {r['status']} | none | no | - | - |")
            continue
        lo, hi = float(r["credible_min"]), float(r["credible_max"])
        b = config["wall" if r["material"] else "granule"]
        reaches_both = all(reaches_bounds(p, lo, hi, float(b[p + "_min"]), float(b[p + "_max"])))
        covered = lo * (1 - 1e-6) <= t <= hi * (1 + 1e-6)
        tells = can_tell.get(r["material"], {}).get(p, False)
        narrowed = not reaches_both
        if not covered:
            fails.append(f"{name}: truth {t:g} outside {lo:.3g} - {hi:.3g}")
        if tells and not narrowed:
            fails.append(f"{name}: the data tell it, but its interval runs to both bounds")
        print(f"| {name} | {t:g} | {float(r['value']):.4g} | {r['status']} | {lo:.3g} – {hi:.3g} | "
              f"{'yes' if covered else '**no**'} | {'yes' if tells else 'no'} | "
              f"{'yes' if narrowed else ('**no**' if tells else 'no')} |")
    for f in fails:
        print("FAIL " + f)
    print(f"{len(fails)} failure(s)")
    return 1 if fails and not report_only else 0


sys.exit(main())
