#!/usr/bin/env bash
# The test command: set up, build, run every ctest label, then rebuild with
# AddressSanitizer + UndefinedBehaviorSanitizer and run the unit and physics tests under it
# (the fuzz corpus replays, label unit, among them), then fuzz the input loaders for a
# bounded time with libFuzzer (clang; tests/fuzz/run_fuzz.sh, on a copy of the corpus).
set -euo pipefail
cd "$(dirname "$0")/.."
bash .ci/setup
# Table 3 end to end (label table3) joins when its tolerances are measured (issue 5; README).
ctest --test-dir build --output-on-failure -j1 -LE table3
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DGRANUCAL_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$(nproc)" >/dev/null
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-asan --output-on-failure -L "unit|physics" -j1
# 45 s per loader (CSV, YAML): about 2.5 min with the clang build.
bash tests/fuzz/run_fuzz.sh 45
