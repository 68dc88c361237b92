#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Issue 36.3: the complete decks a calibration exports (liggghts_drum.in,
# lammps_drum.in) say what they run, checked without LIGGGHTS or LAMMPS (the
# peers test, label peers, runs them). The committed ci twin's outputs are
# re-derived from its store by its own command (no simulation), then each deck:
#  - opens with the run's status banner and every value the data did not
#    choose, the same lines as its parameter file;
#  - includes its parameter file, and sets lambda, the slice depth and the
#    drum radius of configs/calibration.yaml's ci tier;
#  - cuts at the fill level of the config's fill degree (recomputed here);
#  - steps at the fraction of dt_crit its header reports as granucal's;
#  - pours GSD classes whose number fractions sum to 1.
#   bash tests/peers/decks_written.sh GRANUCAL OUTDIR
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
G=$(realpath "$1")
out=$(mkdir -p "$2" && realpath "$2")
COMMITTED=$root/results/twin_ci/r4_ci_test
fails=0
check() { if eval "$2"; then echo "ok   $1"; else echo "FAIL: $1"; fails=$((fails + 1)); fi; }

rm -rf "$out/export" && mkdir -p "$out/export"
cp -r "$COMMITTED/store" "$COMMITTED"/stage_*.yaml "$out/export/"
(cd "$root" && timeout 300 "$G" calibrate --tier ci --stage wall --data "$COMMITTED" --out "$out/export" --jobs 1 \
   configs/calibration.yaml > "$out/derive.out" 2> "$out/derive.log") || { tail "$out/derive.log"; exit 1; }
grep -q "; 0 simulations run now" "$out/derive.log" || { echo "FAIL: re-deriving ran simulations"; exit 1; }

# The ci tier and the drum, from the config.
cfg=$root/configs/calibration.yaml
tier() { awk -v k="$1" '/^  - name: ci$/ {t = 1; next} /^  - name:/ {t = 0} t && $1 == k ":" {print $2; exit}' "$cfg"; }
top() { awk -v k="$1" '$1 == k ":" {print $2; exit}' "$cfg"; }
lambda=$(tier lambda) slice=$(tier slice_depth) diameter=$(top diameter) fill=$(top fill)
radius=$(awk -v d="$diameter" 'BEGIN {printf "%.9g", d / 2}')
# The level below which a circle of radius r holds the fraction f of its area (bisection).
level=$(awk -v r="$radius" -v f="$fill" 'BEGIN {
  pi = atan2(0, -1); lo = -r; hi = r
  for (i = 0; i < 60; i++) { y = (lo + hi) / 2; above = r * r * atan2(sqrt(r * r - y * y), y) - y * sqrt(r * r - y * y)
    if (1 - above / (pi * r * r) < f) lo = y; else hi = y }
  printf "%.9g", (lo + hi) / 2 }')

var() { sed -n "s/^variable $1 \(index\|equal\) \([-0-9.eE+]*\).*/\2/p" "$2" | head -1; }
banner() { grep -E '^# (DEMONSTRATION|CALIBRATION|Coarse-grained|Data:|NOT CALIBRATED|Every friction)' "$1"; }
same() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN {d = a - b; exit !(d * d <= t * t)}'; }
for code in liggghts lammps; do
  deck=$out/export/${code}_drum.in params=$out/export/${code}_parameters.in
  check "$code: the deck exists" "[ -f '$deck' ]"
  check "$code: its banner is its parameter file's" "diff <(banner '$params') <(banner '$deck') > /dev/null && [ -n \"\$(banner '$deck')\" ]"
  check "$code: it includes ${code}_parameters.in" "grep -q '^include ${code}_parameters.in$' '$deck'"
  check "$code: lambda $(var lambda "$deck") = the ci tier's $lambda" "same '$(var lambda "$deck")' '$lambda' 0"
  check "$code: slice depth $(var depth "$deck") = the ci tier's $slice" "same '$(var depth "$deck")' '$slice' 0"
  check "$code: drum radius $(var rdrum "$deck") = half the config's diameter $diameter" "same '$(var rdrum "$deck")' '$radius' 1e-12"
  check "$code: cut $(var cut "$deck") m = the fill level of fill $fill, $level m" "same '$(var cut "$deck")' '$level' 1e-6"
  reported=$(sed -n 's/.*granucal, for this drum before it runs: dt = [-0-9.eE+]* s = \([0-9.]*\) dt_crit.*/\1/p' "$deck")
  check "$code: dt_fraction $(var dt_fraction "$deck") = granucal's reported ${reported:-?} of dt_crit" "[ -n '$reported' ] && same '$(var dt_fraction "$deck")' '$reported' 0.001"
  sum=$(sed -n 's/^#   \(.*\)/\1/p' "$deck" | head -1 | tr ',' '\n' | awk '{s += $3} END {printf "%.6f", s}')
  check "$code: the GSD classes' number fractions sum to $sum" "same '$sum' 1 1e-3"
done
echo "$fails failure(s)"
exit $((fails > 0))
