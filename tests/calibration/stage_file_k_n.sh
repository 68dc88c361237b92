#!/usr/bin/env bash
# A later stage run alone reads k_n from OUT/stage_stiffness.yaml, and the table says what that k_n
# is by what the file says of it (k_n_from), not by comparing it with the config's k_n: a stage 1
# that chose 200 N/m, the shipped config's own value, was printed "stage not run" (the standard
# rerun's folder, stop 53). On a finished run's store (the PTFE wall alone at the check tier), each
# variant of the file is read by the same command (nothing runs again):
#  - k_n_from: stage 1   -> the k_n row is calibrated, from "stage 1, earlier run";
#  - k_n_from: config    -> stage not run, its source says stage 1 was unresolved;
#  - no k_n_from (a file written before it was kept) at the config's k_n -> stage not run, its source
#    saying the file cannot tell (where it differs from the config's, stage 1 chose it, as before);
#  - k_n_from: anything else -> a clear error naming the file and field, exit non-zero.
#   usage: [REFERENCE=DIR] stage_file_k_n.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier check --material PTFE --jobs 1 --checkpoint-every 0)
reference=${REFERENCE:-$work/reference}
[ -n "${REFERENCE:-}" ] || "$bin" "${args[@]}" --out "$reference" > "$work/reference.log" 2>&1 ||
  { cat "$work/reference.log"; exit 1; }
config_k_n=$(sed -n 's/^k_n: *\([0-9.]*\).*/\1/p' configs/calibration.yaml)
fails=0
# variant NAME FILE_BODY: a copy of the run with that stage_stiffness.yaml, the same command on it.
variant() {
  mkdir -p "$work/$1" && cp -r "$reference/store" "$work/$1/"
  printf '%s\n' "$2" > "$work/$1/stage_stiffness.yaml"
  "$bin" "${args[@]}" --out "$work/$1" > /dev/null 2> "$work/$1.log"
}
# k_n_row NAME STATUS SOURCE: the table's k_n row has that status, its .md row that source, and no
# simulation ran.
k_n_row() {
  local row md; row=$(grep '^granule-granule,,k_n,' "$work/$1/calibrated_parameters.csv" || true)
  md=$(grep -m1 'rolling stiffness k_n' "$work/$1/calibrated_parameters.md" || true)
  if [ "$(cut -d, -f10 <<< "$row")" = "$2" ] && [[ $md == *"| $3 |" ]] && grep -q '; 0 simulations run now' "$work/$1.log"; then
    echo "ok   $1: k_n is '$2', from '$3', nothing run"
  else
    echo "FAIL $1: expected '$2' from '$3'; the rows: $row"; echo "$md"
    tail -3 "$work/$1.log"; fails=$((fails + 1))
  fi
}

variant chosen "k_n: $config_k_n
k_n_from: stage 1" || { cat "$work/chosen.log"; exit 1; }
k_n_row chosen calibrated "stage 1, earlier run (stage_stiffness.yaml)"
variant unresolved "k_n: $config_k_n
k_n_from: config" || { cat "$work/unresolved.log"; exit 1; }
k_n_row unresolved "stage not run" "config k_n (stage 1 of an earlier run unresolved: stage_stiffness.yaml)"
variant old "k_n: $config_k_n" || { cat "$work/old.log"; exit 1; }
k_n_row old "stage not run" "stage_stiffness.yaml of an earlier run, which does not say whether stage 1 chose it"
if variant bogus "k_n: $config_k_n
k_n_from: guessed"; then
  echo "FAIL bogus: a k_n_from of 'guessed' was accepted"; fails=$((fails + 1))
elif grep -q "bogus/stage_stiffness.yaml: field 'k_n_from': expected 'stage 1' or 'config'" "$work/bogus.log"; then
  echo "ok   bogus: refused, naming the file and the field"
else echo "FAIL bogus: refused without naming the file and field:"; cat "$work/bogus.log"; fails=$((fails + 1)); fi
echo "$fails failure(s)"
exit $((fails > 0))
