#!/usr/bin/env bash
# granucal synthesize where no seed reaches a steady state (a high-mu_r bed avalanching at 4 rpm
# within max_time): the data point is not dropped, nor the whole synthesis refused; it is the mean of
# the runs that did not settle, its spread at least their series' spread (each mean's error cannot
# exceed it), and the file says which points these are. Made unsteady on purpose here: the
# check-turned tier with a standard-error target no run can reach (0.001) and a short turn.
#   usage: synthesize_unsteady.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
export OMP_NUM_THREADS=1
fail() { echo "FAIL: $*"; exit 1; }
sed -e 's|\.\./experiments/data/|'"$src"'/experiments/data/|' \
    -e '/name: check-turned/,/name: standard/ { s/    steady_se_angle_deg: .*/    steady_se_angle_deg: 0.001/;
        s/    steady_se_csa_percent: .*/    steady_se_csa_percent: 0.001/; s/    max_time: .*/    max_time: 1.0/;
        s/    turned_start_time: .*/    turned_start_time: 0.2/ }' "$src/configs/calibration.yaml" > "$work/unsteady.yaml"
"$bin" synthesize "$work/unsteady.yaml" --tier check-turned --wall aluminium=0.8,0.2 --wall PP=0.9,1e-4 \
  --wall PTFE=0.9,1e-4 --seeds 101 --jobs 1 --out "$work/out" 2> "$work/log" || fail "synthesize refused: $(tail -3 "$work/log")"
angle=$work/out/repose_angle.csv
[ "$(grep -c '^# Not steady: .* at 4 rpm' "$angle")" -eq 4 ] || fail "want 4 'Not steady' lines at 4 rpm: $(grep '^#' "$angle")"
# Each lining's 4 rpm point: one seed, so no standard error over seeds; its spread is its run's series
# spread (to the file's 3 decimals).
python3 - "$work/out" <<'PY'
import csv, glob, sys
out = sys.argv[1]
series = {}
for f in glob.glob(out + "/store/*.yaml"):
    r = dict(l.split(": ", 1) for l in open(f).read().splitlines() if ": " in l)
    if " rpm=4 " in r["key"] and r["steady"].strip() in ("0", "false"):
        series.setdefault(float(r["angle_sd_deg"]), f)
rows = [r for r in csv.DictReader(l for l in open(out + "/repose_angle.csv") if not l.startswith("#"))]
fails = [r["surface"] for r in rows if not any(abs(float(r["angle_sd_deg"]) - s) <= 5e-4 for s in series)]
bad = [r["surface"] for r in rows if float(r["angle_sd_deg"]) < 0.5]
if not series or fails or bad:
    sys.exit(f"FAIL: unsteady 4 rpm records {len(series)}; spreads not their run's series spread: {fails or bad}")
print(f"ok: {len(rows)} angle points, each spread its run's series spread ({min(series):.2f}-{max(series):.2f} deg)")
PY
"$bin" calibrate "$work/unsteady.yaml" --tier check-turned --data "$work/out" --plan 2> "$work/plan.log" ||
  fail "calibrate does not take the data: $(tail -3 "$work/plan.log")"
echo "ok: no seed steady at 4 rpm, and the data keep those points with their spreads, said in the file, read by calibrate"
