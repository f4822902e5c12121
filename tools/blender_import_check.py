"""Imports BVH and glTF files into Blender and checks what it built against an independent FK.

    blender -b --factory-startup --python tools/blender_import_check.py -- out_0.bvh out_1.bvh
    blender -b --factory-startup --python tools/blender_import_check.py -- walk.glb=walk.bvh

A glTF/GLB file is given as FILE.glb=REFERENCE.bvh: it is imported with Blender's glTF add-on
(`import_scene.gltf`, Debian needs `python3-numpy` for it) and its bone heads are compared with
the FK of the BVH it was made from (or one the tools wrote back from it), at several frames.
The scene's frame rate is set to the reference's and key k is looked at at its own time.

Prints one JSON line `BLENDERCHECK [...]`: per file the bones Blender made, the joints and
frames of the file, the imported action's frame range, and the largest distance between
Blender's bone heads and the joint positions of ../shared/tools/bvhfk.py (at the first,
middle and last frame, over the skeleton's height). Exit code 1 if a file does not import or
disagrees by more than 1e-4 of its height.

bvhfk needs numpy: Blender's own Python may lack it; set MENAGERIE_PYTHONPATH to a
site-packages folder that has numpy for the same Python version (e.g. a pyenv one).
"""
import builtins
import json
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "shared", "tools"))
if os.environ.get("MENAGERIE_PYTHONPATH"):
    sys.path.append(os.environ["MENAGERIE_PYTHONPATH"])
import bvhfk  # noqa: E402
import numpy as np  # noqa: E402

# Debian's Blender 3.4 importer opens files with mode 'rU', which its Python 3.11 rejects;
# drop the 'U' (a Blender/Python incompatibility, unrelated to the files being checked).
_open = builtins.open
builtins.open = lambda f, mode="r", *a, **k: _open(f, mode.replace("U", ""), *a, **k)
# Its glTF add-on still uses `np.bool`, which numpy 1.24 (Debian 12's) removed: put it back.
if "bool" not in np.__dict__:
    np.bool = bool


def head_error(arm, names, positions):
    """The largest distance between a bone's head and the joint of its name, at this frame."""
    worst = 0.0
    for i, name in enumerate(names):
        bone = arm.pose.bones.get(name)
        if bone is None:
            continue
        h = arm.matrix_world @ bone.head
        # Both importers turn the file's Y-up into Blender's Z-up: (x, y, z) -> (x, -z, y).
        worst = max(worst, float(np.linalg.norm(np.array([h.x, h.z, -h.y]) - positions[i])))
    return worst


def check(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_anim.bvh(filepath=path, axis_forward="-Z", axis_up="Y", rotate_mode="NATIVE")
    arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"][0]
    names, positions, _ = bvhfk.fk(path)
    positions = np.asarray(positions)
    frames = positions.shape[0]
    start = int(arm.animation_data.action.frame_range[0])
    worst = 0.0
    for k in sorted({0, frames // 2, frames - 1}):
        bpy.context.scene.frame_set(start + k)
        worst = max(worst, head_error(arm, names, positions[k]))
    height = float(np.ptp(positions[0, :, 1])) or 1.0
    return {"file": path, "bones": len(arm.data.bones), "joints": len(names), "frames": frames,
            "action_frames": list(arm.animation_data.action.frame_range),
            "max_head_error_over_height": worst / height}


def check_gltf(path, reference):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    names, positions, frame_time = bvhfk.fk(reference)
    positions = np.asarray(positions)
    frames = positions.shape[0]
    # Blender keys a glTF time t at frame t * fps (the scene's whole fps, fps_base ignored):
    # look at key k there, with a subframe when the frame time is not 1/fps exactly.
    fps = max(1, round(1.0 / frame_time))
    bpy.context.scene.render.fps = fps
    bpy.ops.import_scene.gltf(filepath=path)
    arm = [o for o in bpy.context.scene.objects if o.type == "ARMATURE"][0]
    action = arm.animation_data.action if arm.animation_data else None
    start = round(action.frame_range[0]) if action else 0
    worst = 0.0
    for k in sorted({0, 1, frames // 3, frames // 2, frames - 1}):
        if k >= frames:
            continue
        at = start + float(np.float32(k * frame_time)) * fps
        bpy.context.scene.frame_set(int(at), subframe=at - int(at))
        worst = max(worst, head_error(arm, names, positions[k]))
    height = float(np.ptp(positions[0, :, 1])) or 1.0
    joints_found = sum(1 for n in names if arm.pose.bones.get(n) is not None)
    return {"file": path, "reference": reference, "bones": len(arm.data.bones), "joints": len(names),
            "joints_found": joints_found, "frames": frames,
            "action_frames": list(action.frame_range) if action else None,
            "max_head_error_over_height": worst / height}


def main():
    files = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    results, bad = [], False
    for f in files:
        try:
            if "=" in f:
                r = check_gltf(*f.split("=", 1))
            else:
                r = check(f)
        except Exception as e:  # report every file, then fail
            r, bad = {"file": f, "error": str(e)}, True
        else:
            found = r.get("joints_found", r["bones"])
            bad |= found != r["joints"] or r["max_head_error_over_height"] > 1e-4
        results.append(r)
    print("BLENDERCHECK " + json.dumps(results))
    sys.exit(1 if bad or not files else 0)


main()
