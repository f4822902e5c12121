//! Motion representation throughput (frames/s): `cargo bench --bench encode`.
//!
//! Issue 3 asks `mo-encode` to be fast and to report frames per second. For each input set
//! (every folder of `../shared/data/bvh`, the whole corpus, and the project's own
//! `examples/data`; the corpus rows are skipped with a note when it is absent) the table gives:
//!
//! * `encode`: `Motion -> Features` (m2m), one thread;
//! * `decode`: `Features -> Motion` on the skeleton, one thread;
//! * `BVH->NPY`: what `mo-encode` does per file: parse BVH, build the motion, encode, write the
//!   NPY bytes; one thread, and across clips with rayon on all cores (as the tool does);
//! * `NPY->BVH`: what `mo-encode --decode` does: read the NPY bytes, decode, write BVH text;
//!   one thread.
//!
//! Each measurement runs `RUNS` times over all clips of the set; frames/s is total frames over
//! the median time. No benchmark framework, to keep dependencies at zero.

mod common;
use common::{bvh_files, median, time_runs, RUNS};

use menagerie::bvh;
use menagerie::io::npy;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{AnyTopRig, Encoded, IkOptions, RigOptions};
use menagerie::repr::{m2m, Features};
use menagerie::skeleton::Skeleton;
use rayon::prelude::*;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

struct Clip {
    bytes: Vec<u8>,
    skeleton: Skeleton,
    motion: Motion,
    features: Features,
    npy: Vec<u8>,
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut sets: Vec<(String, Vec<PathBuf>)> = Vec::new();
    let corpus = root.join("../shared/data/bvh");
    if corpus.is_dir() {
        let mut all = Vec::new();
        let mut folders: Vec<PathBuf> = std::fs::read_dir(&corpus).unwrap().flatten().map(|e| e.path()).filter(|p| p.is_dir()).collect();
        folders.sort();
        for folder in folders {
            let files = bvh_files(&folder);
            if !files.is_empty() {
                all.extend(files.iter().cloned());
                sets.push((format!("corpus/{}", folder.file_name().unwrap().to_string_lossy()), files));
            }
        }
        sets.push(("corpus (all)".to_string(), all));
    } else {
        println!("note: {} is absent; skipping the corpus rows", corpus.display());
    }
    sets.push(("examples/data (all)".to_string(), bvh_files(&root.join("examples/data"))));

    let threads = rayon::current_num_threads();
    println!("m2m representation; {RUNS} runs each, frames/s from the median; rayon column uses {threads} threads");
    println!();
    println!("| input | files | frames | joints | encode f/s | decode f/s | BVH->NPY f/s | BVH->NPY f/s ({threads} thr) | NPY->BVH f/s |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, files) in &sets {
        let clips: Vec<Clip> = files.iter().map(|p| load(p)).collect();
        let frames: usize = clips.iter().map(|c| c.motion.frames).sum();
        let (jmin, jmax) = clips.iter().fold((usize::MAX, 0), |(a, b), c| (a.min(c.skeleton.len()), b.max(c.skeleton.len())));
        let joints = if jmin == jmax { jmin.to_string() } else { format!("{jmin}-{jmax}") };

        let encode = time_runs(|| {
            for c in &clips {
                black_box(m2m::encode(black_box(&c.motion)));
            }
        });
        let decode = time_runs(|| {
            for c in &clips {
                black_box(m2m::decode(black_box(&c.features), &c.skeleton).unwrap());
            }
        });
        let bvh_to_npy_seq = time_runs(|| {
            for c in &clips {
                black_box(bvh_to_npy(&c.bytes));
            }
        });
        let bvh_to_npy_par = time_runs(|| {
            let out: Vec<Vec<u8>> = clips.par_iter().map(|c| bvh_to_npy(&c.bytes)).collect();
            black_box(out);
        });
        let npy_to_bvh = time_runs(|| {
            for c in &clips {
                let a = npy::from_bytes(black_box(&c.npy), "bench").unwrap();
                let [f, j, d] = a.shape[..] else { unreachable!() };
                let features = Features { frames: f, joints: j, dims: d, data: a.data };
                let motion = m2m::decode(&features, &c.skeleton).unwrap();
                black_box(bvh::write_string(&motion.to_bvh(&c.skeleton)));
            }
        });
        let fps = |t: &[Duration]| frames as f64 / median(t).as_secs_f64();
        println!(
            "| {name} | {} | {frames} | {joints} | {} | {} | {} | {} | {} |",
            clips.len(),
            human(fps(&encode)),
            human(fps(&decode)),
            human(fps(&bvh_to_npy_seq)),
            human(fps(&bvh_to_npy_par)),
            human(fps(&npy_to_bvh)),
        );
    }

