//! Skeleton document build time: BVH text -> parse -> Skeleton -> Motion ->
//! SkeletonDocument::build -> serde_json::to_string, for a 143-joint skeleton (AnyTop's largest;
//! generated here) and for the biggest corpus skeleton (the 86-joint Truebones Monkey, read from
//! ../shared/data when present). The file is read once; the timed loop starts from its bytes.
//!
//! Run: `cargo bench --bench skeleton_doc` (optional argument: repetitions, default 60).
//! Target: well under 50 ms for 143 joints.

use menagerie::bvh::{self, Bvh, BvhJoint, Channel};
use menagerie::document::{MotionInfo, SkeletonDocument};
use menagerie::skeleton::{names, roles, topology, Skeleton, Stats};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

/// Parent list of a 143-joint creature: spine, neck and head, 8 legs with two toes each,
/// 2 arms with five 3-joint fingers, and a tail that makes up the rest.
fn creature_parents(total: usize) -> Vec<Option<usize>> {
    fn chain(parents: &mut Vec<Option<usize>>, from: usize, len: usize) -> usize {
        let mut at = from;
        for _ in 0..len {
            parents.push(Some(at));
            at = parents.len() - 1;
        }
        at
    }
    let mut p = vec![None];
    let chest = chain(&mut p, 0, 4);
    chain(&mut p, chest, 4);
    for leg in 0..8 {
        let ankle = chain(&mut p, if leg < 4 { 0 } else { chest }, 4);
        chain(&mut p, ankle, 3);
        chain(&mut p, ankle, 2);
    }
    for _ in 0..2 {
        let hand = chain(&mut p, chest, 4);
        for _ in 0..5 {
            chain(&mut p, hand, 3);
        }
    }
    let have = p.len();
    chain(&mut p, 0, total - have);
    p
}

/// BVH text of a synthetic creature: root with 6 channels, the rest Z X Y, smooth motion; no
/// name says left, right or foot, so sides and feet take their geometric paths.
fn synthetic_bvh(total: usize, frames: usize) -> String {
    let parents = creature_parents(total);
    let has_child: Vec<bool> = (0..total).map(|j| parents.contains(&Some(j))).collect();
    let rot = [Channel::Zrotation, Channel::Xrotation, Channel::Yrotation];
    let joints: Vec<BvhJoint> = (0..total)
        .map(|j| {
            let a = j as f64 * 2.399963;
            BvhJoint {
                name: match parents[j] {
                    None => "Hips".to_string(),
                    // No side words: sides come from geometry (the slower path).
                    Some(_) => format!("Bone{j}"),
                },
                parent: parents[j],
                offset: if j == 0 { [0.0, 60.0, 0.0] } else { [4.0 * a.cos(), 3.0 + (j % 4) as f64, 4.0 * a.sin()] },
                channels: if j == 0 { vec![Channel::Xposition, Channel::Yposition, Channel::Zposition, rot[0], rot[1], rot[2]] } else { rot.to_vec() },
                end_sites: if has_child[j] { Vec::new() } else { vec![[0.0, 2.0, 0.0]] },
            }
        })
        .collect();
    let channels: usize = joints.iter().map(|j| j.channels.len()).sum();
    let mut values = Vec::with_capacity(frames * channels);
    for f in 0..frames {
        let t = f as f64 / 30.0;
        for c in 0..channels {
            let v = match c {
                0 => 10.0 * t,
                1 => 60.0 + (3.0 * t).sin(),
                2 => 2.0 * t,
                _ => 35.0 * (1.7 * t + c as f64 * 0.37).sin(),
            };
            values.push((v * 1e4).round() / 1e4);
        }
    }
    bvh::write_string(&Bvh { joints, frame_time: 1.0 / 30.0, frames, values })
}

