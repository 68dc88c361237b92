#!/usr/bin/env bash
# The README's main job, `granucal calibrate` on the default config (the quick tier), run as a user
# runs it; its outputs must say what they are: a demonstration at tier 'quick' on the lab angles and
# the synthetic CSA, every row of the .csv with its status and flags, the .in files with the banner
# and a NOT CALIBRATED line for each friction the data did not choose (check_outputs_say_what.py).
#   usage: quick_outputs.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cd "$src"
"$bin" calibrate --out "$work/quick" --jobs 2 > "$work/quick.log" 2>&1 || { cat "$work/quick.log"; exit 1; }
python3 tests/calibration/check_outputs_say_what.py "$work/quick" --tier quick --purpose demonstration \
  --data "angle lab / CSA synthetic"
