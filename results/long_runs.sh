#!/usr/bin/env bash
# The lab book's runs in progress: one home for their commands, so that a session resumes them as the
# last one left them, says where they stand, and commits their stores before it stops.
#
#   bash results/long_runs.sh status          each run: running or not, records stored, its log's last line,
#                                             and what its own --plan says is left (it runs nothing)
#   bash results/long_runs.sh start [NAME...] resume those not running (by default those the table marks
#                                             yes), niced, in the background, each with a '=== resumed
#                                             ...' line in its log
#   bash results/long_runs.sh stop [NAME...]  SIGTERM (a drum run resumes from its last checkpoint, at most
#                                             --checkpoint-every = 120 s of wall behind), wait for the end,
#                                             then commit, with the checkpoints: run it before a session stops
#   bash results/long_runs.sh commit [--checkpoints]
#                                             commit the runs' folders (only those paths), if they changed;
#                                             the runs' checkpoints too with --checkpoints (see commit())
#   bash results/long_runs.sh chain FIRST NEXT
#                                             wait while FIRST runs, then start NEXT, unless FIRST was
#                                             stopped (its log's last '===' line): run it with nohup, so that
#                                             a core freed between two looks at the session is not left idle
#   bash results/long_runs.sh keep-committed [MINUTES]
#                                             commit every MINUTES (default 20) until killed: a session's stop
#                                             then loses at most that much of a finished simulation
#
# A run's records are named by a hash of all that defines them, so resuming with a newer granucal serves
# its records only where its results version and keys are unchanged: `granucal ... --plan` on the run's
# folder says how many it finds before anything starts (run it after a change to the engine or a tier).
# Each run is one worker, one thread (OMP_NUM_THREADS=1, --jobs 1): on this 2-core machine two runs side
# by side use it fully, where a lone run on two threads turns only 1.29-1.47x faster
# (results/benchmarks/threads_2core/). NICE: a run's share when a test suite or a third run competes.
# A run is listed here while its README says IN PROGRESS; take it out when it is done (twin-data, the
# twin's synthesis, and twin-calibration, its calibration, both ended 2026-12-02:
# results/twin_standard/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
granucal=${GRANUCAL:-build/granucal}

