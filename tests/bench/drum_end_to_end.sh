#!/usr/bin/env bash
# A whole drum run against the engine's own speed (issue 21, part 2): for each drum, one
# bench_drum_phases run (pour, settle, the kernel timed alone on a copy of the settled bed,
# then the 4 rpm turn with its measuring) and its per-phase wall time and particle-steps per
# second. Figures, not a test: run it on a quiet machine (no study on the other core).
# A drum may name its granule stiffness (LAMBDA:SLICE_M:K_N, N/m; default Table 3's 200): the step,
# so the cost, goes as 1/sqrt(K_N).
#   usage: drum_end_to_end.sh BUILD_DIR OUT_FILE [TURN_S] ["LAMBDA:SLICE_M[:K_N] ..."]
set -euo pipefail
build=$1 out=$2 turn_s=${3:-1.0} drums=${4:-"4096:0.015 1000:0.012"}
{
  echo "# drum_end_to_end.sh at $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- engine experiments || echo ' (engine or experiments modified)'), $(date -u +%F), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
  echo "# load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
} > "$out"
for drum in $drums; do
  IFS=: read -r lambda slice k_n <<< "$drum"
  OMP_NUM_THREADS=1 "$build/tests/bench_drum_phases" "$lambda" "$slice" pour 1 4 "$turn_s" ${k_n:+"$k_n"} | tee -a "$out"
done
