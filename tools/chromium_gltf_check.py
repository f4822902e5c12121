#!/usr/bin/env python3
"""Loads glTF files in headless Chromium, as a web viewer would, and checks what it sees.

    python3 tools/chromium_gltf_check.py walk.glb=walk.bvh [more.glb=more.bvh ...] [--shots DIR]

Each FILE.glb (or .gltf) is embedded in a page with tools/gltf_check.js, a small glTF reader
written for this check (no three.js): it parses the file in the browser, plays the first
animation, poses the skin and skins the stick mesh on the CPU. Compared, per file:

* every skin joint's world position at frames 0, 1, a third, half and last (key k at time
  k * frame time) against the independent FK of REFERENCE.bvh (../shared/tools/bvhfk.py),
  as the largest distance over the skeleton's height (as tools/blender_import_check.py does);
* how far the skinned body strays from the bones it wraps (largest vertex distance to the
  nearest bone touching its joint, over the longest such bone; our sticks are 0.08 of a bone
  thick).

With --shots DIR, a PNG of the page (the body at the middle frame) is written per file: look
at it. Prints one JSON line `CHROMIUMCHECK [...]`; exit 1 if a file does not load, a joint is
missing, the joints are off by more than 1e-4 of the height or the body by more than 0.1 of a
bone.

Needs `chromium` (Debian: apt-get install chromium) and numpy.
"""
import base64
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "shared", "tools"))
import bvhfk  # noqa: E402

BROWSER = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--virtual-time-budget=60000"]


def page(path, times, label):
    data = base64.b64encode(open(path, "rb").read()).decode()
    script = open(os.path.join(HERE, "gltf_check.js")).read()
    return (
        "<!doctype html><meta charset=utf-8><title>glTF check</title>"
        "<canvas id=view width=800 height=560></canvas><pre id=result></pre>"
        f"<script>const GLTF_B64 = {json.dumps(data)}; const TIMES = {json.dumps(times)};"
        f" const LABEL = {json.dumps(label)};</script><script>{script}</script>"
    )


def browse(html_path, shot=None):
    url = "file://" + html_path
    if shot:
        subprocess.run([BROWSER, *FLAGS, "--window-size=800,600", f"--screenshot={shot}", url],
                       capture_output=True, timeout=300, check=True)
    dom = subprocess.run([BROWSER, *FLAGS, "--dump-dom", url], capture_output=True, timeout=300, check=True)
    m = re.search(r'<pre id="result">(.*?)</pre>', dom.stdout.decode(), re.S)
    if not m:
        raise RuntimeError("the page wrote no result")
    text = m.group(1).replace("&quot;", '"').replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
    return json.loads(text)


def check(path, reference, shots, work):
    names, positions, frame_time = bvhfk.fk(reference)
    positions = np.asarray(positions)
    frames = positions.shape[0]
    keys = sorted({0, 1, frames // 3, frames // 2, frames - 1} & set(range(frames)))
    times = [float(np.float32(k * frame_time)) for k in keys]
    html = os.path.join(work, "page.html")
    open(html, "w").write(page(path, times, os.path.basename(path)))
    shot = os.path.join(shots, os.path.splitext(os.path.basename(path))[0] + ".png") if shots else None
    seen = browse(html, shot)
    if not seen.get("ok"):
        return {"file": path, "error": seen.get("error", "not loaded")}
    index = {n: i for i, n in enumerate(seen["joints"])}
    found = [n for n in names if n in index]
    got = np.asarray(seen["positions"])
    worst = 0.0
    for row, k in enumerate(keys):
        for j, n in enumerate(names):
            if n in index:
                worst = max(worst, float(np.linalg.norm(got[row, index[n]] - positions[k, j])))
    height = float(np.ptp(positions[0, :, 1])) or 1.0
    return {"file": path, "reference": reference, "joints": len(names), "joints_found": len(found),
            "frames_checked": keys, "animation": seen["animation"],
            "mesh_triangles": seen.get("mesh_triangles", 0),
            "max_joint_error_over_height": worst / height,
            "max_mesh_off_bone": seen["mesh_off_bone"], "shot": shot}


def main():
    args = sys.argv[1:]
    shots = None
    if "--shots" in args:
        i = args.index("--shots")
        shots = os.path.abspath(args[i + 1])
        del args[i:i + 2]
        os.makedirs(shots, exist_ok=True)
    if not args or any("=" not in a for a in args):
        sys.exit("usage: chromium_gltf_check.py FILE.glb=REFERENCE.bvh ... [--shots DIR]")
    if not BROWSER:
        sys.exit("chromium_gltf_check: no chromium on PATH (apt-get install chromium)")
    results, bad = [], False
    with tempfile.TemporaryDirectory() as work:
        for a in args:
            path, reference = (os.path.abspath(x) for x in a.split("=", 1))
            try:
                r = check(path, reference, shots, work)
            except Exception as e:  # report every file, then fail
                r = {"file": path, "error": str(e)}
            bad |= "error" in r or r["joints_found"] != r["joints"] or r["max_joint_error_over_height"] > 1e-4 \
                or r["max_mesh_off_bone"] > 0.1 or r["mesh_triangles"] == 0
            results.append(r)
    print("CHROMIUMCHECK " + json.dumps(results))
    sys.exit(1 if bad else 0)


main()
