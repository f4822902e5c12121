#!/usr/bin/env bash
# Our GLB as the programs users open it in see it: every corpus BVH, every bundled creature and
# the first clip of every zoo folder, converted with `mo-edit convert FILE.bvh -o FILE.glb`, then
#   * imported by Blender 3.4's glTF add-on (tools/blender_import_check.py): bone heads against
#     the independent FK of the source BVH, at frames 0, 1, a third, half and last;
#   * loaded by headless Chromium (tools/chromium_gltf_check.py, a small glTF reader of ours in
#     the page): joint positions at the same frames, and the skinned stick body against its bones.
#
#   cargo build --release && benches/gltf_viewers.sh [ZOO_DIR] [SHOTS_DIR]
#
# ZOO_DIR defaults to $MENAGERIE_ZOO; without it the zoo is skipped with a message (make one
# with `cargo run --release --example zoo -- --training DIR`). The corpus needs ../shared/data
# (or $SHARED_DATA) and is skipped with a message when absent. Needs blender (with Debian's
# python3-numpy) and chromium. Prints the worst error per source and exits 1 if a check fails.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${CARGO_TARGET_DIR:-$ROOT/target}/release
DATA=${SHARED_DATA:-$ROOT/../shared/data}
ZOO=${1:-${MENAGERIE_ZOO:-}}
SHOTS=${2:-}
[ -x "$BIN/mo-edit" ] || { echo "gltf_viewers: build first: cargo build --release" >&2; exit 1; }
for tool in blender chromium; do
    command -v $tool >/dev/null || { echo "gltf_viewers: no $tool (apt-get install blender python3-numpy chromium)" >&2; exit 1; }
done
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

declare -a PAIRS=()
add() { # label file.bvh
    local glb="$OUT/$1.glb"
    "$BIN/mo-edit" convert "$2" -o "$glb"
    PAIRS+=("$glb=$2")
}
for f in "$ROOT"/examples/data/*.bvh; do add "bundled_$(basename "$f" .bvh)" "$f"; done
if [ -d "$DATA/bvh" ]; then
    while IFS= read -r f; do
        add "corpus_$(echo "${f#"$DATA"/bvh/}" | tr '/ ' '__' | sed 's/\.bvh$//I')" "$f"
    done < <(find "$DATA/bvh" -iname '*.bvh' | sort)
else
    echo "gltf_viewers: no corpus at $DATA/bvh, skipped" >&2
fi
if [ -n "$ZOO" ] && [ -d "$ZOO" ]; then
    for d in "$ZOO"/*/; do
        f=$(find "$d" -maxdepth 1 -name '*.bvh' ! -name '*tpose*' | sort | head -1)
        [ -n "$f" ] && add "zoo_$(basename "$d")" "$f"
    done
else
    echo "gltf_viewers: no zoo (give ZOO_DIR or MENAGERIE_ZOO), skipped" >&2
fi
echo "gltf_viewers: ${#PAIRS[@]} files" >&2

status=0
blender -b --factory-startup --python "$ROOT/tools/blender_import_check.py" -- "${PAIRS[@]}" 2>/dev/null \
    | grep '^BLENDERCHECK ' | sed 's/^BLENDERCHECK //' >"$OUT/blender.json" || status=1
python3 "$ROOT/tools/chromium_gltf_check.py" "${PAIRS[@]}" ${SHOTS:+--shots "$SHOTS"} \
    | grep '^CHROMIUMCHECK ' | sed 's/^CHROMIUMCHECK //' >"$OUT/chromium.json" || status=1

python3 - "$OUT/blender.json" "$OUT/chromium.json" <<'EOF'
import json, os, sys
def group(r):
    return os.path.basename(r["file"]).split("_")[0]
for label, path, key in [("Blender 3.4 import", sys.argv[1], "max_head_error_over_height"),
                         ("Chromium", sys.argv[2], "max_joint_error_over_height")]:
    rows = json.load(open(path)) if os.path.getsize(path) else []
    print(f"{label}: {len(rows)} files")
    errors = [r for r in rows if "error" in r]
    for r in errors:
        print(f"  FAILED {r['file']}: {r['error']}")
    for g in sorted({group(r) for r in rows}):
        ok = [r for r in rows if group(r) == g and "error" not in r]
        if not ok:
            continue
        worst = max(ok, key=lambda r: r[key])
        missing = sum(r["joints"] - r.get("joints_found", r.get("bones", r["joints"])) for r in ok)
        line = f"  {g}: {len(ok)} files, worst joint error {worst[key]:.1e} of height ({os.path.basename(worst['file'])}), joints missing {missing}"
        if "max_mesh_off_bone" in worst:
            line += f", body off its bones at most {max(r['max_mesh_off_bone'] for r in ok):.3f} of a bone"
        print(line)
EOF
exit $status
