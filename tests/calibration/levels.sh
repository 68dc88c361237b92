#!/usr/bin/env bash
# Three levels (issue 37, item 2): the check tier maps, check-two-tier decides on that map, and
# check-two-tier's result (its runs and its corrected map's predictions) maps for check-levels.
# `granucal calibrate --tier check-levels --material PTFE` from scratch, then from its outputs:
#  - the plan (--plan, before anything runs) names every level, each with its tier, and the
#    top level's planned runs are its max_evaluations times its speeds;
#  - each level ran: simulations.csv has rows for "PTFE (map 2)" (check), "PTFE (map)"
#    (check-two-tier) and "PTFE" (check-levels), and the progress lines went through the three;
#  - the top level's runs are at most its max_evaluations;
#  - report.md lists each level with its runs and its cost, in its levels table and its cost
#    table (a row a level each), and they agree with each other and with simulations.csv.
#   usage: levels.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier check-levels --material PTFE --jobs 2 --checkpoint-every 0)
"$bin" "${args[@]}" --plan --out "$work/out" > "$work/plan.log" 2>&1 || { cat "$work/plan.log"; exit 1; }
[ ! -e "$work/out" ] || { echo "--plan made the results folder"; exit 1; }
"$bin" "${args[@]}" --out "$work/out" > "$work/run.log" 2>&1 || { cat "$work/run.log"; exit 1; }
python3 - "$work" configs/calibration.yaml <<'PY'
import csv, re, sys
work, config = sys.argv[1], sys.argv[2]
levels = [("PTFE (map 2)", "check"), ("PTFE (map)", "check-two-tier"), ("PTFE", "check-levels")]
sys.path.insert(0, "tests/calibration")
from checks import check, finish, tier_int  # noqa: E402

max_evaluations = tier_int(config, "check-levels", "max_evaluations")  # the top tier's

plan = open(f"{work}/plan.log").read()
for label, tier in levels:
    step = re.search(rf"^   {re.escape(label)}\s+(\d+) \(\s*\d+\) drum runs at tier '{re.escape(tier)}'\s+([0-9.]+) \(", plan, re.M)
    check(step is not None, f"the plan names level {label!r} at tier '{tier}'")
    if label == "PTFE" and step:
        check(int(step.group(1)) == 2 * max_evaluations,
              f"the plan's top level runs {step.group(1)} = max_evaluations {max_evaluations} x 2 speeds (116 rpm, 4 rpm for the angle)")

rows = list(csv.DictReader(open(f"{work}/out/simulations.csv")))
cost = {}
for label, tier in levels:
    mine = [r for r in rows if r["stage"] == label]
    candidates = {(r["mu_s"], r["mu_r"]) for r in mine}
    cost[label] = (len(candidates), len(mine), sum(float(r["wall_time_s"]) + float(r["fill_wall_time_s"] or 0) for r in mine) / 3600)
    check(len(mine) > 0, f"level {label!r} ran: {len(candidates)} candidates, {len(mine)} simulations in simulations.csv")
check(0 < cost["PTFE"][0] <= max_evaluations, f"the top level ran {cost['PTFE'][0]} candidates, at most its max_evaluations {max_evaluations}")

log = open(f"{work}/run.log").read()
for label, _ in levels:
    check(f"({label})" in log, f"progress lines name the step {label!r}")

# The report's levels table and cost table, a row a level. simulations.csv lists a level below
# the top through the predicted candidates standing for its runs, so not a run whose measurement
# failed (as two tiers always did): a level's row has at least the candidates listed there, the
# top level's exactly its own.
report = open(f"{work}/out/report.md").read()
for n, (label, tier) in enumerate(levels, 1):
    listed = cost[label][0]
    row = re.search(rf"^\| {n} \| {re.escape(tier)} \| 65536 \| (\d+) \| (\d+) \| ([0-9.]+) \|", report, re.M)
    runs, sims, core_h = (int(row.group(1)), int(row.group(2)), float(row.group(3))) if row else (0, 0, 0.0)
    check(row is not None and runs >= listed and (label != "PTFE" or runs == listed) and sims >= runs and core_h > 0,
          f"report.md's levels table: level {n}, tier '{tier}': {runs} runs, {sims} simulations, {core_h} core-hours "
          f"({listed} candidates in simulations.csv)")
    costed = re.search(rf"^\| PTFE \| {re.escape(tier)} \| (\d+) \| (\d+) \| ([0-9.]+) \|$", report, re.M)
    check(costed is not None and int(costed.group(1)) == runs and int(costed.group(2)) == sims
          and abs(float(costed.group(3)) - core_h) < 0.006,
          f"report.md's cost table: tier '{tier}' with its {runs} runs, {sims} simulations and core-hours")
finish()
PY
