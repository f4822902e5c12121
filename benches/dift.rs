//! DIFT correspondence where the truth is known (issue 8): top-1 joint accuracy of DIFT at
//! several (t, layer) settings against a names-only and a geometry-only baseline, on each clip
//! against (a) a copy with its joints in another file order and numbers for names and (b)
//! `skel-aug` variants (10-30% of the joints removed, 2 added; surviving joints keep their
//! names); left/right confusions counted apart, raw and centred descriptors (`dift::centred`),
//! clips at temporal position 0. Then frame correspondence against a time-warped copy (mean
//! frame error; each draw at a random temporal position, `DiftOptions::shift`; descriptors
//! the joint mean or the joints side by side, `dift::frame_descriptors`; matched frame by frame
//! and in time order, `correspond::monotonic_matches`), and the time one extraction takes.
//!
//!     cargo bench --bench dift                       # built-in model
//!     MENAGERIE_DIFT_MODEL=DIR cargo bench --bench dift
//!
//! Clips: the synthetic creatures in examples/data, and (when ../shared/data/bvh exists) the
//! first clip of a few corpus collections; every clip is cut to its first 240 frames.
mod common;

use candle_core::Device;
use menagerie::augment::{self, RemoveAmount};
use menagerie::bvh;
use menagerie::diffusion::checkpoint::{self, FrozenDenoiser};
use menagerie::dift::correspond::{self, best_matches, cosine_matrix};
use menagerie::dift::eval::{self, Accuracy};
use menagerie::dift::{self, DiftOptions};
use menagerie::document::AnyTopSection;
use menagerie::motion::Motion;
use menagerie::repr::anytop::RigOptions;
use menagerie::rng::SplitMix64;
use menagerie::skeleton::Skeleton;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

// (t, layer); the built-in model has layers 0 and 1 since it became the compact preset
// (zoo-small's layer 3, measured before, is in BENCHMARKS.md).
const SETTINGS: [(usize, usize); 4] = [(2, 0), (3, 1), (10, 1), (2, 1)];
const MAX_FRAMES: usize = 240;
const DRAWS: usize = 4;

struct Clip {
    set: &'static str,
    name: String,
    skeleton: Skeleton,
    motion: Motion,
}

fn read_clip(path: &Path, set: &'static str) -> Option<Clip> {
    let parsed = bvh::read_path(path).ok()?;
    let skeleton = Skeleton::from_bvh(&parsed);
    skeleton.validate().ok()?;
    let motion = Motion::from_bvh(&parsed, &skeleton).first_frames(MAX_FRAMES);
    let name = path.file_name()?.to_string_lossy().into_owned();
    (motion.frames >= 30).then_some(Clip { set, name, skeleton, motion })
}

fn clips() -> Vec<Clip> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut out: Vec<Clip> = common::bvh_files(&root.join("examples/data")).iter().filter_map(|p| read_clip(p, "synthetic")).collect();
    let corpus = root.join("../shared/data/bvh");
    if corpus.is_dir() {
        for collection in ["truebones_anytop", "cmu_bvh11", "lafan1", "dog_mann", "xia_dme", "bandai_namco"] {
            if let Some(c) = common::bvh_files(&corpus.join(collection)).iter().find_map(|p| read_clip(p, "corpus")) {
                out.push(c);
            }
        }
    } else {
        println!("(no {}: corpus rows skipped)", corpus.display());
    }
    out
}

/// Per-joint rest positions facing +z (the AnyTop rig's natural rest pose).
fn facing_rest(s: &Skeleton, m: &Motion) -> Option<Vec<glam::DVec3>> {
    let section = AnyTopSection::new(s, &m.first_frames(2), &RigOptions::default()).ok()?;
    Some(section.rig.rest_positions(s))
}

/// Per setting: [raw, centred] per-joint and per-frame descriptors.
struct Extracted {
    per_joint: Vec<[Vec<Vec<f32>>; 2]>,
    /// Per setting: features with each draw at a random temporal position (for frames).
    shifted: Vec<dift::DiftFeatures>,
    raw_frames: Vec<Vec<f32>>,
    seconds: f64,
}

