#!/usr/bin/env bash
# Whole-process speed and peak memory of example-based generation, `mo-sample --examples`
# (GenMM), next to the diffusion sampler (`mo-sample` with the built-in model) on the same
# skeleton: two 200-frame samples from one clip, medians of RUNS runs.
#
#   cargo build --release --bin mo-sample && benches/genmm_cli.sh [RUNS]
#
# Bundled creatures always; corpus clips from ../shared/data (or $SHARED_DATA) when present
# (rows say "absent" otherwise). Nothing is written outside a temporary directory.
set -euo pipefail
RUNS=${1:-5}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${MO_SAMPLE:-${CARGO_TARGET_DIR:-$ROOT/target}/release/mo-sample}
DATA=${SHARED_DATA:-$ROOT/../shared/data}/bvh
[ -x "$BIN" ] || { echo "genmm_cli: build first: cargo build --release --bin mo-sample" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "genmm_cli: needs /usr/bin/time (GNU time) for peak RSS" >&2; exit 1; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# measure LABEL CLIP CMD...: median wall seconds and peak RSS (MiB) of RUNS runs of CMD.
measure() {
    local label=$1 clip=$2; shift 2
    if [ ! -e "$clip" ]; then echo "| $label | absent | | |"; return; fi
    local joints frames walls=() rss=()
    joints=$(grep -cE '^\s*(ROOT|JOINT)' "$clip")
    frames=$(sed -n 's/^Frames:\s*//p' "$clip" | tr -d '\r')
    for _ in $(seq 1 "$RUNS"); do
        /usr/bin/time -f "%e %M" -o "$TMP/time" "$@" >/dev/null 2>"$TMP/err" || { echo "| $label | failed: $(tail -1 "$TMP/err") | | |"; return; }
        read -r w m <"$TMP/time"
        walls+=("$w"); rss+=("$m")
    done
    local w m
    w=$(printf '%s\n' "${walls[@]}" | median)
    m=$(printf '%s\n' "${rss[@]}" | median | awk '{ printf "%.0f", $1 / 1024 }')
    echo "| $label | $joints | $frames | $w | $m |"
}

genmm() { measure "$1" "$2" "$BIN" --examples "$2" -n 2 --frames 200 --seed 0 -q --bvh "$TMP/g_{i}.bvh"; }

echo "load average: $(cut -d' ' -f1-3 /proc/loadavg), cores: $(nproc), runs: $RUNS (medians)"
echo
echo "| run (2 x 200 frames, one clip) | joints | clip frames | wall s | peak RSS MiB |"
echo "|---|---|---|---|---|"
genmm "--examples, bundled crab" "$ROOT/examples/data/crab.bvh"
genmm "--examples, bundled dragon" "$ROOT/examples/data/dragon.bvh"
genmm "--examples, corpus chicken walk" "$DATA/truebones_anytop/Chicken/Chicken_Walk.bvh"
genmm "--examples, corpus crab dance" "$DATA/ganimator/Crab/Crab-dance-long.bvh"
genmm "--examples, corpus human walk (60 fps)" "$DATA/ganimator/Joe/Walk-In-Circle.bvh"
genmm "--examples, corpus monkey walk" "$DATA/truebones_motion2motion/Monkey/__Walk.bvh"
measure "--examples, bundled dragon, --threads 1" "$ROOT/examples/data/dragon.bvh" \
    "$BIN" --examples "$ROOT/examples/data/dragon.bvh" -n 2 --frames 200 --seed 0 -q --threads 1 --bvh "$TMP/g_{i}.bvh"
measure "diffusion (built-in model, 10 DDIM steps), bundled dragon" "$ROOT/examples/data/dragon.bvh" \
    "$BIN" "$ROOT/examples/data/dragon.bvh" -n 2 --frames 200 --seed 0 -q --bvh "$TMP/d_{i}.bvh"
