#!/usr/bin/env python3
"""Generation metrics of a diffusion model per skeleton, against baselines, as markdown tables.

For each skeleton folder (one skeleton's clips, e.g. a synthetic-zoo folder written by
`cargo run --release --example zoo -- --training DIR`), this samples N motions with each model
(`mo-sample`, the folder's first clip as the skeleton) and compares them with the folder's clips
(`mo-metrics generation`). Baselines: the clips themselves (`gt`), and whatever models are named
(e.g. an untrained checkpoint), or 'examples' for example-based generation from the folder's
own clips (`mo-sample --examples FOLDER`, no model). With --steps-table it also measures one
skeleton's quality and wall time against sampling steps.

    tools/eval_generation.py --bin target/release --model zoo=models/zoo-small \\
        --model untrained=/tmp/untrained --model genmm=examples \\
        --skeletons /work/zoo/quadruped_v0 /work/zoo/dragon_v7

Only our binaries are run; numbers are printed, nothing is written outside a temp dir.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

METRICS = [
    ("energy_ratio", "energy ratio"),
    ("nearest_pose", "nearest pose"),
    ("calibrated_coverage", "cal. coverage %"),
    ("duty_factor", "duty"),
    ("mixed_contact", "mixed contact"),
    ("alternation", "alternation"),
    ("footfall_error", "footfall"),
    ("swing", "swing"),
    ("coverage", "coverage %"),
    ("local_diversity", "local div"),
    ("inter_diversity", "inter div"),
    ("intra_diversity_diff", "intra-div diff"),
]
# mo-metrics physics, normalised by skeleton size (means over files).
PHYSICS = [
    ("foot_skating", "skate /s"),
    ("jitter", "jerk /s^3"),
    ("ground_penetration", "penetration"),
    ("floating", "floating"),
]


def run(cmd, stdout=None, input=None):
    res = subprocess.run(cmd, stdout=stdout or subprocess.PIPE, stderr=subprocess.PIPE, input=input)
    if res.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {res.stderr.decode().strip()}")
    return res.stdout


def clips(folder):
    return sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".bvh"))


def metrics(bindir, folder, generated, skeleton):
    cmd = [f"{bindir}/mo-metrics", "generation", "--gt", folder, "--gen", generated]
    if generated.endswith(".npy"):
        cmd += ["--skeleton", skeleton]
    full = json.loads(run(cmd))
    report = full["report"]
    movement = full["movement"]
    out = {k: movement["samples"][k] if k in movement["samples"] else report[k]["mean"] for k, _ in METRICS}
    out["baselines"] = dict(movement["baselines"])
    # Which clips' windows are covered (the clip file names, then each one's percent).
    names = [os.path.basename(c) for c in movement.get("clips", [])]
    out["by_clip"] = list(zip(names, movement["samples"].get("calibrated_coverage_by_clip", [])))
    # The footfall error of feet phased at random: a baseline row of its own.
    out["baselines"]["random_phases"] = {"footfall_error": movement.get("footfall_chance")}
    files = clips(generated) if os.path.isdir(generated) else []
    if files:
        phys = json.loads(run([f"{bindir}/mo-metrics", "physics"] + files))["files"]
        for k, _ in PHYSICS:
            values = [f[k]["normalised"] for f in phys if "normalised" in f[k]]  # fish have no feet
            if values:
                out[k] = sum(values) / len(values)
                out[k + "_range"] = (min(values), max(values))
    return out


def cells(m, ranges=False):
    def phys(k):
        if k not in m:
            return "-"
        if ranges and k + "_range" in m:
            lo, hi = m[k + "_range"]
            return f"{m[k]:.3f} ({lo:.3f}-{hi:.3f})"
        return f"{m[k]:.3f}"
    return [num(m.get(k), k) for k, _ in METRICS] + [phys(k) for k, _ in PHYSICS]


def num(v, key=""):
    # Nearest pose is judged against bars of 0.012 and 0.015 of height: a third decimal hides
    # which side of the bar a value falls on.
    digits = 4 if key == "nearest_pose" else 3
    return "-" if v is None else f"{v:.{digits}f}"


def sample(bindir, model, folder, skeleton, out, n, frames, steps, sampler, seed):
    """Samples as BVH files in the new folder `out` (physics needs BVH); returns wall seconds."""
    os.makedirs(out)
    # A model spec is a directory, 'builtin' or 'examples', and optionally more mo-sample
    # options after it; its own --steps / --sampler win over the table-wide ones.
    where, *extra = model.split()
    # '--document' (ours, not mo-sample's): give the skeleton as `skel-info SKELETON | mo-sample`,
    # the README's pipe, whose document carries statistics measured on the clip.
    document = "--document" in extra
    extra = [e for e in extra if e != "--document"]
    common = ["-n", str(n), "--frames", str(frames), "--seed", str(seed), "-q", "--bvh", os.path.join(out, "sample_{i}.bvh")]
    if where == "examples":
        cmd = [f"{bindir}/mo-sample", "--examples", folder] + common
    else:
        cmd = [f"{bindir}/mo-sample"] + ([] if document else [skeleton]) + common
        if "--steps" not in extra:
            cmd += ["--steps", str(steps)]
        if "--sampler" not in extra:
            cmd += ["--sampler", sampler]
        if where != "builtin":
            cmd += ["--model", where]
    cmd += extra
    t = time.monotonic()
    run(cmd, input=run([f"{bindir}/skel-info", skeleton]) if document else None)
    return time.monotonic() - t


def row(cells):
    return "| " + " | ".join(cells) + " |"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/release")
    ap.add_argument("--model", action="append", default=[], metavar="NAME=DIR", help="'builtin' as DIR = the embedded model, 'examples' = mo-sample --examples FOLDER (no model); mo-sample options may follow DIR, e.g. 'raw=builtin --smooth 0'; '--document' samples from `skel-info SKELETON | mo-sample` instead of the file")
    ap.add_argument("--skeletons", nargs="+", required=True, metavar="FOLDER")
    ap.add_argument("-n", type=int, default=8)
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--sampler", default="ddim")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--steps-table", metavar="FOLDER", help="also: quality and time against sampling steps here")
    ap.add_argument("--by-clip", action="store_true", help="also: each generator's calibrated coverage of each clip, in a second table")
    args = ap.parse_args()
    models = [m.split("=", 1) for m in args.model]
    tmp = tempfile.mkdtemp(prefix="menagerie-eval-")
    print(row(["skeleton", "generator"] + [h for _, h in METRICS + PHYSICS]))
    print(row(["---"] * (2 + len(METRICS) + len(PHYSICS))))
    by_clip = []
    for folder in args.skeletons:
        name = os.path.basename(folder.rstrip("/"))
        skeleton = clips(folder)[0]
        m = metrics(args.bin, folder, folder, skeleton)  # the clips against themselves
        # The clips' physics with their per-clip range in brackets: "within the range of the
        # training data" is judged against it.
        print(row([name, "gt (the clips)"] + cells(m, ranges=True)), flush=True)
        # The movement baselines (from the clips alone): leave-one-out clips, a static mean
        # pose, random crops as many and as long as the samples.
        base = None
        for label, model in models:
            out = os.path.join(tmp, f"{name}_{label}")
            sample(args.bin, model, folder, skeleton, out, args.n, args.frames, args.steps, args.sampler, args.seed)
            m = metrics(args.bin, folder, out, skeleton)
            if base is None:
                base = m["baselines"]
                for key, text in [("clips", "clips, leave-one-out"), ("mean_pose", "static mean pose"), ("random_crops", "random crops"), ("random_phases", "feet phased at random")]:
                    b = dict(base[key])
                    print(row([name, text] + [num(b.get(k), k) if k in b else "" for k, _ in METRICS] + [""] * len(PHYSICS)), flush=True)
            print(row([name, label] + cells(m)), flush=True)
            by_clip.append((name, label, m["by_clip"]))
    if args.by_clip:
        print()
        print(row(["skeleton", "generator", "calibrated coverage % of each clip"]))
        print(row(["---"] * 3))
        for name, label, per in by_clip:
            text = ", ".join(f"{clip} {'-' if v is None else f'{v:.1f}'}" for clip, v in per)
            print(row([name, label, text]), flush=True)
    if args.steps_table and models:
        label, model = models[0]
        folder = args.steps_table
        name = os.path.basename(folder.rstrip("/"))
        skeleton = clips(folder)[0]
        print()
        print(f"{label} on {name}, {args.n} x {args.frames} frames, one thread each run:")
        print()
        print(row(["sampler", "steps", "wall s"] + [h for _, h in METRICS + PHYSICS]))
        print(row(["---"] * (3 + len(METRICS) + len(PHYSICS))))
        for sampler, steps in [("ddim", 5), ("ddim", 10), ("ddim", 20), ("ddim", 50), ("ddpm", 20), ("ddpm", 100)]:
            out = os.path.join(tmp, f"steps_{sampler}_{steps}")
            secs = sample(args.bin, model, folder, skeleton, out, args.n, args.frames, steps, sampler, args.seed)
            m = metrics(args.bin, folder, out, skeleton)
            print(row([sampler, str(steps), f"{secs:.1f}"] + cells(m)), flush=True)


if __name__ == "__main__":
    main()
