#!/usr/bin/env python3
"""Dump reference forward-kinematics positions for tests/fk_reference.rs.

Runs the independent numpy checker `bvhfk.py` (not part of this project; by default looked up
at ../shared/tools next to the checkout) on each BVH file and prints, as one JSON object on
stdout, the world positions of a few frames of every file:

    {"files": [{"path": P, "joints": J, "names": [...], "frames": F, "height": H,
                "sampled": [f0, f1, ...], "positions": [[[x, y, z] * J] per sampled frame]},
               {"path": P, "error": "..."}]}

`height` is bvhfk's own scale (largest extent of frame 0's joint positions). Floats are printed
with Python's repr, so they read back to the same f64.

usage: fk_dump.py [--bvhfk DIR] [--frames SPEC] FILE.bvh [FILE.bvh ...]
  SPEC: "sample" (default: first, middle and last frame), "all", or comma-separated indices
        (negative indices count from the end; out-of-range ones are dropped).

Needs numpy (pip install numpy).
"""
import importlib.util
import json
import os
import sys


def load_bvhfk(directory):
    path = os.path.join(directory, "bvhfk.py")
    spec = importlib.util.spec_from_file_location("bvhfk", path)
    if spec is None or not os.path.isfile(path):
        raise SystemExit("fk_dump.py: bvhfk.py not found at %s" % path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def pick_frames(spec, count):
    if count == 0:
        return []
    if spec == "sample":
        wanted = [0, count // 2, count - 1]
    elif spec == "all":
        wanted = list(range(count))
    else:
        wanted = []
        for part in spec.split(","):
            k = int(part)
            if k < 0:
                k += count
            if 0 <= k < count:
                wanted.append(k)
    out = []
    for k in wanted:
        if k not in out:
            out.append(k)
    return out


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    bvhfk_dir = os.path.normpath(os.path.join(here, "..", "..", "..", "shared", "tools"))
    spec = "sample"
    files = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--bvhfk":
            bvhfk_dir = argv[i + 1]
            i += 2
        elif a == "--frames":
            spec = argv[i + 1]
            i += 2
        else:
            files.append(a)
            i += 1
    if not files:
        raise SystemExit(__doc__)
    bvhfk = load_bvhfk(bvhfk_dir)
    results = []
    for path in files:
        try:
            names, world, _frame_time = bvhfk.fk(path)
        except Exception as e:  # report, let the caller decide
            results.append({"path": path, "error": "%s: %s" % (type(e).__name__, e)})
            continue
        count = int(world.shape[0])
        frames = pick_frames(spec, count)
        results.append({
            "path": path,
            "joints": len(names),
            "names": list(names),
            "frames": count,
            "height": bvhfk.height(world) if count else None,
            "sampled": frames,
            "positions": [world[f].tolist() for f in frames],
        })
    json.dump({"files": results}, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main(sys.argv[1:])
