#!/usr/bin/env bash
# Verifies a committed twin's data from their own store (issue 37.5), as verify_committed.sh verifies
# its calibration: the data files (repose_angle.csv, occupied_area.csv) were made by `granucal
# synthesize` (the "Made by:" line of their header), whose runs are kept in DATA_STORE. N of those runs,
# picked at random (the pick's seed is printed: rerun with SEED=... to repeat it), are removed from a
# copy of the store; the same synthesize command then reruns exactly those, each must reproduce its
# committed record's measurements exactly, and the data rows must come out the same as the committed
# files' (N = 0: the data re-derived from the store alone, nothing run). The config is the
# source's, as the command names it: a tier changed since would change every run's key, and fail.
#   usage: [SEED=N] verify_twin_data.sh GRANUCAL SOURCE_DIR RESULTS_DIR DATA_STORE WORK_DIR [N]
set -euo pipefail
source "$(dirname "$0")/verify_common.sh"
bin=$1 src=$2 results=$3 store=$4 work=$5 n=${6:-2}
rm -rf "$work" && mkdir -p "$work/out"
made=$(sed -n 's/^# Made by: granucal synthesize \(.*\)$/\1/p' "$results/repose_angle.csv")
[ -n "$made" ] || { echo "FAIL: no '# Made by: granucal synthesize' line in $results/repose_angle.csv"; exit 1; }
read -r -a words <<< "$made"
args=()
for ((i = 0; i < ${#words[@]}; ++i)); do # its --out becomes ours; --jobs is the machine's
  case ${words[i]} in
    --out) i=$((i + 1)); args+=(--out "$work/out") ;;
    --jobs) i=$((i + 1)) ;;
    *) args+=("${words[i]}") ;;
  esac
done
cp -r "$store" "$work/out/store"
seed=${SEED:-$(date +%s)}
mapfile -t picked < <(ls "$store" | sed -n 's/\.yaml$//p' | shuf -n "$n" --random-source=<(random_bytes "$seed"))
echo "picked at random (SEED=$seed): ${picked[*]}"
[ "${#picked[@]}" -eq "$n" ] || { echo "FAIL: fewer than $n records in $store"; exit 1; }
for h in "${picked[@]}"; do rm "$work/out/store/$h.yaml"; done
echo "re-deriving: granucal synthesize ${args[*]}"
(cd "$src" && "$bin" synthesize "${args[@]}" --jobs 2 > "$work/synthesize.log" 2>&1) || { cat "$work/synthesize.log"; exit 1; }
fails=0
# Each run simulated here prints a line "[lining] mu_s = ..., 4 rpm, seed 101: ok, ..." (and, from a
# worker turning one bed at several speeds, one more without the pair): runs = distinct lining, speed, seed.
# (N = 0: no such line, and grep's exit 1 must not end the script under pipefail)
ran=$({ grep -oE '^\[[^]]*\] (mu_s = [^,]*, mu_r = [^,]*, )?[0-9.]+ rpm, seed [0-9]+: ' "$work/synthesize.log" || true; } |
      sed -E 's/mu_s = [^,]*, mu_r = [^,]*, //' | sort -u | wc -l)
[ "$ran" = "$n" ] || { echo "FAIL: synthesize ran $ran simulations, not the $n removed"; fails=$((fails + 1)); }
reproduced "$store" "$work/out/store" "$work" "${picked[@]}"
fails=$((fails + not_reproduced))
for f in repose_angle.csv occupied_area.csv; do
  if diff <(grep -v '^#' "$results/$f") <(grep -v '^#' "$work/out/$f"); then
    echo "ok   $f: the committed data rows, re-derived"
  else
    echo "FAIL: $f: the data rows differ"; fails=$((fails + 1))
  fi
done
echo "$fails failure(s)"
exit $((fails > 0))
