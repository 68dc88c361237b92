#!/usr/bin/env bash
# The drum geometry study (results/drum_geometry/README.md): the periodic 15 mm slice (configs/drum.yaml)
# against a drum of the same depth closed by end plates (drum_full15.yaml), and,
# if time allows, a periodic slice 44 mm deep and the full 44 mm drum; all at
# lambda 4096, 4 rpm, Table 3 parameters, seed 1. One OpenMP thread per run
# (spinning barriers under an oversubscribed machine cost more than they gain).
# Usage: bash tests/bench/drum_geometry_study.sh [GRANUCAL] [CASE ...]
#   CASE: slice15 full15 slice44 full44 (default: slice15 full15); MAXT caps the turning time (default 6 s)
set -euo pipefail
cd "$(dirname "$0")/../.."
G=${1:-build/granucal}; shift || true
cases=${*:-slice15 full15}
out=results/runs/drum_geometry
for name in $cases; do
  case $name in
    slice15) cfg=configs/drum.yaml ;;
    slice44) cfg=results/drum_geometry/drum_slice44.yaml ;;
    full15)  cfg=results/drum_geometry/drum_full15.yaml ;;
    full44)  cfg=results/drum_geometry/drum_full.yaml ;;
  esac
  mkdir -p $out/$name
  OMP_NUM_THREADS=1 /usr/bin/time -f "%e s wall, %M KiB" -o $out/$name/time.txt \
    $G simulate $cfg --set max_time=${MAXT:-6} --out $out/$name > $out/$name/stdout.json 2> $out/$name/stderr.txt
  cat $out/$name/stdout.json
done
