#!/usr/bin/env bash
# Whole-process speed and peak memory of `mo-retarget` on the Motion2Motion demo
# (Flamingo_Walk -> one Monkey walk clip, the reference's binding, alpha 0.9) and its scaling in
# source length and in example frames. Prints markdown tables of medians over RUNS runs.
#
#   cargo build --release && benches/retarget_cli.sh [RUNS]
#
# Optional, for the side-by-side table: M2M_REF=<checkout of LinghaoChan/Motion2Motion_codes>
# M2M_PY=<python with torch> also times the reference's own demo command the same way.
# Skips (exit 0) with a message when ../shared/data (or $SHARED_DATA) is absent. Inputs longer
# than the demo are made in a temporary directory (the walk repeated k times; copies of the
# example clip) and deleted afterwards.
set -euo pipefail
RUNS=${1:-5}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$ROOT/target/release/mo-retarget
DATA=${SHARED_DATA:-$ROOT/../shared/data}
M2M=$DATA/bvh/truebones_motion2motion
BIND=$DATA/bindings/flamingo_to_monkey.m2m.json
SRC=$M2M/Flamingo/Flamingo_Walk.bvh
EX=$M2M/Monkey/__Walk.bvh
for f in "$SRC" "$EX" "$BIND"; do
    if [ ! -e "$f" ]; then echo "retarget_cli: skipped: $f is absent (shared data not available)"; exit 0; fi
done
[ -x "$BIN" ] || { echo "retarget_cli: build first: cargo build --release" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "retarget_cli: needs /usr/bin/time (GNU time) for peak RSS" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# The source repeated k times (same hierarchy, frames appended; the root jumps back at each seam,
# which does not matter for timing).
repeat() {
    awk -v k="$1" '
        /^MOTION/ { motion = 1; print; next }
        !motion { print; next }
        /^Frames:/ { next }
        /^Frame Time/ { ft = $0; next }
        NF > 0 { d[n++] = $0 }
        END { print "Frames: " n * k; print ft; for (i = 0; i < k; i++) for (j = 0; j < n; j++) print d[j] }' "$SRC" >"$TMP/src_x$1.bvh"
}
for k in 1 8 32 64; do repeat "$k"; done
for n in 1 4 16; do
    mkdir -p "$TMP/ex$n"
    for i in $(seq 1 "$n"); do cp "$EX" "$TMP/ex$n/walk_$i.bvh"; done
done

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# measure LABEL CMD...: median wall seconds and peak RSS (MiB) of RUNS runs of CMD, plus the
# median in-process retarget time from `--report` when CMD is ours.
measure() {
    local label=$1; shift
    local walls=() rss=() loops=()
    for _ in $(seq 1 "$RUNS"); do
        /usr/bin/time -f "%e %M" -o "$TMP/time" "$@" >/dev/null 2>"$TMP/err" || { echo "| $label | failed: $(tail -1 "$TMP/err") |"; return; }
        read -r w m <"$TMP/time"
        walls+=("$w"); rss+=("$m")
        local l
        l=$(sed -n 's/.*time: .*retarget \([0-9.]*\) ms.*/\1/p' "$TMP/err")
        [ -n "$l" ] && loops+=("$l")
    done
    local w m l="-"
    w=$(printf '%s\n' "${walls[@]}" | median)
    m=$(printf '%s\n' "${rss[@]}" | median | awk '{ printf "%.1f", $1 / 1024 }')
    [ ${#loops[@]} -gt 0 ] && l=$(printf '%s\n' "${loops[@]}" | median)
    echo "| $label | $w | $m | $l |"
}

OURS=("$BIN" --bind "$BIND" --alpha 0.9 --seed 0 --report -o "$TMP/out.bvh")
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg), cores: $(nproc), runs: $RUNS (medians)"
echo
echo "| run | wall s | peak RSS MiB | retarget loop ms |"
echo "|---|---|---|---|"
measure "ours, demo (79 frames), all threads" "${OURS[@]}" "$SRC" "$EX"
measure "ours, demo, --threads 1" "${OURS[@]}" "$SRC" "$EX" --threads 1
if [ -n "${M2M_REF:-}" ] && [ -n "${M2M_PY:-}" ] && [ -e "$M2M_REF/run_M2M.py" ]; then
    REF="cd '$M2M_REF' && '$M2M_PY' run_M2M.py -e ./data/processed/Monkey/__Walk.bvh -d cpu --source ./data/processed/Flamingo/Flamingo_Walk.bvh --mapping_file configs/mappings_flamingo.json --output_dir '$TMP/ref' --sparse_retargeting --matching_alpha 0.9 -s 0"
    measure "reference, demo, as shipped" bash -c "$REF"
    measure "reference, demo, OMP_NUM_THREADS=1" env OMP_NUM_THREADS=1 bash -c "$REF"
else
    echo "| reference | skipped: set M2M_REF and M2M_PY | | |"
fi
echo
echo "Source length (one 61-frame example clip):"
echo
echo "| source frames | wall s | peak RSS MiB | retarget loop ms |"
echo "|---|---|---|---|"
for k in 1 8 32 64; do measure "$((79 * k))" "${OURS[@]}" "$TMP/src_x$k.bvh" "$EX"; done
echo
echo "Example clips (79-frame source; copies of the 61-frame clip):"
echo
echo "| example clips (frames) | wall s | peak RSS MiB | retarget loop ms |"
echo "|---|---|---|---|"
for n in 1 4 16; do measure "$n ($((61 * n)))" "${OURS[@]}" "$SRC" "$TMP/ex$n"; done
