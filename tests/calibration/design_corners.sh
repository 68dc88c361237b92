#!/usr/bin/env bash
# design_corners (a tier key): the initial design adds the search box's four corners to the grid, so
# that a map made from the tier's candidates spans the box (the standard tier maps with ci-map, the ci
# tier with its corners). On the check tier fitting PTFE alone, with design_corners: yes in a copy of
# the shipped config:
#  - the four corners of the wall's bounds are candidates, marked "corner" in report.md, each run on
#    the tier's beds and speeds like a grid point;
#  - --plan counts them: 4 candidates x beds x speeds more drum runs than the shipped check tier's plan;
#  - the shipped check tier (no design_corners) has no corner candidate (tests/CMakeLists.txt's
#    calibrate_reference_check run).
#   usage: [REFERENCE=DIR] design_corners.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
awk '{ print } /^  - name: check$/ { on = 1 } on && /^    grid: / { print "    design_corners: yes"; on = 0 }' \
  configs/calibration.yaml | sed "s|\.\./experiments/|$src/experiments/|" > "$work/corners.yaml"
grep -q "design_corners: yes" "$work/corners.yaml" || { echo "FAIL: design_corners not added to the check tier"; exit 1; }
args=(calibrate --tier check --material PTFE --jobs 2 --checkpoint-every 0)
planned() { "$bin" "${args[@]}" "$1" --plan 2>&1 | sed -n 's/^== plan: expected \([0-9]*\) simulations.*/\1/p'; }
with=$(planned "$work/corners.yaml") without=$(planned configs/calibration.yaml)
"$bin" "${args[@]}" "$work/corners.yaml" --out "$work/out" > "$work/run.log" 2>&1 || { cat "$work/run.log"; exit 1; }
python3 - "$work/out" "$with" "$without" "${REFERENCE:-}" <<'PY'
import csv, sys
sys.path.insert(0, "tests/calibration")
from checks import check, finish  # noqa: E402

out, with_plan, without_plan, reference = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
beds, speeds = 2, 1  # the check tier: seeds 2 (beds), rpm [116]
with open(f"{out}/simulations.csv") as f:
    rows = [r for r in csv.DictReader(f) if r["stage"] == "PTFE" and r["experiment"] == "drum"]
pairs = {(float(r["mu_s"]), float(r["mu_r"])) for r in rows}
corners = [(0.1, 1e-5), (0.1, 0.5), (1.0, 1e-5), (1.0, 0.5)]  # configs/calibration.yaml: wall bounds
for c in corners:
    runs = sum(1 for r in rows if (float(r["mu_s"]), float(r["mu_r"])) == c)
    check(runs == beds * speeds, f"corner {c} is a candidate, run on {runs} bed x speed(s) (want {beds * speeds})")
report = open(f"{out}/report.md").read()
check(report.count("| corner |") == 4, f"report.md marks {report.count('| corner |')} candidates as corners (want 4)")
check(with_plan - without_plan == 4 * beds * speeds,
      f"--plan counts them: {with_plan} drum runs with the corners, {without_plan} without (want {4 * beds * speeds} more)")
if reference:
    ref = open(f"{reference}/report.md").read()
    check("| corner |" not in ref, "the shipped check tier (no design_corners) has no corner candidate")
finish()
PY
