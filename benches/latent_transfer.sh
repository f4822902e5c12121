#!/usr/bin/env bash
# Zero-shot retargeting through the latent model (SATA) side by side with Motion2Motion on the
# same pairs: human (LAFAN1 walk, held out of the corpus model) -> dog, dog -> human, flamingo ->
# chicken. Scores both with `mo-metrics transfer` (frequency alignment, contact consistency and
# motion ratio, over the pairs of an automatic binding, the same pairs for both methods) and renders PNG
# sheets of source and results to look at.
#
#   cargo build --release && benches/latent_transfer.sh [MODEL_DIR ...]   # default: built-in
#
# LOOK_DIR=/tmp/look keeps the pictures and results (default: a temporary directory). Skips
# (exit 0) with a message when ../shared/data (or $SHARED_DATA) is absent.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$ROOT/target/release
DATA=${SHARED_DATA:-$ROOT/../shared/data}/bvh
HUMAN=$DATA/lafan1/walk4_subject1.bvh
HUMAN_EX=$DATA/cmu_bvh11/131_01.bvh
DOG=$DATA/dog_mann/Dog/D1_010_KAN01_002.bvh
DOG_EX=$DATA/dog_mann/Dog/D1_001_KAN01_001.bvh
FLAMINGO=$DATA/truebones_motion2motion/Flamingo/Flamingo_Walk.bvh
CHICKEN=$DATA/truebones_anytop/Chicken/Chicken_Walk.bvh
CHICKEN_EX=$DATA/truebones_anytop/Chicken/Chicken_IdlePecking.bvh
for f in "$HUMAN" "$HUMAN_EX" "$DOG" "$DOG_EX" "$FLAMINGO" "$CHICKEN" "$CHICKEN_EX"; do
    if [ ! -e "$f" ]; then echo "latent_transfer: skipped: $f is absent (shared data not available)"; exit 0; fi
done
for b in mo-retarget mo-metrics mo-render; do
    [ -x "$BIN/$b" ] || { echo "latent_transfer: build first: cargo build --release" >&2; exit 1; }
done
OUT=${LOOK_DIR:-$(mktemp -d)}
mkdir -p "$OUT"
[ -n "${LOOK_DIR:-}" ] || trap 'rm -rf "$OUT"' EXIT
MODELS=("$@")
[ ${#MODELS[@]} -gt 0 ] || MODELS=(builtin)

# 300 frames of a BVH from frame $3 (long captures make slow, unreadable sheets).
frames_from() {
    awk -v n=300 -v s="$3" '/^MOTION/ { m = 1; print; next } !m { print; next }
        /^Frames:/ { next } /^Frame Time/ { ft = $0; next }
        NF > 0 { if (j++ >= s && k < n) d[k++] = $0 } END { print "Frames: " k; print ft; for (i = 0; i < k; i++) print d[i] }' "$1" >"$2"
}
# LAFAN1 captures open with a T-pose: the walk starts after about 4 s.
frames_from "$HUMAN" "$OUT/human.bvh" 150
frames_from "$DOG" "$OUT/dog.bvh" 0
cp "$FLAMINGO" "$OUT/flamingo.bvh"

echo "| pair | method | model | frequency alignment | contact consistency | motion ratio | seconds |"
echo "|---|---|---|---|---|---|---|"
run_pair() { # name source target examples...
    local name=$1 src=$2 tgt=$3
    shift 3
    "$BIN/mo-retarget" "$src" "$tgt" --bind auto --emit-binding -q >"$OUT/$name.binding.json"
    local t0 t1
    t0=$(date +%s.%N)
    "$BIN/mo-retarget" "$src" "$@" --bind auto -q -o "$OUT/$name.m2m.bvh"
    t1=$(date +%s.%N)
    report "$name" m2m - "$src" "$OUT/$name.m2m.bvh" "$(echo "$t1 - $t0" | bc)"
    for model in "${MODELS[@]}"; do
        local tag flag=()
        tag=$(basename "$model")
        [ "$model" = builtin ] || flag=(--model "$model")
        t0=$(date +%s.%N)
        "$BIN/mo-retarget" --method latent "$src" --to "$tgt" "${flag[@]}" -q -o "$OUT/$name.latent-$tag.bvh"
        t1=$(date +%s.%N)
        report "$name" latent "$tag" "$src" "$OUT/$name.latent-$tag.bvh" "$(echo "$t1 - $t0" | bc)"
    done
    "$BIN/mo-render" "$src" "$OUT/$name".*.bvh --sheet "$OUT/$name.png" --frames 0:120 -q
}
report() { # name method model source result seconds
    "$BIN/mo-metrics" transfer --source "$4" --result "$5" --binding "$OUT/$1.binding.json" -q >"$OUT/$1.$2-$3.metrics.json"
    python3 - "$OUT/$1.$2-$3.metrics.json" "$1" "$2" "$3" "$6" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
row = r["results"][0] if "results" in r else r["per_result"][0]
f = row["frequency_alignment"]; c = row["contact_consistency"]; m = row["motion_ratio"]
def num(v):
    v = v.get("value", v.get("mean", v)) if isinstance(v, dict) else v
    return f"{v:.3f}" if isinstance(v, float) else v
print(f"| {sys.argv[2]} | {sys.argv[3]} | {sys.argv[4]} | {num(f)} | {num(c)} | {num(m)} | {float(sys.argv[5]):.2f} |")
PY
}
run_pair human_to_dog "$OUT/human.bvh" "$DOG_EX" "$DOG_EX"
run_pair dog_to_human "$OUT/dog.bvh" "$HUMAN_EX" "$HUMAN_EX"
run_pair flamingo_to_chicken "$OUT/flamingo.bvh" "$CHICKEN" "$CHICKEN" "$CHICKEN_EX"
echo
echo "pictures: $OUT/*.png"
