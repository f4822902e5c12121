//! Motion2Motion retarget speed: `cargo bench --bench retarget`.
//!
//! Rows (median of `RUNS` in-process runs of `retarget::retarget`, after one warm-up; the
//! reference's numbers in docs/reference/motion2motion.md §2 are for its warm retarget loop):
//! * the demo: Flamingo_Walk (79 frames) -> one Monkey walk (61 frames), 6 bound bones, the
//!   reference's binding, at the reference demo's alpha 0.9 and at the paper's 0.85;
//! * long sources: the Flamingo clip repeated 8x and 64x (632 and 5056 frames);
//! * several example clips: the Monkey clip 4x and 16x.
//!
//! Each row runs on one thread (wall and on-CPU time) and on all threads. When ../shared/data
//! is absent the rows use the project's synthetic biped -> quadruped instead.
//!
//! Then, for the demo, how our output compares with the reference's output BVH (seed 0, alpha
//! 0.9, default and copy mode): frames, root height range, mean joint position error.

mod common;
use common::{median, ms, time_runs, RUNS};

use menagerie::binding::{Binding, JointMap};
use menagerie::bvh;
use menagerie::motion::Motion;
use menagerie::retarget::{retarget, Settings};
use menagerie::skeleton::Skeleton;
use std::hint::black_box;
use std::path::Path;

struct Case {
    source: Motion,
    source_skeleton: Skeleton,
    example: Motion,
    target: Skeleton,
    map: JointMap,
}

fn load(path: &Path) -> (Skeleton, Motion) {
    let text = std::fs::read_to_string(path).expect("reading a BVH");
    let parsed = bvh::parse(&text, &path.display().to_string()).expect("parsing a BVH");
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    (skeleton, motion)
}

/// The reference's demo files carry 5-character name suffixes (`Hips__laU`); its binding does
/// not. Drop them for this benchmark (the CLI decides how users deal with them).
fn strip_suffixes(s: &mut Skeleton) {
    for j in &mut s.joints {
        if let Some(at) = j.name.rfind("__") {
            if j.name.len() - at == 5 {
                j.name.truncate(at);
            }
        }
    }
}

fn demo() -> Option<Case> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    let dir = root.join("bvh/truebones_motion2motion");
    let (mut source_skeleton, source) = (dir.join("Flamingo/Flamingo_Walk.bvh").is_file()).then(|| load(&dir.join("Flamingo/Flamingo_Walk.bvh")))?;
    let (mut target, example) = load(&dir.join("Monkey/__Walk.bvh"));
    let text = std::fs::read_to_string(root.join("bindings/flamingo_to_monkey.m2m.json")).ok()?;
    let binding = Binding::from_json(&text, "binding").ok()?;
    strip_suffixes(&mut source_skeleton);
    strip_suffixes(&mut target);
    let map = binding.resolve("binding", &source_skeleton, "flamingo", &target, "monkey").expect("resolving the demo binding");
    Some(Case { source, source_skeleton, example, target, map })
}

fn synthetic() -> Case {
    let (source_skeleton, source) = menagerie::synth::creature("biped", 1).unwrap();
    let (target, example) = menagerie::synth::creature("quadruped", 1).unwrap();
    let pairs = [
        ("mixamorig:LeftUpLeg", "Bip01_L_Thigh"),
        ("mixamorig:LeftLeg", "Bip01_L_Calf"),
        ("mixamorig:LeftFoot", "Bip01_L_Foot"),
        ("mixamorig:RightUpLeg", "Bip01_R_Thigh"),
        ("mixamorig:RightLeg", "Bip01_R_Calf"),
        ("mixamorig:RightFoot", "Bip01_R_Foot"),
    ];
    let map = pairs.iter().map(|(s, t)| (source_skeleton.index_of(s).unwrap(), target.index_of(t).unwrap())).collect();
    Case { source: source.first_frames(79), source_skeleton, example: example.first_frames(61), target, map }
}

/// `m` played `k` times in a row.
fn repeat(m: &Motion, k: usize) -> Motion {
    let mut out = m.clone();
    out.frames = m.frames * k;
    out.rotations = m.rotations.repeat(k);
    out.translations = m.translations.repeat(k);
    out
}

