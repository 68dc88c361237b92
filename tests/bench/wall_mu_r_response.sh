#!/usr/bin/env bash
# How the wall's rolling friction moves the 116 rpm drum at the ci tier's fidelity
# (results/table3_ci/wall_mu_r_response/README.md): the ci tier's drum (lambda 32768,
# 30 mm periodic slice, at most 4 s) lined with each of the six wall materials of
# drum_walls.yaml (wall mu_r 1e-4 ... 0.2), one seed. One JSON (and one log) per wall in OUTDIR.
# Usage: bash tests/bench/wall_mu_r_response.sh GRANUCAL SEED [OUTDIR]
#   (the committed JSONs: granucal at 86abf7e, seeds 1 and 2, OUTDIR the results folder)
set -euo pipefail
cd "$(dirname "$0")/../.."
g=${1:?usage: wall_mu_r_response.sh GRANUCAL SEED [OUTDIR]}
seed=${2:?usage: wall_mu_r_response.sh GRANUCAL SEED [OUTDIR]}
study=results/table3_ci/wall_mu_r_response
out=${3:-results/runs/wall_mu_r_response}
mkdir -p "$out"
for m in r1e-4 r1e-3 r1e-2 r0.033 r0.1 r0.2; do
  "$g" simulate "$study/drum_walls.yaml" --set lambda=32768 --set slice_depth=0.03 --set rpm=116 \
    --set max_time=4 --set seed="$seed" --set wall="$m" --out "$out/out_${m}_s$seed" \
    > "$out/${m}_s$seed.json" 2> "$out/${m}_s$seed.log"
done