#[derive(Default)]
struct Times {
    parse: Vec<Duration>,
    skeleton_motion: Vec<Duration>,
    build: Vec<Duration>,
    json: Vec<Duration>,
    total: Vec<Duration>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn median(v: &[Duration]) -> f64 {
    let m: Vec<f64> = v.iter().map(|d| ms(*d)).collect();
    Stats::of(&m).map_or(f64::NAN, |s| s.median)
}

fn min(v: &[Duration]) -> f64 {
    v.iter().map(|d| ms(*d)).fold(f64::INFINITY, f64::min)
}

/// One full document build from BVH bytes, stage by stage.
fn run_once(bytes: &[u8], source: &str, t: &mut Times) -> (usize, usize, usize) {
    let t0 = Instant::now();
    let parsed = bvh::parse_bytes(black_box(bytes), source).expect("parse");
    let t1 = Instant::now();
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = MotionInfo::of(&parsed, &skeleton);
    let t2 = Instant::now();
    let doc = SkeletonDocument::build(&skeleton, motion, source, topology::DEFAULT_DMAX);
    let t3 = Instant::now();
    let json = serde_json::to_string(&doc).expect("json");
    let t4 = Instant::now();
    t.parse.push(t1 - t0);
    t.skeleton_motion.push(t2 - t1);
    t.build.push(t3 - t2);
    t.json.push(t4 - t3);
    t.total.push(t4 - t0);
    black_box(&json);
    (skeleton.len(), parsed.frames, json.len())
}

/// Median time of `f` over `reps` runs, in ms.
fn time_it<R>(reps: usize, mut f: impl FnMut() -> R) -> (f64, f64) {
    let mut v = Vec::with_capacity(reps);
    for _ in 0..reps {
        let t = Instant::now();
        black_box(f());
        v.push(t.elapsed());
    }
    (median(&v), min(&v))
}

fn main() {
    let reps: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(60);
    let mut cases: Vec<(String, Vec<u8>)> =
        vec![("synthetic 143 joints".into(), synthetic_bvh(143, 61).into_bytes()), ("synthetic 143 joints".into(), synthetic_bvh(143, 600).into_bytes())];
    let monkey = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh/truebones_motion2motion/Monkey/__Walk.bvh");
    match std::fs::read(&monkey) {
        Ok(bytes) => cases.push(("Truebones Monkey __Walk".into(), bytes)),
        Err(e) => eprintln!("note: {} not read ({e}); the corpus case is skipped", monkey.display()),
    }

    println!("skeleton document build: parse + Skeleton + Motion + SkeletonDocument::build + serde_json::to_string");
    println!("{reps} repetitions after 3 warm-up runs; times in ms (median / min)\n");
    println!("| case | joints | frames | BVH KiB | JSON KiB | total median | total min | parse | skeleton+motion | build | to_string |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, bytes) in &cases {
        let mut warm = Times::default();
        for _ in 0..3 {
            run_once(bytes, name, &mut warm);
        }
        let mut t = Times::default();
        let mut shape = (0, 0, 0);
        for _ in 0..reps {
            shape = run_once(bytes, name, &mut t);
        }
        println!(
            "| {name} | {} | {} | {:.0} | {:.0} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            shape.0,
            shape.1,
            bytes.len() as f64 / 1024.0,
            shape.2 as f64 / 1024.0,
            median(&t.total),
            min(&t.total),
            median(&t.parse),
            median(&t.skeleton_motion),
            median(&t.build),
            median(&t.json),
        );
    }

    // Where SkeletonDocument::build spends its time, per component (public functions it calls).
    for (name, bytes) in [0, 2].iter().filter_map(|&i| cases.get(i)) {
        let parsed = bvh::parse_bytes(bytes, name).unwrap();
        let skeleton = Skeleton::from_bvh(&parsed);
        let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect();
        let n = reps.max(20);
        let rows: Vec<(&str, (f64, f64))> = vec![
            ("names::normalise (all joints)", time_it(n, || skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect::<Vec<_>>())),
            ("roles::sides", time_it(n, || roles::sides(&skeleton, &normalised))),
            ("roles::feet", time_it(n, || roles::feet(&skeleton))),
            ("rest_positions", time_it(n, || skeleton.rest_positions())),
            ("rest_bounds", time_it(n, || skeleton.rest_bounds())),
            ("topology::relations", time_it(n, || topology::relations(&skeleton))),
            ("topology::distances (dmax 5)", time_it(n, || topology::distances(&skeleton, topology::DEFAULT_DMAX))),
            ("topology::kinematic_chains", time_it(n, || topology::kinematic_chains(&skeleton))),
            ("MotionInfo::of (frame 0 FK)", time_it(n, || MotionInfo::of(&parsed, &skeleton))),
            ("SkeletonDocument::build (whole)", time_it(n, || SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), name, 5))),
        ];
        println!("\nbuild breakdown, {name} ({} joints, {} frames): median / min ms", skeleton.len(), parsed.frames);
        println!("| component | median | min |");
        println!("|---|---:|---:|");
        for (what, (med, lo)) in rows {
            println!("| {what} | {med:.4} | {lo:.4} |");
        }
    }
}
