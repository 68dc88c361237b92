#!/usr/bin/env bash
# A calibration killed with SIGKILL at 5 different points, then run again with the same
# command, completes with the same table as an uninterrupted run, reruns nothing already
# stored, and never leaves a damaged file.
#   usage: [REFERENCE=DIR] kill_resume.sh GRANUCAL SOURCE_DIR WORK_DIR [TIER]   (TIER: check;
#   check-two-tier for the two-tier search, whose map tier's runs are part of the same store and the
#   same table). REFERENCE: the uninterrupted run of the same command, made once for several tests
#   (tests/CMakeLists.txt: calibrate_reference_*); without it, it is made here.
set -euo pipefail
bin=$1 src=$2 work=$3 tier=${4:-check}
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier "$tier" --material PTFE --jobs 2)
whole=${REFERENCE:-$work/whole}
[ -n "${REFERENCE:-}" ] || "$bin" "${args[@]}" --out "$whole" > "$work/whole.log" 2>&1 || { cat "$work/whole.log"; exit 1; }
total=$(($(wc -l < "$whole/simulations.csv") - 1))
# The table's Markdown warns exactly where a value lies outside its identified range (the branch
# where one does is exercised on a committed run that has one: verify_committed_standard_affine).
python3 tests/calibration/check_value_in_range.py "$whole"
# Stored = a record a rerun keeps: not one marking a worker killed from outside (retry: true),
# which the next run runs again by design.
records() {
  local n=0 f
  for f in "$work/killed/store"/*.yaml; do
    [ -e "$f" ] && ! grep -q '^retry: true' "$f" && n=$((n + 1))
  done
  echo "$n"
}
# Five kill points spread over the run: once N records are stored (0 = during the first
# fill; then 1, a third, two thirds and all but two of the uninterrupted run's records, so that
# with check-two-tier the last kills fall in the deciding tier's runs, after its map tier's), 2 s
# later, in whatever phase that is (filling, turning, writing), SIGKILL the driver and its
# workers; then the same command again.
for target in 0 1 $((total / 3)) $((2 * total / 3)) $((total - 2)); do
  "$bin" "${args[@]}" --out "$work/killed" > "$work/killed.$target.log" 2>&1 &
  pid=$!
  while kill -0 "$pid" 2>/dev/null && [ "$(records)" -lt "$target" ]; do sleep 0.5; done
  sleep 2
  pkill -KILL -P "$pid" 2>/dev/null || true   # the worker processes, then the driver
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  echo "killed once ${target}+ records were stored, 2 s later: $(records) stored"
done
before=$(records)
# --plan replays the killed store (running nothing, writing nothing) and says where the run resumes.
left() { "$bin" "${args[@]}" --out "$work/killed" --plan 2>&1 | grep '^== left:' || echo "(no left line)"; }
folder_sums() { (cd "$work/killed" && find . -type f | sort | xargs md5sum); } # the store, stage files, inputs
sums=$(folder_sums)
left_killed=$(left)
[ "$(folder_sums)" = "$sums" ] || { echo "--plan changed the killed run's folder"; exit 1; }
echo "plan on the killed store: $left_killed"
stamp=$(mktemp)
"$bin" "${args[@]}" --out "$work/killed" > "$work/resume.log" 2>&1 || { cat "$work/resume.log"; exit 1; }
diff "$whole/calibrated_parameters.csv" "$work/killed/calibrated_parameters.csv"
ran=$(sed -n 's/.*; \([0-9]*\) simulations run now.*/\1/p' "$work/resume.log")
echo "resume: ${before} of ${total} records were stored before it; it ran ${ran}"
[ "$before" -gt 0 ] || { echo "no record survived the kills: the test did not test resuming"; exit 1; }
[ "$ran" -eq $((total - before)) ] || { echo "the resume reran stored simulations"; exit 1; }
# The replay ended where the resume had to run: at a batch missing at least one run and at most what
# the resume ran; on the finished store it finds every record use that simulations.csv lists.
missing=$(echo "$left_killed" | sed -n 's/.* found, \([0-9]*\) of the next batch missing.*/\1/p')
if [ "$ran" -gt 0 ]; then
  [ -n "$missing" ] && [ "$missing" -ge 1 ] && [ "$missing" -le "$ran" ] ||
    { echo "the plan's replay of the killed store ($left_killed) does not match the resume, which ran $ran"; exit 1; }
else
  echo "$left_killed" | grep -q '^== left: nothing' || { echo "nothing was left to run, the plan said: $left_killed"; exit 1; }
fi
uses=$(($(wc -l < "$work/killed/simulations.csv") - 1))
left_done=$(left)
echo "$left_done" | grep -q "^== left: nothing; .* ($uses found)" ||
  { echo "on the finished store the plan should find all $uses record uses of simulations.csv: $left_done"; exit 1; }
# Stored records were not rewritten by the resume.
changed=$(find "$work/killed/store" -name '*.yaml' ! -newer "$stamp" | wc -l)
[ "$changed" -ge "$before" ] || { echo "stored records were rewritten"; exit 1; }
[ -n "$(find "$work/killed" -name '*.tmp')" ] && { echo "a temporary file was left behind: $(find "$work/killed" -name '*.tmp')"; exit 1; } || true
# The inputs it read, kept beside its results (what verify_committed.sh re-derives from).
for f in config.yaml:configs/calibration.yaml repose_angle.csv:experiments/data/repose_angle.csv \
         occupied_area.csv:experiments/data/occupied_area.csv; do
  cmp "$work/killed/${f%%:*}" "${f#*:}" || { echo "$work/killed/${f%%:*} is not a copy of ${f#*:}"; exit 1; }
done
echo "same table after 5 kills; nothing stored was recomputed; the inputs kept beside it; --plan's replay said where the resume started"
