#!/usr/bin/env bash
# One damaged record in a run's store loses nothing but its own simulation: run the same
# command again and the record is moved aside to store/damaged/<hash>.yaml (kept), one line
# says so and that its simulation runs again, exactly that one simulation is rerun, and the
# table is the same. Two kinds of damage, one after the other: a record cut within a line
# (no YAML error may be needed to see it), then one whose last line is missing.
#   usage: [REFERENCE=DIR] damaged_record.sh GRANUCAL SOURCE_DIR WORK_DIR
#   REFERENCE: a finished run of the same command (made once for several tests: tests/CMakeLists.txt),
#   copied and damaged here; without it, the run is made here.
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier check --material PTFE --jobs 2 --out "$work/run")
if [ -n "${REFERENCE:-}" ]; then cp -r "$REFERENCE" "$work/run"
else "$bin" "${args[@]}" > "$work/whole.log" 2>&1 || { cat "$work/whole.log"; exit 1; }; fi
cp "$work/run/calibrated_parameters.csv" "$work/table.csv"
records=("$work/run/store/"*.yaml)
[ "${#records[@]}" -ge 2 ] || { echo "the run stored ${#records[@]} records: nothing to damage"; exit 1; }

cut_within_a_line() { head -c $(($(stat -c %s "$1") / 2)) "$1" > "$work/cut" && mv "$work/cut" "$1"; }
last_line_missing() { head -n -1 "$1" > "$work/cut" && mv "$work/cut" "$1"; }
# damage_and_rerun NAME RECORD: damage RECORD with the function NAME, rerun, check.
damage_and_rerun() {
  local name=$1 record=$2 hash log
  hash=$(basename "$record" .yaml)
  "$name" "$record"
  cp "$record" "$work/$hash.damaged"
  log="$work/rerun_$name.log"
  "$bin" "${args[@]}" > "$log" 2>&1 || { echo "FAIL $name: the rerun stopped:"; cat "$log"; exit 1; }
  local moved=$(grep -c "damaged store record moved to .*damaged/$hash.yaml.*its simulation runs again" "$log" || true)
  [ "$moved" -eq 1 ] || { echo "FAIL $name: no one line saying the record was moved aside:"; cat "$log"; exit 1; }
  cmp -s "$work/run/store/damaged/$hash.yaml" "$work/$hash.damaged" ||
    { echo "FAIL $name: store/damaged/$hash.yaml is not the damaged record, kept"; exit 1; }
  local ran=$(sed -n 's/.*; \([0-9]*\) simulations run now.*/\1/p' "$log")
  [ "$ran" = 1 ] || { echo "FAIL $name: the rerun ran '$ran' simulations, not exactly the damaged one"; exit 1; }
  [ -s "$record" ] && tail -n 1 "$record" | grep -q '^granules: ' || { echo "FAIL $name: the record was not rewritten whole"; exit 1; }
  diff "$work/table.csv" "$work/run/calibrated_parameters.csv" || { echo "FAIL $name: the table changed"; exit 1; }
  echo "ok   $name: $(grep 'damaged store record' "$log")"
}
damage_and_rerun cut_within_a_line "${records[0]}"   # half its bytes
damage_and_rerun last_line_missing "${records[1]}"   # the YAML parses; its last field (granules) is gone
echo "each damaged record was moved aside and its one simulation rerun; the same table"
