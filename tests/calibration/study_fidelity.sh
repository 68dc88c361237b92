#!/usr/bin/env bash
# `granucal study fidelity` end to end on a tiny ladder: two cheap rungs run, a Table B.1
# rung (lambda 8, full drum) is over the budget and listed with a predicted cost instead;
# the finest rung run has error 0 (errors are against it), the other a finite one; a rerun
# recomputes nothing, and its plan says every run is stored. Then the committed ladder (results/fidelity_ladder/store) is read back at 4 rpm
# and must be called still moving between lambda 1000 and 512.
#   usage: study_fidelity.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cfg="$work/study.yaml"
# The shipped config up to its own ladder, with data paths made absolute, then a tiny ladder.
sed -n '/^fidelity:/q;p' "$src/configs/calibration.yaml" | sed "s#\.\./experiments#$src/experiments#" > "$cfg"
cat >> "$cfg" <<'YAML'
fidelity:
  rpm: [116]
  seeds: 1
  budget_hours: 0.5
  rungs:
    - {name: coarse, lambda: 65536, slice_depth: 0.04, max_time: 0.4, window: 0.1}
    - {name: coarse-long, lambda: 65536, slice_depth: 0.04, max_time: 0.6, window: 0.1}
    - {name: L8-full, lambda: 8, slice_depth: 0, max_time: 6.0, window: 1.0}
YAML
cd "$src"
"$bin" study fidelity "$cfg" --out "$work/out" --jobs 2 --yes > "$work/run1.log" 2>&1 || { cat "$work/run1.log"; exit 1; }
summary="$work/out/fidelity_summary.csv"
cat "$summary"
field() { awk -F, -v r="$1" -v c="$2" 'NR==1{for(i=1;i<=NF;i++)h[$i]=i;next} $1==r{print $h[c]}' "$summary"; }
[ "$(field coarse-long status)" = run ] && [ "$(field coarse status)" = run ] || { echo "the cheap rungs did not run"; exit 1; }
[ "$(field coarse-long finest_rung)" = coarse-long ] || { echo "the longer run of the same lambda is not the finest rung"; exit 1; }
awk -v w="$(field coarse wall_time_per_run_s)" 'BEGIN{exit !(w > 0 && w < 900)}' || { echo "no wall time per run"; exit 1; }
# The finest rung is named as such, never "reference", and no convergence is claimed that
# the ladder did not show (no coarser lambda than the finest was run here).
grep -q "The finest rung run is coarse-long" "$work/out/fidelity.md" || { echo "fidelity.md names no finest rung"; exit 1; }
grep -q "reference" "$work/out/fidelity.md" && { echo "fidelity.md still calls a rung the reference"; exit 1; }
grep -q "No coarser λ was run beside it: its convergence is not shown" "$work/out/fidelity.md" ||
  { echo "fidelity.md claims or omits convergence"; exit 1; }
awk -v e="$(field coarse-long angle_error_deg)" 'BEGIN{exit !(e == 0)}' || { echo "reference error not 0"; exit 1; }
awk -v e="$(field coarse angle_error_deg)" 'BEGIN{exit !(e >= 0 && e < 90)}' || { echo "no finite angle error"; exit 1; }
[ "$(field L8-full status)" = "not run (over budget)" ] || { echo "the lambda 8 rung should be over the budget"; exit 1; }
# Predicted hours: far above the budget (1.5 million granules), and finite.
awk -v p="$(field L8-full predicted_wall_time_s)" 'BEGIN{exit !(p > 3600 && p < 1e12)}' || { echo "bad prediction"; exit 1; }
for f in fidelity.csv fidelity.md fidelity_error_vs_cost.png fidelity_vs_lambda.png; do
  [ -s "$work/out/$f" ] || { echo "missing $f"; exit 1; }
done
# Its plan now counts the stored runs: the two rungs that ran hold their one run each, nothing is left.
plan=$("$bin" study fidelity "$cfg" --out "$work/out" --jobs 2 --plan 2>&1) || { echo "$plan"; exit 1; }
for rung in coarse coarse-long; do
  grep -q "^   $rung .*  1 of 1 stored$" <<< "$plan" || { echo "the plan does not count $rung's stored run: $plan"; exit 1; }
