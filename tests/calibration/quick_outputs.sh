#!/usr/bin/env bash
# The README's main job, `granucal calibrate` on the default config (the quick tier), verified from
# its committed run (results/plots_quick/, made by that very command): the table re-derived from the
# committed store by the same command is the committed one byte for byte with 0 simulations; two of
# its drum records, drawn at random, rerun to the same measurements; and every re-derived output says
# what it is: a demonstration at tier 'quick' on the lab angles and the synthetic CSA, every row of the
# .csv with its status and flags, the .in files with the banner and a NOT CALIBRATED line for each
# friction the data did not choose (check_outputs_say_what.py).
# It ran the whole main job from scratch until stop 48 (~200 s of both cores); that whole path, from
# photos to a table, is run from scratch by the `guide` test at the tiny tier, and the quick tier's
# simulations by the reruns here. A change that moves the quick tier's results fails here until
# results/plots_quick/ is made again (its README says how).
#   usage: quick_outputs.sh GRANUCAL SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
SAYS="quick demonstration angle lab / CSA synthetic" JOBS=2 \
  bash "$src/tests/calibration/verify_committed.sh" "$bin" "$src" "$src/results/plots_quick" "$work" 2
