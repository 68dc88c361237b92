#!/usr/bin/env bash
# Prune a finished calibration's store to what its table was derived from (the "When it finishes" step
# of a long run's README): the records its simulations.csv names stay, with every turned start bed
# (*.start.h5: a record names its start bed by key, not by file; there are one or two per lining and
# seed, so they all stay); every other record (*.yaml: seeded from other runs, never served) goes.
# A checkpoint (*.turn.h5) left in a finished run's store is refused: a run in flight, or a stop that
# did not end it, and pruning then would drop what it resumes from.
#   usage: bash results/prune_store.sh FOLDER            what would go (nothing is removed)
#          bash results/prune_store.sh FOLDER --apply    remove them (git rm where tracked)
# Afterwards the same calibrate command on FOLDER must say "0 simulations run now" and write the same
# table; check it before committing.
set -euo pipefail
folder=${1:?usage: prune_store.sh FOLDER [--apply]} apply=${2:-}
csv=$folder/simulations.csv store=$folder/store
[ -f "$csv" ] || { echo "prune_store.sh: $csv: no such file (a finished calibration writes it)" >&2; exit 2; }
[ -d "$store" ] || { echo "prune_store.sh: $store: no such folder" >&2; exit 2; }
if compgen -G "$store/*.turn.h5" > /dev/null; then
  echo "prune_store.sh: $store holds checkpoints (*.turn.h5): is the run still going? Nothing pruned." >&2; exit 1
fi
used=$(python3 - "$csv" <<'PY'
import csv, sys
with open(sys.argv[1]) as f:
    print("\n".join(sorted({r["record"] for r in csv.DictReader(f) if r["record"]})))
PY
)
[ -n "$used" ] || { echo "prune_store.sh: $csv names no record: nothing pruned" >&2; exit 1; }
kept=0 gone=()
for f in "$store"/*.yaml; do
  if grep -qxF "$(basename "$f" .yaml)" <<< "$used"; then kept=$((kept + 1)); else gone+=("$f"); fi
done
missing=$(comm -23 <(echo "$used") <(ls "$store" | sed -n 's/\.yaml$//p' | sort) | wc -l)
[ "$missing" -eq 0 ] || { echo "prune_store.sh: $missing record(s) simulations.csv names are not in $store: nothing pruned" >&2; exit 1; }
echo "$folder: $kept record(s) named by simulations.csv kept, $(ls "$store"/*.start.h5 2>/dev/null | wc -l) start bed(s) kept, ${#gone[@]} record(s) to go"
[ "$apply" = --apply ] || { printf '  would go: %s\n' "${gone[@]:-none}"; exit 0; }
for f in "${gone[@]}"; do
  if git ls-files --error-unmatch "$f" > /dev/null 2>&1; then git rm -q "$f"; else rm "$f"; fi
done
echo "removed ${#gone[@]}"
