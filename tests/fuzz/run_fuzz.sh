#!/usr/bin/env bash
# Fuzz the input loaders with libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer
# (and LeakSanitizer) for a bounded time each: fuzz_csv (calib/inputs/cal_data.c) and
# fuzz_yaml (calib/inputs/cal_config.c, experiments/drum/exp_drum_config.c,
# experiments/scene/exp_scene.c).
#
#   tests/fuzz/run_fuzz.sh [SECONDS_PER_TARGET] [csv|yaml ...]     (default: 60 s, both)
#
# Builds them with clang in build-fuzz/ (GRANUCAL_FUZZ=ON, GRANUCAL_SANITIZE=ON)
# and runs each on a COPY of the committed corpus (tests/fuzz/corpus/KIND), so a
# run never grows the corpus, the targets side by side where the machine has a core for
# each. Exits non-zero on any crash, leak, UB, timeout or broken invariant, printing the
# log's tail and the input that did it (kept in build-fuzz/run/KIND/artifacts/); replay one with
#   build-fuzz/tests/fuzz/fuzz_KIND ARTIFACT
# Without clang or libFuzzer it says so and exits 2 (.ci/setup installs them).
#
# FUZZ_MERGE=1: after a clean run, merge what the run found that covers new
# code into the committed corpus (libFuzzer -merge=1, which keeps only inputs
# adding coverage); review and commit it by hand. Keep the corpus small.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-60}
shift || true
kinds=("$@")
[ ${#kinds[@]} -eq 0 ] && kinds=(csv yaml)
for kind in "${kinds[@]}"; do
  case "$kind" in csv | yaml) ;; *) echo "run_fuzz.sh: unknown target '$kind' (csv, yaml)" >&2; exit 2 ;; esac
done
[[ "$seconds" =~ ^[0-9]+$ ]] && [ "$seconds" -gt 0 ] || { echo "run_fuzz.sh: SECONDS must be a positive integer, got '$seconds'" >&2; exit 2; }
build=build-fuzz
cc=${FUZZ_CC:-clang}

missing() {
  echo "run_fuzz.sh: ERROR: $1" >&2
  echo "run_fuzz.sh: ERROR: the fuzz run needs clang with libFuzzer (Debian: clang libclang-rt-14-dev libomp-dev; .ci/setup installs them)" >&2
  exit 2
}
command -v "$cc" >/dev/null 2>&1 || missing "'$cc' not found"
mkdir -p "$build"
probe="$build/libfuzzer_probe"
printf '%s\n' '#include <stddef.h>' '#include <stdint.h>' \
  'int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }' > "$probe.c"
"$cc" -fsanitize=fuzzer,address,undefined "$probe.c" -o "$probe" >"$probe.log" 2>&1 ||
  { cat "$probe.log" >&2; missing "'$cc' cannot link -fsanitize=fuzzer,address,undefined (libFuzzer runtime missing)"; }

echo "run_fuzz.sh: building fuzz_csv and fuzz_yaml with $cc in $build/"
cmake -S . -B "$build" -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGRANUCAL_SANITIZE=ON \
  -DGRANUCAL_FUZZ=ON -DGRANUCAL_MPI=OFF >"$build/configure.log" 2>&1 || { cat "$build/configure.log" >&2; exit 1; }
cmake --build "$build" -j"$(nproc)" --target fuzz_csv fuzz_yaml >"$build/build.log" 2>&1 ||
  { tail -50 "$build/build.log" >&2; exit 1; }

# fuzz_one KIND: one target for $seconds s; its report goes to stdout, a failure's to stderr, and its
# exit status says whether it failed.
fuzz_one() {
  local kind=$1 max_len exe work rc=0 a
  case "$kind" in csv) max_len=8192 ;; yaml) max_len=16384 ;; esac
  exe="$build/tests/fuzz/fuzz_$kind"
  work="$build/run/$kind"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts" "$work/tmp"
  cp tests/fuzz/corpus/"$kind"/* "$work/corpus/"   # a copy: the committed corpus never grows in CI
  echo "run_fuzz.sh: fuzz_$kind for ${seconds} s on a copy of tests/fuzz/corpus/$kind ($(ls "$work/corpus" | wc -l) inputs)"
  TMPDIR="$PWD/$work/tmp" ASAN_OPTIONS=detect_leaks=1:symbolize=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$exe" "$work/corpus" -max_total_time="$seconds" -timeout=25 -rss_limit_mb=2048 -max_len=$max_len \
      -dict=tests/fuzz/$kind.dict -artifact_prefix="$work/artifacts/" -print_final_stats=1 \
      >"$work/fuzz.log" 2>&1 || rc=$?
  local artifacts=("$work"/artifacts/*)
  [ -e "${artifacts[0]}" ] || artifacts=()
  if [ "$rc" -ne 0 ] || [ ${#artifacts[@]} -gt 0 ]; then
    echo "run_fuzz.sh: FAILED: fuzz_$kind exited with $rc; the end of $work/fuzz.log:" >&2
    tail -60 "$work/fuzz.log" >&2
    for a in "${artifacts[@]}"; do
      echo "run_fuzz.sh: crash input $a ($(stat -c %s "$a") bytes), as hex:" >&2
      od -A d -t x1z -v "$a" | head -40 >&2
      echo "run_fuzz.sh: reproduce: $exe $a   (or build-fuzz-replay's fuzz_replay_$kind $a)" >&2
    done
    return 1
  fi
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb|^Done [0-9]+ runs" "$work/fuzz.log" | tr '\n' ' ' || true
  echo "(new inputs: $(($(ls "$work/corpus" | wc -l) - $(ls tests/fuzz/corpus/"$kind" | wc -l))))"
  if [ "${FUZZ_MERGE:-0}" = 1 ]; then
    local before
    before=$(ls tests/fuzz/corpus/"$kind" | wc -l)
    TMPDIR="$PWD/$work/tmp" "$exe" -merge=1 -max_len=$max_len tests/fuzz/corpus/"$kind" "$work/corpus" >"$work/merge.log" 2>&1
    echo "run_fuzz.sh: merged into tests/fuzz/corpus/$kind: $before -> $(ls tests/fuzz/corpus/"$kind" | wc -l) inputs"
  fi
}

# The targets side by side, one core each where the machine has a core for each (a libFuzzer run is one
# process): each still fuzzes for its whole $seconds, in less wall time. Each one's report is printed
# whole, in the order given, once all have ended.
status=0
parallel=$(( $(nproc) >= ${#kinds[@]} ))
pids=()
mkdir -p "$build/run"
for kind in "${kinds[@]}"; do
  if [ "$parallel" -eq 1 ]; then
    fuzz_one "$kind" >"$build/run/$kind.out" 2>&1 & pids+=($!)
  else
    fuzz_one "$kind" || status=1
  fi
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || status=1
  cat "$build/run/${kinds[$i]}.out"
done
[ "$status" -eq 0 ] && echo "run_fuzz.sh: no crash, leak, UB or broken invariant in ${seconds} s per target"
exit "$status"
