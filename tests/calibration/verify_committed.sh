#!/usr/bin/env bash
# Verifies a committed calibration from its own store (issue 22):
#  1. the table re-derived from the committed store, by the calibration's own command (report.md),
#     is the committed calibrated_parameters.csv byte for byte, and no simulation runs;
#  2. N of the simulations that command used, picked at random (the pick's seed is printed: rerun
#     with SEED=... to repeat it; for a two-tier calibration half of them, rounded up, from the
#     deciding tier's runs and the rest from the map tier's), are removed from a copy of the store and run again; each must
#     reproduce its committed record's measurements exactly (one thread a simulation: the engine is
#     deterministic, and its results do not depend on the CPU), and the table must come out the same.
#     With MAX_RERUN_S set, the picks are drawn only among the records whose own recorded wall time is
#     at most that many seconds (a converged drum's slowest runs take 20 minutes; CI has less), and
#     the script says how many records that left to draw from.
#   With SAYS="TIER PURPOSE DATA" set (e.g. "standard calibration angle lab / CSA synthetic"), the
#   re-derived outputs must also say what the run is (check_outputs_say_what.py).
#   usage: [MAX_RERUN_S=S] [SEED=N] [SAYS=...] [JOBS=J] [EXPECT_OUTSIDE=1] verify_committed.sh GRANUCAL SOURCE_DIR RESULTS_DIR WORK_DIR [N]
#   (N = 0: step 1 alone)
# RESULTS_DIR holds report.md, calibrated_parameters.csv, simulations.csv, store/, the stage_*.yaml
# files, and the data files the run read (repose_angle.csv, occupied_area.csv): for a run made with
# --data they replace its --data folder, and for one made on the config's own files they are read
# instead of those (--data), so a later change of the shipped data does not change its table. A
# config.yaml there (calibrate keeps a copy of the config it read) replaces the command's config
# the same way.
set -euo pipefail
source "$(dirname "$0")/verify_common.sh"
bin=$1 src=$2 results=$3 work=$4 n=${5:-2}
rm -rf "$work" && mkdir -p "$work/out"
command=$(sed -n 's/^Command: `\(.*\)`.*/\1/p' "$results/report.md")
[ -n "$command" ] || { echo "FAIL: no Command: line in $results/report.md"; exit 1; }
read -r -a words <<< "$command"
# The same command, its results folder here and its data the committed copies.
args=() stage=all
for ((i = 2; i < ${#words[@]}; ++i)); do # words[0..1]: granucal calibrate
  case ${words[i]} in
    --out) i=$((i + 1)); args+=(--out "$work/out") ;;
    --data) i=$((i + 1)); args+=(--data "$results") ;;
    --jobs) i=$((i + 1)) ;;
    --stage) stage=${words[i + 1]}; args+=("${words[i]}") ;;
    *.yaml) if [ -f "$results/config.yaml" ]; then args+=("$results/config.yaml"); else args+=("${words[i]}"); fi ;;
    *) args+=("${words[i]}") ;;
  esac
done
grep -q -- "--out" <<< "${args[*]}" || args+=(--out "$work/out")
if ! grep -q -- "--data" <<< "${args[*]}" && [ -f "$results/repose_angle.csv" ] && [ -f "$results/occupied_area.csv" ]; then
  args+=(--data "$results")
fi
cp -r "$results/store" "$work/out/"
cp "$results"/stage_*.yaml "$work/out/" 2>/dev/null || true
# JOBS: the workers (default 2). A batch of one simulation gets every idle worker's core as an OpenMP
# thread (cal_pool.c), so a test declared as one core must say JOBS=1: two threads beside another test
# on a 2-core machine spin against each other (a lambda 1000 run measured 10x slower that way).
run() { (cd "$src" && "$bin" calibrate "${args[@]}" --jobs "${JOBS:-2}" 2> "$work/$1.log" > /dev/null) || { cat "$work/$1.log"; exit 1; }; }
ran() { sed -n 's/.*; \([0-9]*\) simulations run now.*/\1/p' "$work/$1.log"; }
fails=0