/// On-CPU time of the calling thread (Linux `schedstat`), in ms: on a machine shared with other
/// jobs, wall time counts the waits for a core; this does not.
fn thread_cpu_ms() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(text.split_whitespace().next()?.parse::<f64>().ok()? / 1e6)
}

/// Median on-CPU ms of `retarget` on one thread (`None` without schedstat). The kernel may
/// account CPU time in scheduler ticks (4 ms here), so each sample times enough runs to span
/// about 100 ticks and divides.
fn cpu_time(case: &Case, source: &Motion, examples: &[Motion], settings: &Settings) -> Option<f64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        let run = || black_box(retarget(source, &case.source_skeleton, examples, &case.target, &case.map, settings).unwrap());
        let start = std::time::Instant::now();
        run();
        let once = start.elapsed().as_secs_f64() * 1e3;
        let batch = ((400.0 / once.max(1e-3)).ceil() as usize).clamp(1, 1000);
        let mut t: Vec<f64> = Vec::new();
        for _ in 0..RUNS {
            let start = thread_cpu_ms()?;
            for _ in 0..batch {
                run();
            }
            t.push((thread_cpu_ms()? - start) / batch as f64);
        }
        t.sort_by(f64::total_cmp);
        Some(t[t.len() / 2])
    })
}

fn time(case: &Case, source: &Motion, examples: &[Motion], settings: &Settings, threads: usize) -> f64 {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let run = || black_box(retarget(source, &case.source_skeleton, examples, &case.target, &case.map, settings).unwrap());
        run();
        ms(median(&time_runs(|| {
            run();
        })))
    })
}

fn main() {
    let (case, name) = match demo() {
        Some(c) => (c, "Flamingo_Walk -> Monkey"),
        None => {
            println!("note: ../shared/data is absent; using the synthetic biped -> quadruped");
            (synthetic(), "biped -> quadruped (synthetic)")
        }
    };
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    let ref_settings = Settings { alpha: 0.9, ..Settings::default() };
    let paper = Settings::default();
    println!(
        "{name}: source {} frames x {} joints, example {} frames x {} joints, {} bound bones; {RUNS} runs, median ms",
        case.source.frames,
        case.source.joints,
        case.example.frames,
        case.example.joints,
        case.map.len()
    );
    println!();
    println!("| case | source frames | example clips (frames) | levels | 1 thread ms | 1 thread on-CPU ms | {threads} threads ms | frames/s ({threads} thr) |");
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    let rows: Vec<(&str, usize, usize, &Settings)> = vec![
        ("demo, alpha 0.9 (reference demo)", 1, 1, &ref_settings),
        ("demo, paper defaults", 1, 1, &paper),
        ("source x8", 8, 1, &ref_settings),
        ("source x64", 64, 1, &ref_settings),
        ("4 example clips", 1, 4, &ref_settings),
        ("16 example clips", 1, 16, &ref_settings),
    ];
    let mut breakdown = Vec::new();
    for (label, k, clips, settings) in rows {
        let source = repeat(&case.source, k);
        let examples = vec![case.example.clone(); clips];
        let report = retarget(&source, &case.source_skeleton, &examples, &case.target, &case.map, settings).unwrap().report;
        let levels = report.levels.iter().map(|l| l.frames.to_string()).collect::<Vec<_>>().join(", ");
        let t = &report.timings;
        breakdown.push(format!("| {label} | {:.2} | {:.2} | {:.2} | {:.2} |", ms(t.prepare), ms(t.synthesis), ms(t.decode), ms(t.total)));
        let one = time(&case, &source, &examples, settings, 1);
        let cpu = cpu_time(&case, &source, &examples, settings).map(|c| format!("{c:.2}")).unwrap_or_else(|| "-".into());
        let all = time(&case, &source, &examples, settings, threads);
        println!(
            "| {label} | {} | {clips} ({}) | {levels} | {one:.2} | {cpu} | {all:.2} | {:.0} |",
            source.frames,
            clips * case.example.frames,
            source.frames as f64 / all * 1e3
        );
    }
    println!();
    println!("One run's own timings ({threads} threads, from the report), ms:");
    println!();
    println!("| case | prepare | synthesis | decode | total |");
    println!("|---|---:|---:|---:|---:|");
    for line in breakdown {
        println!("{line}");
    }
    compare_with_reference(&case);
}