    // AnyTop: the rig is built once per clip from its own frame 0 (as skel-info does) and is
    // not timed; encode, decode from rotations and decode from positions (IK) are.
    println!();
    println!("AnyTop representation (13-D per joint); {RUNS} runs each, one thread, frames/s from the median");
    println!();
    println!("| input | files | frames | encode f/s | decode (rotations) f/s | decode (IK) f/s |");
    println!("|---|---:|---:|---:|---:|---:|");
    for (name, files) in &sets {
        let clips: Vec<Clip> = files.iter().map(|p| load(p)).filter(|c| c.motion.frames >= 2).collect();
        let rigged: Vec<(&Clip, AnyTopRig, Encoded)> = clips
            .iter()
            .filter_map(|c| {
                let rig = AnyTopRig::new(&c.skeleton, &c.motion.first_frames(1), &RigOptions::default()).ok()?;
                let encoded = rig.encode(&c.skeleton, &c.motion).ok()?;
                Some((c, rig, encoded))
            })
            .collect();
        let frames: usize = rigged.iter().map(|(_, _, e)| e.features.frames).sum();
        let encode = time_runs(|| {
            for (c, rig, _) in &rigged {
                black_box(rig.encode(&c.skeleton, black_box(&c.motion)).unwrap());
            }
        });
        let decode = time_runs(|| {
            for (c, rig, e) in &rigged {
                black_box(rig.decode(&c.skeleton, black_box(&e.features), &e.placement).unwrap());
            }
        });
        let ik = time_runs(|| {
            for (c, rig, e) in &rigged {
                black_box(rig.decode_ik(&c.skeleton, black_box(&e.features), &e.placement, &IkOptions::default()).unwrap());
            }
        });
        let fps = |t: &[Duration]| frames as f64 / median(t).as_secs_f64();
        println!("| {name} | {} | {frames} | {} | {} | {} |", rigged.len(), human(fps(&encode)), human(fps(&decode)), human(fps(&ik)));
    }
}

fn load(path: &Path) -> Clip {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let parsed = bvh::parse_bytes(&bytes, &path.display().to_string()).unwrap_or_else(|e| panic!("{e}"));
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    let features = m2m::encode(&motion);
    let npy = npy::to_bytes(&features.shape(), &features.data).unwrap();
    Clip { bytes, skeleton, motion, features, npy }
}

/// `mo-encode FILE.bvh` minus the file I/O.
fn bvh_to_npy(bytes: &[u8]) -> Vec<u8> {
    let parsed = bvh::parse_bytes(black_box(bytes), "bench").unwrap();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    let f = m2m::encode(&motion);
    npy::to_bytes(&f.shape(), &f.data).unwrap()
}

/// 1234567.8 -> "1.23 M", 45678 -> "45.7 k".
fn human(v: f64) -> String {
    if v >= 1e6 {
        format!("{:.2} M", v / 1e6)
    } else if v >= 1e3 {
        format!("{:.1} k", v / 1e3)
    } else {
        format!("{v:.0}")
    }
}