echo "re-deriving: granucal calibrate ${args[*]}"
run derive
[ "$(ran derive)" = 0 ] || { echo "FAIL: re-deriving ran $(ran derive) simulations (the store is incomplete)"; fails=$((fails + 1)); }
if cmp -s "$results/calibrated_parameters.csv" "$work/out/calibrated_parameters.csv"; then
  echo "ok   the table re-derived from the store is the committed one, byte for byte"
else
  echo "FAIL: the re-derived table differs:"; diff "$results/calibrated_parameters.csv" "$work/out/calibrated_parameters.csv" || true
  fails=$((fails + 1))
fi
# EXPECT_OUTSIDE=1: the run is known to hold a value outside its range, so the warning's branch is exercised.
python3 "$src/tests/calibration/check_value_in_range.py" "$work/out" ${EXPECT_OUTSIDE:+--expect-outside} || fails=$((fails + 1))
# SAYS="TIER PURPOSE DATA...": every re-derived output must say what the run is (check_outputs_say_what.py).
if [ -n "${SAYS:-}" ]; then
  read -r says_tier says_purpose says_data <<< "$SAYS"
  python3 "$src/tests/calibration/check_outputs_say_what.py" "$work/out" --tier "$says_tier" --purpose "$says_purpose" \
    --data "$says_data" || fails=$((fails + 1))
fi
if [ "$n" -eq 0 ]; then # nothing to rerun: a second derivation would only repeat the first
  echo "$fails failure(s)"
  exit $((fails > 0))
fi

# The drum records this command's stages used (simulations.csv: stage, candidate, record, experiment,
# ...; a two-tier stage lists its map tier's runs as "NAME (map)").
seed=${SEED:-$(date +%s)}
# records STAGES TIER: STAGES granule|wall|all, TIER map|deciding|any.
records() {
  awk -F, -v stages="$1" -v tier="$2" 'NR > 1 && $4 == "drum" {
    s = $1; map = sub(/ \(map\)$/, "", s)
    if (stages == "granule" && s != "granule") next
    if (stages == "wall" && (s == "granule" || s == "stiffness")) next
    if ((tier == "map" && !map) || (tier == "deciding" && map)) next
    print $3 }' "$results/simulations.csv" | sort -u | affordable
}
# affordable: the records read on stdin whose recorded wall time is at most MAX_RERUN_S (all without it).
affordable() {
  while read -r h; do
    [ -z "${MAX_RERUN_S:-}" ] ||
      awk -v cap="$MAX_RERUN_S" '/^wall_time_s:/ { exit !($2 <= cap) }' "$results/store/$h.yaml" || continue
    echo "$h"
  done
}
pick() { shuf -n "$1" --random-source=<(random_bytes "$seed"); }
# Two tiers: half the picks (rounded up) from the deciding tier, so a run of the expensive drum is
# always among them, the rest from the map tier.
if [ -n "$(records "$stage" map)" ]; then
  mapfile -t picked < <(records "$stage" deciding | pick $(((n + 1) / 2)); records "$stage" map | pick $((n / 2)))
else
  mapfile -t picked < <(records "$stage" any | pick "$n")
fi
[ -z "${MAX_RERUN_S:-}" ] || echo "drawn among the $(records "$stage" any | wc -l) drum records of at most $MAX_RERUN_S s of recorded wall time"
echo "picked at random (SEED=$seed): ${picked[*]}"
[ "${#picked[@]}" -eq "$n" ] || { echo "FAIL: fewer than $n drum records to pick from"; exit 1; }
for h in "${picked[@]}"; do rm "$work/out/store/$h.yaml"; done
run rerun
[ "$(ran rerun)" = "$n" ] || { echo "FAIL: the rerun ran $(ran rerun) simulations, not $n"; fails=$((fails + 1)); }
reproduced "$results/store" "$work/out/store" "$work" "${picked[@]}"
fails=$((fails + not_reproduced))
cmp -s "$results/calibrated_parameters.csv" "$work/out/calibrated_parameters.csv" ||
  { echo "FAIL: the table after the reruns differs"; fails=$((fails + 1)); }
echo "$fails failure(s)"
exit $((fails > 0))
