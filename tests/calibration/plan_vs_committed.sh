#!/usr/bin/env bash
# `granucal calibrate --plan`'s EXPECTED cost against what the committed standard run
# (results/calibration-standard/) measured: within 30 % in core-hours and in wall time, or
# the cost model (calib/runs/cal_plan.c, the planner in calib/cli/cal_cmd_calibrate.c) has drifted.
# The plan is made from that run's own config and data copies and its store (where stage
# 1's cylinders lie: the plan takes k_n from them, as the run did); nothing is simulated.
#   Core-hours: the plan's whole calibration against the distinct records of its
#   simulations.csv (wall and settling seconds of each; report.md states the same total).
#   Wall time: the run's measured wall time, between "counted" and "at most" in its
#   README (a session's end killed it once and the time lost is bounded, not known), against
#   the plan's steps it ran: all but stage 1, whose cylinders it found in its store. The
#   prediction must be within 30 % of both ends, so of whatever the run really took.
#   And the plan's replay of that store finds every record use of simulations.csv, nothing left, so
#   --budget-hours (which judges what is left) passes at any budget.
#   usage: plan_vs_committed.sh GRANUCAL SOURCE_DIR
set -euo pipefail
bin=$1 src=$2
run=results/calibration-standard
cd "$src"
plan=$("$bin" calibrate "$run/config.yaml" --tier standard --jobs 2 --plan --out "$run" --data "$run" 2>&1 >/dev/null) ||
  { echo "$plan"; exit 1; }
echo "$plan"
# --budget-hours judges what is left: nothing of a finished run, so the least budget passes.
"$bin" calibrate "$run/config.yaml" --tier standard --jobs 2 --plan --out "$run" --data "$run" --budget-hours 0.001 \
  > /dev/null 2>&1 || { echo "FAIL: --budget-hours refused a finished run's folder, where nothing is left"; exit 1; }
echo "ok   --budget-hours 0.001 on the finished run's folder: nothing left, not refused"
PLAN=$plan python3 - "$run" <<'PY'
import csv, os, re, sys
run = sys.argv[1]
plan = os.environ["PLAN"]
total = re.search(r"^== plan: expected (\d+) simulations, ([0-9.e+]+) core-hours, ([0-9.e+]+) h on 2 worker", plan, re.M)
stage1 = re.search(r"^\s+stiffness\s+\d+ \(\s*\d+\) poured cylinders\s+[0-9.]+ \(\s*[0-9.]+\) core-hours\s+([0-9.]+) \(", plan, re.M)
if not total or not stage1:
    sys.exit("the plan's expected figures were not found in its output")
planned_core_h, planned_wall_h = float(total.group(2)), float(total.group(3)) - float(stage1.group(1))

cost = {}
with open(f"{run}/simulations.csv") as f:
    for r in csv.DictReader(f):
        cost[r["record"]] = float(r["wall_time_s"]) + float(r["fill_wall_time_s"] or 0)
measured_core_h = sum(cost.values()) / 3600
report = open(f"{run}/report.md").read()
stated = re.search(r"Distinct simulations in all: (\d+), ([0-9.]+) core-hours", report)
if not stated or int(stated.group(1)) != len(cost) or abs(float(stated.group(2)) - measured_core_h) > 0.01:
    sys.exit(f"simulations.csv ({len(cost)} records, {measured_core_h:.3f} core-hours) does not match report.md's total")
readme = open(f"{run}/README.md").read()
wall = re.search(r"([0-9.]+) h counted, at most ([0-9.]+) h", readme)
if not wall:
    sys.exit(f"{run}/README.md states no measured wall time ('H h counted, at most H h')")
counted_h, at_most_h = float(wall.group(1)), float(wall.group(2))

fails = 0
def judge(what, predicted, measured):
    global fails
    off = predicted / measured - 1
    ok = abs(off) <= 0.30
    fails += not ok
    print(f"{'ok  ' if ok else 'FAIL'} {what}: expected {predicted:.2f}, measured {measured:.2f} ({off:+.0%})")
# The plan replays the store (running nothing): a finished run's store holds every record use its
# simulations.csv lists, so nothing is left.
with open(f"{run}/simulations.csv") as f:
    uses = sum(1 for _ in csv.DictReader(f))
left = re.search(r"^== left: nothing; .* \((\d+) found\)", plan, re.M)
ok = left is not None and int(left.group(1)) == uses
fails += not ok
print(f"{'ok  ' if ok else 'FAIL'} the replay of the store: {left.group(0) if left else 'no left line'}; simulations.csv: {uses} uses")
judge("core-hours, whole calibration", planned_core_h, measured_core_h)
judge("wall hours on 2 workers, the steps it ran, against the time counted", planned_wall_h, counted_h)
judge("wall hours on 2 workers, the steps it ran, against the most it took", planned_wall_h, at_most_h)
sys.exit(fails > 0)
PY
