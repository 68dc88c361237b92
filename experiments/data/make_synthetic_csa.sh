#!/usr/bin/env bash
# Makes experiments/data/occupied_area.csv: a SYNTHETIC occupied-area (CSA) curve per drum
# lining, simulated by granucal itself at the paper's Table 3 pairs. The paper publishes its
# CSA measurements only as figures (Fig. 15, 18), so no lab numbers exist to ship; this stands
# in for them so that a calibration has a curve to fit. Replace it with your own lab CSV (same
# schema) to calibrate a real powder.
#
# The drum is the `fine` tier of configs/calibration.yaml: lambda 512 in an 8 mm slice, the
# finest rung of the fidelity ladder (results/fidelity_ladder/), which is NOT converged (its
# 4 rpm angle is still falling with lambda). Beds (seeds) 2 and 3: bed 1 is the one a `fine`
# calibration's candidates would use. The drum lined with granules at Table 3's pair is the
# ladder's own L512 run, so those records are taken from the ladder's store (--reuse, same
# key: same simulation) and only the PP/PTFE lining is simulated here (about 2 hours of one
# core per bed). Aluminium has the granule pair and PP the PTFE pair (Table 3), so each is the
# same simulation as its twin and runs once.
#   usage: experiments/data/make_synthetic_csa.sh [BUILD_DIR] [JOBS]
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build} jobs=${2:-2}
out=results/synthetic-fine
# One thread per simulation: simulations run side by side (OpenMP threads spinning at
# barriers on a shared machine slow a run down by orders of magnitude).
export OMP_NUM_THREADS=1
"$build/granucal" synthesize configs/calibration.yaml --tier fine --granule 0.8,0.2 \
  --wall aluminium=0.8,0.2 --wall PP=0.9,1e-4 --wall PTFE=0.9,1e-4 --seeds 2,3 \
  --reuse results/fidelity_ladder/store --out "$out" --jobs "$jobs"
{
  echo "# SYNTHETIC stand-in for the CSA curves the paper shows only as figures (Fig. 15, 18);"
  echo "# made by experiments/data/make_synthetic_csa.sh. Its own header follows."
  cat "$out/occupied_area.csv"
} > experiments/data/occupied_area.csv.tmp
mv experiments/data/occupied_area.csv.tmp experiments/data/occupied_area.csv
echo "wrote experiments/data/occupied_area.csv (the run: $out)"
