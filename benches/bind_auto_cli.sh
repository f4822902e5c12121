#!/usr/bin/env bash
# `mo-retarget --bind auto` (every confident pair, the default; and limited to the paper's rate
# 0.061) next to a hand binding, at alpha 0.85 and 0.9, 3 seeds each. Frequency alignment and
# contact consistency from `mo-metrics transfer`, always over the pairs of the hand binding (or,
# where there is none, of the 0.061 binding), so every row is scored on the same joints.
#
#   cargo build --release && benches/bind_auto_cli.sh
#
# Pairs: Flamingo -> Monkey with the reference's binding, Monkey -> Flamingo with it swapped,
# five more corpus pairs with our hand bindings (benches/bindings/*.hand.json: joint names only,
# written by reading the skeletons) -- all need ../shared/data, or $SHARED_DATA, and are
# skipped with a message when absent -- and the zoo pairs of docs/retarget-results.md.
#
# After the table, every automatic binding is checked for a pair across side (left with right)
# or limb class (front with hind) by benches/binding_check.py, from skel-info's sides and the
# joint names (independent of the engine's own reasoning).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${CARGO_TARGET_DIR:-$ROOT/target}/release
DATA=${SHARED_DATA:-$ROOT/../shared/data}
for b in mo-retarget mo-metrics skel-info; do
    [ -x "$BIN/$b" ] || { echo "bind_auto_cli: build first: cargo build --release" >&2; exit 1; }
done
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
EX=$ROOT/examples/data

CHECKS=$OUT/checks.txt
: >"$CHECKS"
check() { # label source target bind-arg...: is any auto pair across side or limb class?
    local label=$1 src=$2 tgt=$3
    shift 3
    "$BIN/mo-retarget" "$src" "$tgt" "$@" --emit-binding -q >"$OUT/check.json"
    "$BIN/skel-info" "$src" --format json >"$OUT/check_s.json"
    "$BIN/skel-info" "$tgt" --format json >"$OUT/check_t.json"
    echo "$label: $(python3 "$ROOT/benches/binding_check.py" "$OUT/check.json" "$OUT/check_s.json" "$OUT/check_t.json")" >>"$CHECKS"
}

mean() { python3 -c "import json,sys; r=json.load(sys.stdin)['results']; f=[x['frequency_alignment']['value'] for x in r]; c=[x['contact_consistency']['value'] for x in r]; print('%.4f | %.4f' % (sum(f)/len(f), sum(c)/len(c)))"; }

row() { # label source target score-binding bind-arg...
    local label=$1 src=$2 tgt=$3 score=$4
    shift 4
    local pairs
    [ "${1:-}" = --bind ] && [ "${2:-}" = auto ] && check "$label" "$src" "$tgt" "$@"
    pairs=$("$BIN/mo-retarget" "$src" "$tgt" "$@" --emit-binding -q | python3 -c "import json,sys; print(len(json.load(sys.stdin)['mapping']))")
    for alpha in 0.85 0.9; do
        for seed in 0 1 2; do
            "$BIN/mo-retarget" "$src" "$tgt" "$@" --alpha $alpha --seed $seed -q -o "$OUT/r_$seed.bvh"
        done
        echo "| $label | $pairs | $alpha | $("$BIN/mo-metrics" transfer --source "$src" --result "$OUT"/r_0.bvh "$OUT"/r_1.bvh "$OUT"/r_2.bvh --binding "$score" --examples "$tgt" 2>/dev/null | mean) |"
    done
}

