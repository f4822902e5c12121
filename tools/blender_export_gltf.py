"""Imports a BVH into Blender and exports it as GLB with Blender's own glTF exporter.

    blender -b --factory-startup --python tools/blender_export_gltf.py -- IN.bvh OUT.glb

Made tests/fixtures/quadruped_blender34.glb (Debian's Blender 3.4.1, from the first 12 frames
of examples/data/quadruped.bvh): a glTF written by another program, with the rest rotations,
per-bone translation and scale keys and armature object that Blender exports, for the reader's
tests (tests/it/gltf_io.rs).
"""
import builtins
import sys

import bpy
import numpy as np

# Blender 3.4 on Python 3.11 opens BVH files with mode 'rU'; its glTF add-on uses `np.bool`,
# gone from numpy 1.24. Both are Blender/library incompatibilities, patched here.
_open = builtins.open
builtins.open = lambda f, mode="r", *a, **k: _open(f, mode.replace("U", ""), *a, **k)
if "bool" not in np.__dict__:
    np.bool = bool

src, out = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_anim.bvh(filepath=src, axis_forward="-Z", axis_up="Y", rotate_mode="NATIVE", update_scene_fps=True, update_scene_duration=True)
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_animations=True)