/// How far our demo output is from the reference's output BVHs.
fn compare_with_reference(case: &Case) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/reference-outputs");
    let files =
        [("default", "m2m_flamingo_walk_to_monkey_seed0_alpha0.9.bvh", false), ("copy mode", "m2m_flamingo_walk_to_monkey_seed0_alpha0.9_copymode.bvh", true)];
    if !dir.is_dir() {
        return;
    }
    println!();
    println!("Demo vs the reference's output (alpha 0.9); errors in Monkey units (rest height {:.1}):", case.target.rest_height());
    println!();
    println!("| mode | reference frames | ours frames | ref root y range | our root y range | mean joint error, seed 0 | over seeds 0-4 | example vs ref | ours: seed 0 vs seeds 1-4 |");
    println!("|---|---:|---:|---|---|---:|---:|---:|---:|");
    // Our default draws among near-tie patches (diversity); 1 choice is the reference's rule.
    let runs = files.iter().flat_map(|&(mode, file, copy)| [(mode, file, copy, Settings::default().sample_choices), (mode, file, copy, 1)]);
    for (mode, file, copy, choices) in runs {
        let mode = format!("{mode}, {choices} choice(s)");
        let path = dir.join(file);
        if !path.is_file() {
            continue;
        }
        let (ref_skeleton, reference) = load(&path);
        if ref_skeleton.len() != case.target.len() {
            println!("| {mode} | skeleton differs ({} joints) | | | | | | | |", ref_skeleton.len());
            continue;
        }
        let errors: Vec<(f64, Motion)> = (0..5)
            .map(|seed| {
                let settings = Settings { alpha: 0.9, copy_bound: copy, seed, sample_choices: choices, ..Settings::default() };
                let ours =
                    retarget(&case.source, &case.source_skeleton, std::slice::from_ref(&case.example), &case.target, &case.map, &settings).unwrap().motion;
                (mean_error(&ours, &reference, &case.target), ours)
            })
            .collect();
        let ours = &errors[0].1;
        let mean5 = errors.iter().map(|e| e.0).sum::<f64>() / 5.0;
        // A baseline: the Monkey example itself (looped to length) against the reference.
        let looped = repeat(&case.example, reference.frames.div_ceil(case.example.frames)).first_frames(reference.frames);
        let baseline = mean_error(&looped, &reference, &case.target);
        let (ry, oy) = (root_y(&reference), root_y(ours));
        let diversity = errors[1..].iter().map(|e| mean_error(&e.1, ours, &case.target)).sum::<f64>() / 4.0;
        println!(
            "| {mode} | {} | {} | {:.2}..{:.2} | {:.2}..{:.2} | {:.3} | {:.3} | {:.2} | {:.3} |",
            reference.frames, ours.frames, ry.0, ry.1, oy.0, oy.1, errors[0].0, mean5, baseline, diversity
        );
    }
}

/// Mean distance between corresponding joints, positions taken relative to the root's
/// horizontal position (the two root tracks start at different places).
fn mean_error(a: &Motion, b: &Motion, skeleton: &Skeleton) -> f64 {
    let (pa, pb) = (a.forward_kinematics(skeleton), b.forward_kinematics(skeleton));
    let (frames, j) = (a.frames.min(b.frames), skeleton.len());
    let mut sum = 0.0;
    for f in 0..frames {
        let (ra, rb) = (pa.position(f, 0), pb.position(f, 0));
        for k in 0..j {
            let mut da = pa.position(f, k) - ra;
            let mut db = pb.position(f, k) - rb;
            da.y += ra.y;
            db.y += rb.y;
            sum += da.distance(db);
        }
    }
    sum / (frames * j).max(1) as f64
}

fn root_y(m: &Motion) -> (f64, f64) {
    let ys = (0..m.frames).map(|f| m.translations[f * m.joints].y);
    ys.clone().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)))
}