# name | folder committed | log | nice | started by a plain `start` (yes) or only by name (waits: no core
# for it while the others run) | command (from the repository root) | what its start does first, if
# anything (run each start: it must leave what is already there as it is)
runs=(
  "rerun|results/calibration-standard-r2|results/calibration-standard-r2/run.log|10|yes|$granucal calibrate configs/calibration.yaml --tier standard --jobs 1 --out results/calibration-standard-r2"
  "stiffness-L512|results/stiffness_drum_L512|results/stiffness_drum_L512/run.log|19|waits|$granucal calibrate configs/calibration.yaml --tier fine-levels --stage stiffness --jobs 1 --out results/stiffness_drum_L512"
)
field() { cut -d'|' -f"$2" <<< "$1"; }
# selected ROW DEFAULT NAME...: the row is one of the names given; with none given, every row (DEFAULT
# all) or those whose fifth field is yes (DEFAULT yes: what a plain start starts).
selected() {
  local row=$1 default=$2; shift 2
  [ $# -eq 0 ] && { [ "$default" = all ] || [ "$(field "$row" 5)" = yes ]; return; }
  local n; for n in "$@"; do [ "$(field "$row" 1)" = "$n" ] && return 0; done
  return 1
}
known() { local n r; for n in "$@"; do for r in "${runs[@]}"; do [ "$(field "$r" 1)" = "$n" ] && continue 2; done
  echo "long_runs.sh: no run named '$n' (runs: $(for r in "${runs[@]}"; do printf '%s ' "$(field "$r" 1)"; done))" >&2; exit 2; done; }
# The pid of a run's command, empty if none runs: its parent process, the one whose own parent is not
# another of the same command (workers are its forked children, with the same command line). Not the
# lowest pid: once the pids wrap round a worker's can be lower, and a stop at stop 53 sent SIGTERM to
# the workers alone. Whatever path the binary was started by, and only a process working in this
# checkout (another clone's run of the same command is not this one's).
pid_of() {
  local args pid here parent mine=()
  args=$(field "$1" 6 | cut -d' ' -f2- | sed 's/[][\\.*^$+?(){}|]/\\&/g')
  here=$(pwd -P)
  for pid in $(pgrep -f -- "(^|/)granucal $args\$" || true); do
    [ "$(readlink "/proc/$pid/cwd" 2>/dev/null)" = "$here" ] && mine+=("$pid")
  done
  for pid in "${mine[@]}"; do
    parent=$(ps -o ppid= -p "$pid" 2>/dev/null | tr -d ' ')
    [[ " ${mine[*]} " == *" $parent "* ]] || { echo "$pid"; return; }
  done
  return 0
}
# A run's records: its store beside its log (0 for a run not started: no store yet).
records() {
  local store; store=$(dirname "$(field "$1" 3)")/store
  if [ -d "$store" ]; then find "$store" -name '*.yaml' | wc -l; else echo 0; fi
}

# What a run's own --plan says is left (from its '== left' line): --plan replays the store and
# runs and writes nothing, so it is safe beside the run itself.
left() {
  [ -x "$granucal" ] || { echo "(not built: no plan)"; return 0; }
  # shellcheck disable=SC2046 # the command is words
  local plan; plan=$(OMP_NUM_THREADS=1 $(field "$1" 6) --plan 2>&1 || true)
  if grep -q '^== left' <<< "$plan"; then
    # Both of its figures: at the plan's rate, and at the stored runs' own wall times (these runs, side by
    # side on this 2-core machine, ran at ~0.6 of the plan's rate: calibration-standard-r2/README.md).
    grep '^== left' <<< "$plan" | sed -E 's/.*[Ee]xpected left: /its plan: left /; s/ \(each (step|lining)[^)]*\)//; s/\. What the search.*//'
  else echo "its plan: none ($(tail -1 <<< "$plan" | cut -c1-120))"; fi
}

status() {
  local r pid
  for r in "${runs[@]}"; do
    pid=$(pid_of "$r")
    printf '%-17s %-8s %4d records  %s\n' "$(field "$r" 1)" "${pid:+running}" "$(records "$r")" "$(field "$r" 2)"
    printf '                  %s\n' "$(tail -1 "$(field "$r" 3)" 2>/dev/null | cut -c1-150)"
    printf '                  %s\n' "$(left "$r")"
  done
}

start() {
  [ -x "$granucal" ] || { echo "long_runs.sh: $granucal not built (bash .ci/setup)" >&2; exit 1; }
  local r log when commit
  commit=$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- engine experiments calib || echo "+uncommitted")
  for r in "${runs[@]}"; do
    selected "$r" yes "$@" || continue
    [ -z "$(pid_of "$r")" ] || { echo "$(field "$r" 1): already running"; continue; }
    log=$(field "$r" 3) when=$(date -u +%Y-%m-%dT%H:%M:%SZ)
    mkdir -p "$(dirname "$log")"
    if [ -n "$(field "$r" 7)" ]; then
      echo "$(field "$r" 1): first: $(field "$r" 7)"
      bash -c "$(field "$r" 7)"
    fi
    echo "=== resumed $when by $commit (results/long_runs.sh, nice $(field "$r" 4), one worker) ===" >> "$log"
    # shellcheck disable=SC2086 # the command is words
    OMP_NUM_THREADS=1 nohup nice -n "$(field "$r" 4)" $(field "$r" 6) >> "$log" 2>&1 < /dev/null &
    echo "$(field "$r" 1): started (pid $!), log $log"
  done
}

stop() {
  local r pid pids=()
  for r in "${runs[@]}"; do
    selected "$r" all "$@" || continue
    pid=$(pid_of "$r")
    [ -n "$pid" ] || continue
    echo "=== stopped $(date -u +%Y-%m-%dT%H:%M:%SZ) (SIGTERM, results/long_runs.sh) ===" >> "$(field "$r" 3)"
    kill -TERM "$pid" && pids+=("$pid") && echo "$(field "$r" 1): SIGTERM sent (pid $pid)"
  done
  local p; for p in "${pids[@]}"; do while kill -0 "$p" 2>/dev/null; do sleep 1; done; done
  commit --checkpoints
}

