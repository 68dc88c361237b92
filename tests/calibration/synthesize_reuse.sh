#!/usr/bin/env bash
# granucal synthesize --reuse STORE takes a simulation another run already made (same key)
# instead of running it again: a second synthesize of the same beds, reusing the first's
# store, runs nothing, ends with a store identical to the first's, byte for byte, and writes
# the same data rows. (experiments/data/make_synthetic_csa.sh takes the fidelity ladder's
# runs this way.)
#   usage: synthesize_reuse.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
args=("$src/configs/calibration.yaml" --tier quick --wall aluminium=0.8,0.2 --wall PP=0.9,1e-4 --wall PTFE=0.9,1e-4
      --seeds 101 --jobs 1)
export OMP_NUM_THREADS=1
fail() { echo "FAIL: $*"; exit 1; }
# A synthesize that stops: its exit code and the end of its log (gone with the work folder).
synthesize() { local log=$1 rc=0; shift; "$bin" synthesize "$@" 2> "$log" || rc=$?; [ $rc -eq 0 ] || fail "synthesize stopped (exit $rc): $(tail -20 "$log")"; }
synthesize "$work/made.log" "${args[@]}" --out "$work/made"
# Before the second synthesize, its plan counts what --reuse holds: every run, nothing left.
total=$((4 * 2)) # 4 linings x 1 seed x the quick tier's 2 speeds
left=$("$bin" synthesize "${args[@]}" --out "$work/reused" --reuse "$work/made/store" --plan 2>&1 | grep '^== left:') ||
  fail "the plan says nothing of the runs --reuse holds"
echo "$left" | grep -q "^== left: $total of $total drum runs already in .*; expected left: 0 drum runs" ||
  fail "the plan should find all $total runs in --reuse: $left"
synthesize "$work/reused.log" "${args[@]}" --out "$work/reused" --reuse "$work/made/store"
made_runs=$(ls "$work/made/store" | wc -l)
[ "$made_runs" -ge 2 ] || fail "the first synthesize stored $made_runs runs"
# Progress lines ("[lining] ... rpm: ...") are printed only for simulations run here.
if grep -q ' rpm: ' "$work/reused.log"; then fail "the reusing run simulated: $(grep ' rpm: ' "$work/reused.log")"; fi
grep -q "taken from $work/made/store" "$work/reused.log" || fail "no record was said to be taken: $(cat "$work/reused.log")"
diff -r "$work/made/store" "$work/reused/store" || fail "the stores differ"
for f in occupied_area.csv repose_angle.csv; do
  diff <(grep -v '^#' "$work/made/$f") <(grep -v '^#' "$work/reused/$f") || fail "$f: the data rows differ"
done
echo "ok: $made_runs run(s) taken from the first store, none rerun; stores and data rows identical"
