#!/usr/bin/env bash
# The paper's benchmark (Appendix A.2, Table A.2): the silo discharge run by
# granucal and by LIGGGHTS 3.8 from ONE initial state, and the two curves of
# contacts, kinetic energy and discharged granules compared (tolerances in
# tests/peers/silo/compare_silo.c). Not part of ctest: needs `liggghts`
# (apt-get install -y liggghts).
#   bash tests/peers/compare_silo.sh [GRANUCAL] [OUTDIR] [DURATION_S]
# Defaults: build/granucal, results/silo, 120 s. Exit status 1 if a metric is
# outside its tolerance.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
G=$(realpath "${1:-$root/build/granucal}")
out=$(mkdir -p "${2:-$root/results/silo}" && realpath "${2:-$root/results/silo}")
dur=${3:-120}
command -v liggghts >/dev/null || { echo "liggghts not installed (apt-get install -y liggghts)" >&2; exit 2; }
cfg=$root/configs/silo.yaml
val() { awk -v k="$1" '$1 == k":" {print $2}' "$cfg"; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# 1. granucal: fill (with the orifice closed), write the t = 0 state, discharge.
start=$(date +%s.%N)
"$G" simulate "$cfg" --set duration="$dur" --out "$work/granucal" > "$work/granucal.json"
t_g=$(echo "$(date +%s.%N) - $start" | bc)

# 2. LIGGGHTS on the same t = 0 state (silo_initial.data), same step and length.
mkdir -p "$work/liggghts" && cp "$work/granucal/silo_initial.data" "$work/liggghts/"
steps=$(awk -v d="$dur" -v dt="$(val dt)" 'BEGIN {printf "%d", d / dt + 0.5}')
nthermo=$(awk -v s="$(val sample_interval)" -v dt="$(val dt)" 'BEGIN {printf "%d", s / dt + 0.5}')
zbelow=$(awk -v z="$(val plate_z)" -v a="$(val plate_sphere_radius)" 'BEGIN {print z - a}')
start=$(date +%s.%N)
(cd "$work/liggghts" && liggghts -in "$root/tests/peers/silo/in.silo" -var STEPS "$steps" -var NTHERMO "$nthermo" \
   -var RCYL "$(val silo_radius)" -var ZBELOW "$zbelow" -log log.liggghts > stdout.txt)
t_l=$(echo "$(date +%s.%N) - $start" | bc)
# thermo rows: step time contacts ket ker discharged
awk 'BEGIN {print "t_s,contacts,ke_translational_J,ke_rotational_J,discharged"}
     /^ *Step +Time/ {on = 1; next} /^Loop time/ {on = 0}
     on && NF == 6 && $1 ~ /^[0-9]+$/ {printf "%s,%s,%s,%s,%s\n", $2, $3, $4, $5, $6}' \
  "$work/liggghts/log.liggghts" > "$work/liggghts.csv"

# 3. Compare.
cc -O2 -std=c11 -I"$root/experiments/plot" -I"$root/engine" "$root/tests/peers/silo/compare_silo.c" \
   "$root/experiments/plot/exp_plot.c" $(pkg-config --cflags --libs plplot) -lm -o "$work/compare_silo"
cp "$work/granucal/series.csv" "$out/granucal_series.csv"
cp "$work/liggghts.csv" "$out/liggghts_series.csv"
cp "$work/granucal.json" "$out/granucal_result.json"
n=$(awk -F'"granules": ' '{split($2, a, ","); print a[1]}' "$work/granucal.json")
set +e
"$work/compare_silo" "$work/granucal/series.csv" "$work/liggghts.csv" "$n" "$out" > "$out/metrics.md"
rc=$?
set -e
printf '\nwall time: granucal %.0f s (fill + discharge), LIGGGHTS %.0f s (discharge)\n' "$t_g" "$t_l" >> "$out/metrics.md"
cat "$out/metrics.md"
exit $rc