# commit [--checkpoints]: the runs' folders, only those paths. A drum run's checkpoint (STORE/*.turn.h5,
# ignored by git: a few MB, rewritten every 120 s) is taken only with --checkpoints, as `stop` does: a
# later session's clone has no ignored file, so without it each stop threw away every run in flight
# (the rerun's 4 rpm run of candidate 4 lost 1 823 s of wall that way at stop 50). Taken at each stop only, it
# adds a few MB a stop to the repository, not a few MB every 20 minutes; git drops it from the tree once
# the run has stored its record and removed it.
commit() {
  local r paths=() summary=() checkpoints=()
  for r in "${runs[@]}"; do paths+=("$(field "$r" 2)"); summary+=("$(field "$r" 1) $(records "$r")"); done
  git add -A -- "${paths[@]}"
  if [ "${1:-}" = --checkpoints ]; then
    mapfile -t checkpoints < <(find "${paths[@]}" -path '*/store/*.turn.h5' 2>/dev/null)
    [ ${#checkpoints[@]} -eq 0 ] || git add -f -- "${checkpoints[@]}"
  fi
  if git diff --cached --quiet -- "${paths[@]}"; then echo "long_runs.sh: nothing new to commit"; return 0; fi
  local joined; joined=$(printf '%s, ' "${summary[@]}")
  git commit -q -m "Long runs in progress (not results): records stored: ${joined%, }${checkpoints:+; with the checkpoints of the runs in flight (${#checkpoints[@]})}" -- "${paths[@]}"
  git log --oneline -1
}

# chain FIRST NEXT: NEXT starts once FIRST's process is gone, unless FIRST's log says it was stopped
# (`stop` writes '=== stopped' there; a run that ended by itself leaves its own last line after the
# '=== resumed' one).
chain() {
  [ $# -eq 2 ] || { echo "long_runs.sh: chain FIRST NEXT" >&2; exit 2; }
  known "$1" "$2"
  local r first=""; for r in "${runs[@]}"; do [ "$(field "$r" 1)" = "$1" ] && first=$r; done
  while [ -n "$(pid_of "$first")" ]; do sleep 60; done
  local last; last=$(grep '^===' "$(field "$first" 3)" | tail -n 1 || true)
  if [[ $last == "=== stopped"* ]]; then
    echo "long_runs.sh: $1 was stopped, so $2 is not started"; return 0
  fi
  echo "long_runs.sh: $1 ended at $(date -u +%H:%M:%SZ): its log's end:"; tail -3 "$(field "$first" 3)"
  start "$2"
}

keep_committed() {
  local minutes=${1:-20}
  [[ "$minutes" =~ ^[0-9]+$ ]] && [ "$minutes" -gt 0 ] || { echo "long_runs.sh: MINUTES must be a positive integer" >&2; exit 2; }
  while sleep $((minutes * 60)); do
    # another git command holding the index: try again shortly instead of failing the loop
    local try; for try in 1 2 3 4 5 6; do [ -e .git/index.lock ] && sleep 10 || break; done
    commit || echo "long_runs.sh: commit failed at $(date -u +%H:%M:%SZ) (exit $?); the loop goes on" >&2
  done
}

main() {
  local cmd=${1:-status}; shift || true
  case $cmd in
    status) status ;;
    start) known "$@"; start "$@" ;;
    stop) known "$@"; stop "$@" ;;
    commit) commit "$@" ;;
    chain) chain "$@" ;;
    keep-committed) keep_committed "$@" ;;
    -h | --help | help) sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' ;;
    *) echo "long_runs.sh: unknown command '$cmd' (status, start, stop, chain, commit, keep-committed; --help)" >&2; exit 2 ;;
  esac
}
# One line, read whole before it runs: a chain or keep-committed runs for hours, and bash reads a script
# as it goes, so without the exit on this line an edit of this file meanwhile had the ended command read
# on at its old offset (a chain ended in a syntax error, stop 53).
main "$@"; exit