echo "| pair, binding | pairs | alpha | FA (mean of 3 seeds) | CC |"
echo "|---|---|---|---|---|"
FL=$DATA/bvh/truebones_motion2motion/Flamingo/Flamingo_Walk.bvh
MK=$DATA/bvh/truebones_motion2motion/Monkey/__Walk.bvh
HAND=$DATA/bindings/flamingo_to_monkey.m2m.json
if [ -e "$FL" ] && [ -e "$MK" ] && [ -e "$HAND" ]; then
    python3 -c "import json,sys; b=json.load(open(sys.argv[1])); b['mapping']=[{'source':p['target'],'target':p['source']} for p in b['mapping']]; json.dump(b,open(sys.argv[2],'w'))" "$HAND" "$OUT/swapped.json"
    row "Flamingo -> Monkey, hand (reference)" "$FL" "$MK" "$HAND" --bind "$HAND"
    row "Flamingo -> Monkey, auto" "$FL" "$MK" "$HAND" --bind auto
    row "Flamingo -> Monkey, auto --bind-rate 0.061" "$FL" "$MK" "$HAND" --bind auto --bind-rate 0.061
    row "Monkey -> Flamingo, hand (swapped)" "$MK" "$FL" "$OUT/swapped.json" --bind "$OUT/swapped.json"
    row "Monkey -> Flamingo, auto" "$MK" "$FL" "$OUT/swapped.json" --bind auto
    row "Monkey -> Flamingo, auto --bind-rate 0.061" "$MK" "$FL" "$OUT/swapped.json" --bind auto --bind-rate 0.061
else
    echo "bind_auto_cli: corpus rows skipped: $FL, $MK or $HAND is absent"
fi
B=$ROOT/benches/bindings
CORPUS=(
    # label | source | target (examples) | hand binding
    "Monkey -> Elephant (Truebones quadrupeds)|truebones_motion2motion/Monkey/__Walk.bvh|ganimator/Elephant/idle1.bvh|monkey_to_elephant.hand.json"
    "Dog -> Crab (dog_mann, ganimator)|dog_mann/Dog/D1_007_KAN01_001.bvh|ganimator/Crab/Crab-dance-long.bvh|dog_to_crab.hand.json"
    "LAFAN1 -> Dog (human -> dog)|lafan1/walk4_subject1.bvh|dog_mann/Dog/D1_007_KAN01_001.bvh|lafan1_to_dog.hand.json"
    "CMU -> Xia (human rigs)|cmu_bvh11/131_01.bvh|xia_dme/neutral_01_000.bvh|cmu_to_xia.hand.json"
    "Chicken -> Monkey (bird -> quadruped)|truebones_anytop/Chicken/Chicken_Walk.bvh|truebones_motion2motion/Monkey/__Walk.bvh|chicken_to_monkey.hand.json"
)
for entry in "${CORPUS[@]}"; do
    IFS='|' read -r label src tgt hand <<<"$entry"
    src=$DATA/bvh/$src tgt=$DATA/bvh/$tgt hand=$B/$hand
    if [ ! -e "$src" ] || [ ! -e "$tgt" ]; then
        echo "bind_auto_cli: $label skipped: $src or $tgt is absent"
        continue
    fi
    row "$label, hand" "$src" "$tgt" "$hand" --bind "$hand"
    row "$label, auto" "$src" "$tgt" "$hand" --bind auto
    row "$label, auto --bind-rate 0.061" "$src" "$tgt" "$hand" --bind auto --bind-rate 0.061
done
for pair in "biped quadruped" "quadruped dragon" "spider crab"; do
    set -- $pair
    "$BIN/mo-retarget" "$EX/$1.bvh" "$EX/$2.bvh" --bind auto --bind-rate 0.061 --emit-binding -q >"$OUT/sparse.json"
    cp "$OUT/sparse.json" "$OUT/score_$1.json"
    row "$1 -> $2, auto" "$EX/$1.bvh" "$EX/$2.bvh" "$OUT/score_$1.json" --bind auto
    row "$1 -> $2, auto --bind-rate 0.061" "$EX/$1.bvh" "$EX/$2.bvh" "$OUT/score_$1.json" --bind auto --bind-rate 0.061
done
echo
echo "Automatic bindings across side or limb class (benches/binding_check.py):"
echo
sed 's/^/* /' "$CHECKS"
