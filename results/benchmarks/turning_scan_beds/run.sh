#!/usr/bin/env bash
# The turning scan's LIGGGHTS runs again with three beds a step (issue 37.3): the exported decks of the
# committed ci twin, 40 rpm, beds 0 1 2 (the decks' `bed` variable), each step's granucal 3 seeds beside.
#   bash results/benchmarks/turning_scan_beds/run.sh BUILD "F1 F2 ..."
set -uo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
build=$(realpath "$1") out=$root/results/benchmarks/turning_scan_beds
for f in $2; do
  PEERS=liggghts PEER_BEDS="0 1 2" DT_FRACTION=$f bash "$root/tests/peers/drum_peers.sh" "$build/granucal" \
    "$build/tests/drum_peers" "$out/turn_$f" > "$out/turn_$f.txt" 2>&1
  rm -f "$out/turn_$f"/*/*.dump "$out/turn_$f"/*/*.h5
  rm -rf "$out/turn_$f/export" "$out/turn_$f"/granucal_s*/
done
