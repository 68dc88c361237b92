#!/usr/bin/env bash
# Turned starts (tier keys turned_start_rpm, turned_start_time; tier check-turned): a tier's 4 rpm
# runs start from each seed's bed turned first at the stage's start pair, one bed shared by every
# candidate of the stage, kept in the store as a file (<hash>.start.h5).
#  1. The granule stage on two workers: one turned bed per seed (made side by side), every 4 rpm
#     record names its start in its key (start=turned[...], no start tilt, MSER), the 116 rpm records
#     do not, and each bed's cost is charged to one run only (the bound probes, a second batch,
#     start from the beds the grid's batch made).
#  2. A 4 rpm record deleted and made again on one worker, from the bed's file, has the same
#     numbers to the last digit; so has one made after its bed's file too is deleted (the bed turned
#     again): the file is the bed the run would have turned.
#  3. The wall stage (one material) starts from a bed of its own: the granule-lined drum at the
#     frozen pair, again one per seed.
#   usage: turned_start.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
export OMP_NUM_THREADS=1
fail() { echo "FAIL: $*"; exit 1; }
# A granucal that stops says why in its log: shown with the failure (the log is gone with the work folder).
stopped() { echo "FAIL: granucal $1 stopped with exit code $2; the end of its log:"; tail -40 "$work/log"; exit 1; }
run() { "$bin" calibrate "$src/configs/calibration.yaml" --tier check-turned --out "$work/out" "$@" 2>> "$work/log" || stopped "calibrate $*" $?; }
store=$work/out/store
# The numbers a record holds (not its wall times or writer).
numbers() { grep -E '^(status|angle_deg|angle_sd_deg|csa_percent|csa_sd_percent|steady|simulated_time_s|particle_steps|dt_s):' "$1"; }

run --stage granule --jobs 2
beds=$(ls "$store"/*.start.h5 2>/dev/null | wc -l)
[ "$beds" -eq 2 ] || fail "granule stage: $beds turned beds in the store, want 2 (one per seed)"
slow=$(grep -l "rpm=4 " "$store"/*.yaml) fast=$(grep -l "rpm=116 " "$store"/*.yaml)
[ "$(echo "$slow" | wc -l)" -eq 12 ] || fail "want 12 records at 4 rpm (4 grid candidates and 2 bound probes x 2 beds)"
for f in $slow; do
  k=$(grep '^key:' "$f")
  for want in 'start=turned\[time=1 tilt=20 granule\[k=200,200,200 xi=0.7 mu=0.5,0.1 ' 'start_tilt=0 ' 'steady=mser se=3,1'; do
    echo "$k" | grep -q "$want" || fail "$f: its key lacks '$want': $k"
  done
done
for f in $fast; do grep -q 'start=turned' "$f" && fail "$f: a 116 rpm run started turned"; done
grep -q "^Runs: 4 rpm from the stage's bed turned 1 s at that speed first" "$work/out/report.md" ||
  fail "report.md does not say how the 4 rpm runs start"
charged=$(for f in $slow; do grep '^fill_wall_time_s:' "$f"; done | awk '$2 > 0' | wc -l)
[ "$charged" -eq 2 ] || fail "$charged of the 4 rpm records carry a turned bed's cost, want 2 (one per bed, the probes' batch from the same beds)"

# 2. Made again: from the bed's file, then with the bed turned again.
victim=$(echo "$slow" | head -1)
cp "$victim" "$work/original.yaml"
rm "$victim"
run --stage granule --jobs 1
[ -f "$victim" ] || fail "the deleted record was not made again"
diff <(numbers "$work/original.yaml") <(numbers "$victim") || fail "a run from the bed's file differs from the original"
rm "$victim" "$store"/*.start.h5
run --stage granule --jobs 1
diff <(numbers "$work/original.yaml") <(numbers "$victim") || fail "a run from a bed turned again differs from the original"
[ "$(ls "$store"/*.start.h5 | wc -l)" -ge 1 ] || fail "the bed turned again was not kept in the store"

# 3. The wall stage's own beds.
before=$(ls "$store"/*.start.h5 | wc -l)
run --material PTFE --jobs 2
after=$(ls "$store"/*.start.h5 | wc -l)
[ $((after - before)) -eq 2 ] || fail "the wall stage made $((after - before)) turned beds, want 2"
walls=$(grep -l "rpm=4 .*start=turned" "$store"/*.yaml | xargs grep -l 'wall\[k=400' || true)
[ -n "$walls" ] || fail "no wall-stage 4 rpm record started turned"
for deck in liggghts_drum.in lammps_drum.in; do
  grep -q "^# Not as granucal ran it at 4 rpm" "$work/out/$deck" || fail "$deck does not say its 4 rpm start differs"
done
# 4. One bed per candidate and COBYLA's steps: a batch of one candidate shares its fill, which the
#    parent settles (a new one each candidate) while the turned bed stays kept for the next batch:
#    made and charged once (a build that let it go with the level bed charged it twice).
sed -e 's|\.\./experiments/data/|'"$src"'/experiments/data/|' \
    -e '/name: check-turned/,/name: standard/ { s/    beds: 2/    beds: 1/; s/    max_evaluations: 0/    max_evaluations: 2/ }' \
  "$src/configs/calibration.yaml" > "$work/one_bed.yaml"
"$bin" calibrate "$work/one_bed.yaml" --tier check-turned --out "$work/one" --stage granule --jobs 2 2>> "$work/log" ||
  stopped "calibrate one_bed.yaml" $?
one=$(grep -l "rpm=4 " "$work/one/store"/*.yaml)
[ "$(echo "$one" | wc -l)" -ge 7 ] || fail "one bed: want at least 7 records at 4 rpm (6 candidates and a COBYLA step)"
[ "$(ls "$work/one/store"/*.start.h5 | wc -l)" -eq 1 ] || fail "one bed: want one turned bed"
charged=$(for f in $one; do grep '^fill_wall_time_s:' "$f"; done | awk '$2 > 0' | wc -l)
[ "$charged" -eq 1 ] || fail "one bed: $charged of its 4 rpm records carry the turned bed's cost, want 1"
echo "ok: one turned bed per seed and stage, keys name it, its cost charged once, a run from its file or from it turned again is the same to the last digit"