fn extract_all(model: &FrozenDenoiser, s: &Skeleton, m: &Motion, name: &str) -> anyhow::Result<Extracted> {
    let prepared = dift::prepare(&model.info, s, m, name)?;
    let schedule = model.info.schedule();
    let cond = prepared.condition.condition();
    let (mut per_joint, mut shifted_all) = (Vec::new(), Vec::new());
    let started = Instant::now();
    for &(t, layer) in &SETTINGS {
        let extract =
            |shift| dift::extract(&model.model, &schedule, &cond, &prepared.features, &DiftOptions { t, layer, draws: DRAWS, seed: 0, shift }, &Device::Cpu);
        let (fixed, shifted) = (extract(false)?, extract(true)?);
        per_joint.push([fixed.per_joint(), dift::centred(fixed.per_joint())]);
        shifted_all.push(shifted);
    }
    let seconds = started.elapsed().as_secs_f64() / SETTINGS.len() as f64;
    let per = prepared.features.joints * prepared.features.dims;
    let raw_frames = prepared.features.data.chunks(per).map(|c| c.to_vec()).collect();
    Ok(Extracted { per_joint, shifted: shifted_all, raw_frames, seconds })
}

fn main() {
    let device_model = match std::env::var_os("MENAGERIE_DIFT_MODEL") {
        Some(dir) => checkpoint::frozen(Path::new(&dir), &Device::Cpu),
        None => checkpoint::frozen_default(&Device::Cpu),
    };
    let model = match device_model {
        Ok(m) => m,
        Err(e) => {
            println!("SKIP dift: {e:#}");
            return;
        }
    };
    let methods: Vec<String> = SETTINGS
        .iter()
        .flat_map(|(t, l)| [format!("DIFT t{t} l{l}"), format!("centred t{t} l{l}")])
        .chain(["names only".to_string(), "geometry only".to_string()])
        .collect();
    // (set, target kind) -> per method accuracy.
    let mut joints: BTreeMap<(String, &str), Vec<Accuracy>> = BTreeMap::new();
    let mut frames: BTreeMap<(String, &str), Vec<(f64, usize)>> = BTreeMap::new();
    let mut timing = Vec::new();
    for clip in clips() {
        let Ok(reference) = extract_all(&model, &clip.skeleton, &clip.motion, &clip.name) else {
            println!("(skipped {}: no DIFT features)", clip.name);
            continue;
        };
        timing.push((clip.name.clone(), clip.motion.frames, clip.skeleton.len(), reference.seconds));
        let Some(ref_rest) = facing_rest(&clip.skeleton, &clip.motion) else { continue };
        let ref_names = eval::name_descriptors(&clip.skeleton).expect("name table");
        let mirror = eval::mirrors(&clip.skeleton);
        let mut rng = SplitMix64::new(7);
        let mut targets: Vec<(&str, Skeleton, Motion, Vec<Option<usize>>)> = Vec::new();
        for _ in 0..2 {
            let (s, m, order) = eval::renamed_shuffled(&clip.skeleton, &clip.motion, &mut rng);
            targets.push(("renamed + shuffled", s, m, order.into_iter().map(Some).collect()));
            let opts = augment::Options { remove: Some(RemoveAmount::Random), add: 2, keep_feet: true };
            let plan = augment::plan(&clip.skeleton, &opts, &mut rng);
            let m = plan.apply_motion(&clip.skeleton, &clip.motion);
            let truth = eval::truth_by_name(&clip.skeleton, &plan.skeleton);
            targets.push(("skel-aug variant", plan.skeleton, m, truth));
        }
        for (kind, s, m, truth) in &targets {
            let Ok(tgt) = extract_all(&model, s, m, &clip.name) else { continue };
            let Some(rest) = facing_rest(s, m) else { continue };
            let mut sims: Vec<Vec<Vec<f64>>> = (0..SETTINGS.len())
                .flat_map(|k| (0..2).map(move |v| (k, v)))
                .map(|(k, v)| cosine_matrix(&tgt.per_joint[k][v], &reference.per_joint[k][v]))
                .collect();
            sims.push(cosine_matrix(&eval::name_descriptors(s).expect("name table"), &ref_names));
            sims.push(eval::distance_similarity(&eval::geometry_descriptors(&rest), &eval::geometry_descriptors(&ref_rest)));
            let row = joints.entry((clip.set.to_string(), kind)).or_insert_with(|| vec![Accuracy::default(); methods.len()]);
            for (k, sim) in sims.iter().enumerate() {
                row[k].add(eval::score_joints(&best_matches(sim), truth, &mirror));
            }
        }
        // Frames: the clip against a time-warped copy of itself.
        let (warped, truth) = eval::time_warp(&clip.motion, 0.5);
        if let Ok(w) = extract_all(&model, &clip.skeleton, &warped, &clip.name) {
            // Feature frame k is BVH frame k; the last BVH frame has no features.
            let n = w.shifted[0].frames();
            let truth = &truth[..n];
            let mut sims: Vec<Vec<Vec<f64>>> = (0..SETTINGS.len())
                .flat_map(|k| [false, true].map(move |same| (k, same)))
                .map(|(k, same)| {
                    let (r, t) = dift::frame_descriptors(&reference.shifted[k], &w.shifted[k], same);
                    cosine_matrix(&t, &r)
                })
                .collect();
            sims.push(cosine_matrix(&w.raw_frames, &reference.raw_frames));
            let unmatched = truth.iter().enumerate().map(|(k, x)| (k as f64 - x).abs()).sum::<f64>() / n.max(1) as f64;
            for (align, matcher) in [("nearest", best_matches as fn(&[Vec<f64>]) -> Vec<_>), ("monotonic", correspond::monotonic_matches)] {
                let mut errors: Vec<f64> = sims.iter().map(|sim| eval::frame_error(&matcher(sim), truth)).collect();
                errors.push(unmatched);
                let row = frames.entry((clip.set.to_string(), align)).or_insert_with(|| vec![(0.0, 0); errors.len()]);
                for (r, e) in row.iter_mut().zip(errors) {
                    r.0 += e;
                    r.1 += 1;
                }
            }
        }
    }

    println!("\n## Joint correspondence: top-1 accuracy % (left/right confusions among the errors)\n");
    println!("| clips | target | {} |", methods.join(" | "));
    println!("|---|---|{}", "---|".repeat(methods.len()));
    for ((set, kind), row) in &joints {
        let cells: Vec<String> = row.iter().map(|a| format!("{:.1} ({})", 100.0 * a.rate(), a.left_right)).collect();
        println!("| {set} | {kind} (n = {}) | {} |", row[0].total, cells.join(" | "));
    }
    println!("\n## Frame correspondence against a time-warped copy (warp strength 0.5): mean frame error\n");
    let frame_methods: Vec<String> = SETTINGS
        .iter()
        .flat_map(|(t, l)| [format!("joint mean t{t} l{l}"), format!("joints side by side t{t} l{l}")])
        .chain(["raw features".into(), "no matching (k -> k)".into()])
        .collect();
    println!("| clips | matching | {} |", frame_methods.join(" | "));
    println!("|---|---|{}", "---|".repeat(frame_methods.len()));
    for ((set, align), row) in &frames {
        let cells: Vec<String> = row.iter().map(|(s, n)| format!("{:.2}", s / (*n).max(1) as f64)).collect();
        println!("| {set} (n = {}) | {align} | {} |", row[0].1, cells.join(" | "));
    }
    println!("\n## Extraction time per clip (one setting, {DRAWS} draws; median over settings is not taken: mean)\n");
    println!("| clip | frames | joints | seconds |");
    println!("|---|---|---|---|");
    for (name, f, j, s) in &timing {
        println!("| {name} | {f} | {j} | {s:.3} |");
    }
}
