#!/usr/bin/env bash
# A small calibration (the PTFE wall alone, tier `check`, or TIER) run on one process and with
# `mpirun -np 2` gives the same table and the same measurement in every record. With
# TIER=check-two-tier the two-tier search (its map tier's runs, then the deciding tier's) is
# spread over the ranks as the standard tier's would be. And a run on its own starts no MPI.
#   usage: [REFERENCE=DIR] mpi_same_table.sh GRANUCAL SOURCE_DIR WORK_DIR [TIER]
#   REFERENCE: the same calibration run without MPI (made once for several tests, on 2 worker
#   processes: tests/CMakeLists.txt); without it, it is made here on one process.
set -euo pipefail
bin=$1 src=$2 work=$3 tier=${4:-check}
rm -rf "$work" && mkdir -p "$work"
cd "$src"
args=(calibrate configs/calibration.yaml --tier "$tier" --material PTFE --jobs 1)
serial=${REFERENCE:-$work/serial}
[ -n "${REFERENCE:-}" ] || "$bin" "${args[@]}" --out "$serial" > "$work/serial.log" 2>&1 || { cat "$work/serial.log"; exit 1; }
# Run on its own, granucal starts no MPI (cal_mpi.c): Open MPI's singleton init would leave its session
# directory in TMPDIR, beside an orted daemon it forks and execs as a child of the run.
mkdir -p "$work/tmp"
TMPDIR=$work/tmp "$bin" "${args[@]}" --plan --out "$work/plan" > /dev/null 2>&1
[ -z "$(ls -A "$work/tmp")" ] || { echo "a run on its own started MPI: TMPDIR holds $(ls "$work/tmp")"; exit 1; }
mpi=(mpirun -np 2)
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
"${mpi[@]}" --oversubscribe "$bin" "${args[@]}" --out "$work/mpi" > "$work/mpi.log" 2>&1 || { cat "$work/mpi.log"; exit 1; }
diff "$serial/calibrated_parameters.csv" "$work/mpi/calibrated_parameters.csv"
# Every simulation's measurement (costs aside) is the same whichever rank ran it.
strip() { cut -d, -f1-15,18-20 "$1"; } # wall, fill and memory columns aside
diff <(strip "$serial/simulations.csv") <(strip "$work/mpi/simulations.csv")
n=$(($(wc -l < "$serial/simulations.csv") - 1))
grep -q "2 rank(s)" "$work/mpi/report.md" || { echo "the MPI run did not see 2 ranks"; exit 1; }
echo "tier $tier: same table and the same $n simulations without MPI and from 2 MPI ranks"