done
grep -q "^== left: 0 of the 2 drum runs not in $work/out/store yet" <<< "$plan" || { echo "the plan's left line: $plan"; exit 1; }
# A rerun reads every simulation back from the store.
"$bin" study fidelity "$cfg" --out "$work/out" --jobs 2 --yes > "$work/run2.log" 2>&1 || { cat "$work/run2.log"; exit 1; }
if grep -q "simulated in" "$work/run2.log"; then echo "the rerun simulated again"; cat "$work/run2.log"; exit 1; fi
# The committed ladder (results/fidelity_ladder/store), read back at 4 rpm: lambda 1000 lies inside the
# 1 deg band of lambda 512 but 0.93 +- 0.15 deg above it (6.2 standard errors of the difference, from the
# seeds' spreads), so the text must say the angle is still moving, not that the ladder levelled off.
mkdir -p "$work/ladder" && cp -r "$src/results/fidelity_ladder/store" "$work/ladder/" && rm -f "$work/ladder/store/"*.turn.h5
"$bin" study fidelity configs/calibration.yaml --out "$work/ladder" --jobs 1 --budget-hours 100 --rpm 4 \
  --rungs L4096-slice15-avg8,L1000-slice12-avg8,L512-slice8-avg8 > "$work/ladder.log" 2>&1 || { cat "$work/ladder.log"; exit 1; }
if grep -q "simulated in" "$work/ladder.log"; then echo "the committed ladder was simulated again"; exit 1; fi
grep -q "but the angle is still moving.*0.93 ± 0.15° (6.2 standard errors" "$work/ladder/fidelity.md" ||
  { echo "the committed ladder's verdict is wrong:"; grep -A1 "finest rung run" "$work/ladder/fidelity.md"; exit 1; }
grep -q "levelled off" "$work/ladder/fidelity.md" && { echo "the committed ladder is called levelled off"; exit 1; }
# --report: one rung's report written beside the ladder's, which stays as it was.
before=$(md5sum < "$work/ladder/fidelity.md")
"$bin" study fidelity configs/calibration.yaml --out "$work/ladder" --report "$work/ladder/one_rung" --jobs 1 \
  --budget-hours 100 --rpm 4 --rungs L512-slice8-avg8 > "$work/one_rung.log" 2>&1 || { cat "$work/one_rung.log"; exit 1; }
[ "$(md5sum < "$work/ladder/fidelity.md")" = "$before" ] || { echo "--report overwrote the ladder's fidelity.md"; exit 1; }
grep -q "The finest rung run is L512-slice8-avg8" "$work/ladder/one_rung/fidelity.md" || { echo "--report wrote no report"; exit 1; }
[ -e "$work/ladder/one_rung/store" ] && { echo "--report made a second store"; exit 1; }
# Several speeds, read back from the committed ladder: every seed's speeds are fetched together, and each
# record must land on its own speed (the values the one-seed-at-a-time study wrote in
# results/fidelity_ladder/fast_speeds_L1000/fidelity.csv); a per-speed table and a plot against the speed.
"$bin" study fidelity configs/calibration.yaml --out "$work/ladder" --report "$work/ladder/speeds" --jobs 2 \
  --budget-hours 100 --rpm 40,80,105,116 --rungs L1000-slice9-avg2 > "$work/speeds.log" 2>&1 || { cat "$work/speeds.log"; exit 1; }
if grep -q "simulated in" "$work/speeds.log"; then echo "the committed fast speeds were simulated again"; exit 1; fi
grep -q "| L1000-slice9-avg2 | 43.21 ± 0.14 / 48.45 ± 0.01 | 51.95 ± 0.07 / 51.47 ± 0.01 | 49.81 ± 0.18 / 57.87 ± 0.22 | 34.63 ± 0.29 / 64.56 ± 0.45 |" \
  "$work/ladder/speeds/fidelity.md" || { echo "the per-speed table is not the committed ladder's:"; grep -A4 "Every speed" "$work/ladder/speeds/fidelity.md"; exit 1; }
[ -s "$work/ladder/speeds/fidelity_vs_rpm.png" ] || { echo "no plot against the speed"; exit 1; }
echo "fidelity study: 2 rungs run, 1 predicted, rerun from the store; the committed ladder read as still moving; --report beside it; the fast speeds read back speed by speed"
