#!/usr/bin/env bash
# Makes experiments/data/occupied_area.csv: a SYNTHETIC occupied-area (CSA) curve per drum
# lining, simulated by granucal itself at the paper's Table 3 parameters. The paper publishes
# its CSA measurements only as figures (Fig. 15, 18), so no lab numbers exist to ship; this
# stands in for them so the calibration has a curve to fit, at a fidelity higher than the
# CI tier (drum lambda = 16384 here, twice the granules of the ci tier's 32768). Replace it with your own lab CSV (same
# schema) to calibrate a real powder.
#   usage: experiments/data/make_synthetic_csa.sh [BUILD_DIR]   (needs python3 for the JSON)
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build}
out=results/runs/synthetic_csa
rpms=4,40,80,105,116
mkdir -p "$out"
# One thread per simulation: two run side by side, and OpenMP threads spinning at barriers
# on a shared, oversubscribed machine slow a run down by orders of magnitude.
export OMP_NUM_THREADS=1
run() { # lining surface-name
  "$build/granucal" simulate configs/drum.yaml --set wall="$1" --set lambda=16384 --set slice_depth=0.025 \
    --set max_time=6 --rpm-list "$rpms" \
    --out "$out/$1" > "$out/$1.json" 2> "$out/$1.log"
}
# Table 3 gives aluminium the granule-granule pair and PP the PTFE pair, with the same
# granule-boundary stiffness, so those linings are the same deterministic simulation:
# each distinct one is run once and its curve written under both names.
run granules & run PTFE & wait
python3 - "$out" "$(git rev-parse --short HEAD)" <<'PY'
import json, sys
out, commit = sys.argv[1], sys.argv[2]
names = {"spray-dried powder": "granules", "Aluminium": "granules", "PP": "PTFE", "PTFE": "PTFE"}
with open("experiments/data/occupied_area.csv", "w") as f:
    f.write("# SYNTHETIC - not lab data. Occupied cross-section area (eq. 20) simulated by granucal\n")
    f.write(f"# (commit {commit}) at Table 3's parameters: configs/drum.yaml, lambda 16384, 25 mm periodic\n")
    f.write("# slice, max_time 6 s, steady-state window 1 s; csa_sd_percent is the spread over the last\n")
    f.write("# window. Aluminium repeats the granule lining and PP repeats PTFE: Table 3 gives them the\n")
    f.write("# same pair, so the simulation is the same. Made by: experiments/data/make_synthetic_csa.sh\n")
    f.write("surface,rpm,csa_percent,csa_sd_percent\n")
    for surface, lining in names.items():
        for r in json.load(open(f"{out}/{lining}.json"))["runs"]:
            f.write(f"{surface},{r['rpm']:g},{r['csa_percent']:.2f},{max(r['csa_sd_percent'], 0.05):.2f}\n")
PY
echo "wrote experiments/data/occupied_area.csv"
