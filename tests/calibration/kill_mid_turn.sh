#!/usr/bin/env bash
# A drum run killed with SIGKILL in the middle of its turn resumes from its last checkpoint
# when the calibration is run again, and ends with the same records, bit for bit, as a
# calibration that was never interrupted and wrote no checkpoint (issue 21, part 3).
#   usage: [REFERENCE=DIR] kill_mid_turn.sh GRANUCAL SOURCE_DIR WORK_DIR
#   REFERENCE: the uninterrupted calibration, written with --checkpoint-every 0 (made once for several
#   tests: tests/CMakeLists.txt); without it, it is made here.
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier check --material PTFE --jobs 1)
whole=${REFERENCE:-$work/whole}
[ -n "${REFERENCE:-}" ] ||
  "$bin" "${args[@]}" --checkpoint-every 0 --out "$whole" > "$work/whole.log" 2>&1 || { cat "$work/whole.log"; exit 1; }
# The same calibration, saving every 0.5 s of wall time; killed (driver and workers) once a
# checkpoint has been saved and the run has turned on past it.
setsid "$bin" "${args[@]}" --checkpoint-every 0.5 --out "$work/killed" > "$work/killed.log" 2>&1 &
pid=$!
for _ in $(seq 600); do
  compgen -G "$work/killed/store/*.turn.h5" > /dev/null && break
  kill -0 "$pid" 2>/dev/null || { echo "the run ended before its first checkpoint"; cat "$work/killed.log"; exit 1; }
  sleep 0.2
done
sleep 0.7
kill -KILL -- -"$pid" 2>/dev/null || true
wait "$pid" 2>/dev/null || true
ls "$work/killed/store"/*.turn.h5 > /dev/null || { echo "no checkpoint survived the kill"; exit 1; }
echo "killed mid-turn with $(ls "$work/killed/store"/*.turn.h5 | wc -l) checkpoint(s) on disk"
"$bin" "${args[@]}" --checkpoint-every 0.5 --out "$work/killed" > "$work/resume.log" 2>&1 || { cat "$work/resume.log"; exit 1; }
grep -q "resumed from its checkpoint" "$work/resume.log" || { echo "the rerun did not resume a checkpoint"; cat "$work/resume.log"; exit 1; }
grep "resumed from its checkpoint" "$work/resume.log"
diff "$whole/calibrated_parameters.csv" "$work/killed/calibrated_parameters.csv"
# Every record the same but for what the clock and the process say.
strip() { grep -vE '^(wall_time_s|fill_wall_time_s|peak_rss_mb|writer):' "$1"; }
n=0
for f in "$whole/store"/*.yaml; do
  g="$work/killed/store/$(basename "$f")"
  [ -e "$g" ] || { echo "missing record $(basename "$f") after the resume"; exit 1; }
  diff <(strip "$f") <(strip "$g") || { echo "record $(basename "$f") differs"; exit 1; }
  n=$((n + 1))
done
[ -z "$(compgen -G "$work/killed/store/*.turn.h5*")" ] || { echo "a checkpoint was left behind"; exit 1; }
echo "$n records identical to the uninterrupted run's; no checkpoint left behind"
