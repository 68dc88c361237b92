#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# docs/guide.md, run as a reader runs it: every ```sh block, in the guide's order, in one fresh
# work folder (the reader's), each block by `bash -e -o pipefail`, with the built granucal first on
# PATH and GRANUCAL_SRC the source tree (as the guide asks the reader to set). Fails on the first
# block that fails, naming its line in the guide; then checks that what the guide tells the reader
# to read was written.
#
#   guide.sh GRANUCAL SRC [WORK [GUIDE]]     # WORK: default a new temporary folder (kept on failure,
#                                            # and on success with GUIDE_KEEP=1)
set -euo pipefail
granucal=$(realpath "$1") src=$(realpath "$2")
work=${3:-$(mktemp -d /tmp/guide.XXXXXX)}
guide=$(realpath "${4:-$src/docs/guide.md}")
rm -rf "$work" && mkdir -p "$work/.blocks"
export PATH="$(dirname "$granucal"):$PATH" GRANUCAL_SRC="$src"
[ "$(command -v granucal)" = "$granucal" ] || { echo "FAIL: granucal on PATH is $(command -v granucal)"; exit 1; }

# Each ```sh block into .blocks/NNN-LINE.sh (LINE: the guide's line of its first command).
awk -v dir="$work/.blocks" '
    /^```sh[ \t]*$/ { inside = 1; n++; file = sprintf("%s/%03d-%d.sh", dir, n, NR + 1); next }
    /^```/ && inside { inside = 0; close(file); next }
    inside { print > file }
    END { if (inside) { print "unterminated ```sh block" > "/dev/stderr"; exit 1 } }' "$guide"
blocks=("$work"/.blocks/*.sh)
[ -e "${blocks[0]}" ] || { echo "FAIL: no \`\`\`sh block in $guide"; exit 1; }
echo "guide: ${#blocks[@]} command blocks from $guide, run in $work"

for block in "${blocks[@]}"; do
    line=$(basename "$block" .sh); line=${line#*-}
    echo "== $guide:$line"
    sed 's/^/   $ /' "$block"
    start=$SECONDS
    if ! (cd "$work" && bash -e -o pipefail "$block") > "$block.log" 2>&1; then
        tail -20 "$block.log"
        echo "FAIL: the block at $guide:$line failed (log: $block.log; work folder kept: $work)"
        exit 1
    fi
    echo "   ok ($((SECONDS - start)) s)"
done

# What the guide has the reader read and copy must be there, from this run.
fails=0
for file in repose_angle.csv occupied_area.csv my_drum.yaml psd_volume.csv run_tiny/report.md \
    run_tiny/calibrated_parameters.csv run_tiny/calibrated_parameters.md run_tiny/liggghts_parameters.in \
    run_tiny/lammps_parameters.in; do
    [ -s "$work/$file" ] || { echo "FAIL: the guide's $file was not written"; fails=$((fails + 1)); }
done
# The guide measures both linings at both speeds: 2 angle rows (the angle speed) and 4 CSA rows.
[ "$(grep -c ',4,' "$work/repose_angle.csv" || true)" = 2 ] || { echo "FAIL: repose_angle.csv lacks a lining's 4 rpm row"; fails=$((fails + 1)); }
[ "$(grep -cE ',(4|40),' "$work/occupied_area.csv" || true)" = 4 ] || { echo "FAIL: occupied_area.csv lacks rows"; fails=$((fails + 1)); }
grep -q 'steel' "$work/run_tiny/calibrated_parameters.csv" || { echo "FAIL: no steel row in the table"; fails=$((fails + 1)); }
# The run drew its granules from the table: every stored simulation's key names it (a log-normal's does not).
records=$(ls "$work"/run_tiny/store/*.yaml 2>/dev/null | wc -l)
keyed=$(grep -l "^key: .* gsd_table=18:" "$work"/run_tiny/store/*.yaml 2>/dev/null | wc -l)
[ "$records" -gt 0 ] && [ "$keyed" = "$records" ] || { echo "FAIL: $keyed of $records stored simulations keyed by the 18-row size table"; fails=$((fails + 1)); }
if [ "$fails" = 0 ]; then
    echo "guide: every block ran"
    [ "${GUIDE_KEEP:-0}" = 1 ] || rm -rf "$work"
fi
echo "$fails failure(s)"
[ "$fails" = 0 ]
