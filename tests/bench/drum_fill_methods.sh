#!/usr/bin/env bash
# The drum's bed built two ways (issue 21, part 2): the layer-by-layer pour and the random
# packing bands, over several seeds, each settled bed turned at 4 rpm as a calibration turns it.
# A study, not a test: it appends one line per run (bench_drum_phases) to OUT/runs.txt and
# prints, per method, the mean and seed spread of what must agree (solid fraction,
# coordination, the 4 rpm angle and CSA) and what the pack should save (fill wall time).
#   usage: drum_fill_methods.sh BUILD_DIR OUT "LAMBDA:SLICE_M ..." "SEEDS" [RPM MAX_TIME_S]
set -euo pipefail
build=$1 out=$2 rungs=$3 seeds=$4 rpm=${5:-4} max_time=${6:-6}
mkdir -p "$out"
for rung in $rungs; do
  lambda=${rung%%:*} slice=${rung##*:}
  for seed in $seeds; do
    for method in pour pack; do
      line=$("$build/tests/bench_drum_phases" "$lambda" "$slice" "$method" "$seed" "$rpm" "$max_time")
      echo "$line" | tee -a "$out/runs.txt"
    done
  done
done
summary() {
  awk -v lam="$1" -v m="$2" '
    { delete f; for (i = 1; i <= NF; ++i) { split($i, kv, "="); f[kv[1]] = kv[2] } }
    f["lambda"] == lam && f["fill_method"] == m {
      n++; for (k in f) if (f[k] + 0 == f[k]) { s[k] += f[k]; q[k] += f[k] * f[k] } }
    END {
      if (!n) exit
      printf "| %s | %s | %d |", lam, m, n
      split("solid_fraction coordination angle_deg csa_percent fill_wall_s fill_sim_s turn_wall_s", ks, " ")
      for (j = 1; j <= 7; ++j) { k = ks[j]; mu = s[k] / n; v = n > 1 ? (q[k] - n * mu * mu) / (n - 1) : 0
        printf " %.4g ± %.2g |", mu, sqrt(v > 0 ? v : 0) }
      printf "\n" }' "$out/runs.txt"
}
echo "| λ | fill | seeds | solid fraction | coordination | angle at ${rpm} rpm (°) | CSA (%) | fill wall (s) | fill simulated (s) | turn wall (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for rung in $rungs; do for method in pour pack; do summary "${rung%%:*}" "$method"; done; done
