#!/usr/bin/env bash
# Threads on a many-core node (issue 37.4; a benchmark, not a test): the fine tier's drum
# (λ 512, 8 mm periodic slice, ~4 900 granules) turned at 40 rpm for 0.2 s on 1, 2, 4, 8 and 16
# threads, then the node's 16 cores shared as 16 runs x 1 thread ... 1 run x 16 threads; then the
# same on a 3x deeper slice (~15 000 granules), where threads have more granules each.
# Each measurement is one line of bench_threads (tests/bench/bench_threads.c) in OUT/threads_*.txt.
#   usage: threads_on_node.sh BENCH_THREADS OUT [CORES]
# Results: results/benchmarks/threads_node/ (with the machine's lscpu).
set -uo pipefail
bench=$1 out=$2 cores=${3:-$(nproc)}
mkdir -p "$out"
lscpu > "$out/lscpu.txt"
counts=1
for ((t = 2; t <= cores; t *= 2)); do counts+=",$t"; done
run() { # NAME SECONDS ARGS...
  local name=$1 limit=$2; shift 2
  echo "== $name: bench_threads $* (limit ${limit} s)"
  local timer=(); [ -x /usr/bin/time ] && timer=(/usr/bin/time -v)
  "${timer[@]}" timeout "$limit" "$bench" "$@" 2> "$out/$name.time" | tee "$out/$name.txt"
  grep -E "Elapsed|Maximum resident" "$out/$name.time" || cat "$out/$name.time"
}
run threads_L512_slice8 300 512 0.008 40 0.2 "$counts" "$cores"
run threads_L512_slice24 200 512 0.024 40 0.1 "$counts"
