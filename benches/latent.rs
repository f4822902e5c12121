//! The latent model (SATA, issue 9) measured: reconstruction (JR, RT, JP, FS, GP) against the
//! mean-pose baseline, retargeting error onto `skel-aug` variants (SAN's 1000 x MSE / height²)
//! where the variant's motion is the ground truth, topology independence of the latents (the
//! same motion from a skeleton and from its variants vs other motions), and encode + decode
//! time of a 1000-frame clip.
//!
//!     cargo bench --bench latent                                    # built-in model
//!     MENAGERIE_LATENT_MODELS="zoo=DIR,corpus=DIR" MENAGERIE_ZOO=/work/zoo cargo bench --bench latent
//!
//! Clip sets: `MENAGERIE_ZOO` (a training zoo from `cargo run --example zoo -- --training DIR`):
//! the held-out `walk_stop_walk_0.bvh` of every `*_v0` skeleton (seen skeletons, unseen clip)
//! and every clip of `dragon_v7` (a skeleton held out of training); without it, the creatures
//! of examples/data. The corpus (../shared/data/bvh, when present): the clips the corpus model
//! was trained without (`CORPUS_HELD_OUT`) and the Monkey (a skeleton it never saw). Clips are
//! cut to their first `MAX_FRAMES` frames.
mod common;

use candle_core::Device;
use menagerie::augment::{self, RemoveAmount};
use menagerie::bvh;
use menagerie::document::AnyTopSection;
use menagerie::embed::NameTable;
use menagerie::metrics::physics::PhysicsOptions;
use menagerie::metrics::reconstruction::{reconstruction, rotation_joints, ReconstructionReport, Rotations};
use menagerie::metrics::WorldClip as MetricClip;
use menagerie::motion::Motion;
use menagerie::repr::anytop::{Placement, RestSource, RigOptions};
use menagerie::repr::Features;
use menagerie::rng::SplitMix64;
use menagerie::sata::checkpoint::{self, FrozenAutoencoder};
use menagerie::sata::infer::{Latents, PreparedSkeleton};
use menagerie::skeleton::Skeleton;
use std::path::{Path, PathBuf};
use std::time::Instant;

const MAX_FRAMES: usize = 600;
/// Held out of the corpus model's training (`mo-train` was given every other corpus BVH).
const CORPUS_HELD_OUT: [&str; 6] = [
    "bandai_namco/dataset-2/dataset-2_walk_normal_001.bvh",
    "cmu_bvh11/131_03.bvh",
    "dog_mann/Dog/D1_010_KAN01_002.bvh",
    "lafan1/walk4_subject1.bvh",
    "xia_dme/old_13_000.bvh",
    "truebones_anytop/Chicken/Chicken_Walk.bvh",
];
const CORPUS_UNSEEN: [&str; 1] = ["truebones_motion2motion/Monkey/__Walk.bvh"];

struct Clip {
    name: String,
    skeleton: Skeleton,
    motion: Motion,
    /// For a skel-aug variant: its original's rest pose, augmented the same way, so its rig
    /// is measured from the same pose as the original's (else: the clip's first frame).
    rest: Option<Motion>,
}

fn read(path: &Path) -> Option<Clip> {
    let parsed = bvh::read_path(path).ok()?;
    let skeleton = Skeleton::from_bvh(&parsed);
    skeleton.validate().ok()?;
    let motion = Motion::from_bvh(&parsed, &skeleton).first_frames(MAX_FRAMES);
    let name = path.strip_prefix(path.ancestors().nth(2)?).ok()?.to_string_lossy().into_owned();
    (motion.frames >= 20).then_some(Clip { name, skeleton, motion, rest: None })
}

/// (set name, clips).
fn sets() -> Vec<(String, Vec<Clip>)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    match std::env::var_os("MENAGERIE_ZOO").map(PathBuf::from) {
        Some(zoo) => {
            let mut seen: Vec<PathBuf> = std::fs::read_dir(&zoo)
                .into_iter()
                .flatten()
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.to_string_lossy().ends_with("_v0"))
                .map(|p| p.join("walk_stop_walk_0.bvh"))
                .collect();
            seen.sort();
            out.push(("zoo: held-out clips, seen skeletons".to_string(), seen.iter().filter_map(|p| read(p)).collect::<Vec<_>>()));
            out.push(("zoo: unseen skeleton (dragon_v7)".to_string(), common::bvh_files(&zoo.join("dragon_v7")).iter().filter_map(|p| read(p)).collect()));
        }
        None => out.push(("examples/data creatures".to_string(), common::bvh_files(&root.join("examples/data")).iter().filter_map(|p| read(p)).collect())),
    }
    let corpus = root.join("../shared/data/bvh");
    if corpus.is_dir() {
        out.push(("corpus: held-out clips".to_string(), CORPUS_HELD_OUT.iter().filter_map(|p| read(&corpus.join(p))).collect()));
        out.push(("corpus: unseen skeleton (Monkey)".to_string(), CORPUS_UNSEEN.iter().filter_map(|p| read(&corpus.join(p))).collect()));
    } else {
        println!("(../shared/data/bvh absent: corpus sets skipped)");
    }
    out.retain(|(_, clips)| !clips.is_empty());
    out
}

fn models(device: &Device) -> Vec<(String, FrozenAutoencoder)> {
    let spec = std::env::var("MENAGERIE_LATENT_MODELS").unwrap_or_else(|_| "builtin=".to_string());
    spec.split(',')
        .filter(|s| !s.is_empty())
        .map(|item| {
            let (name, dir) = item.split_once('=').unwrap_or(("model", item));
            let model = if dir.is_empty() { checkpoint::frozen_default(device) } else { checkpoint::frozen(Path::new(dir), device) };
            (name.to_string(), model.unwrap_or_else(|e| panic!("{item}: {e:#}")))
        })
        .collect()
}

/// A clip's features, placement and prepared graph.
struct Encoded {
    prepared: PreparedSkeleton,
    /// The clip's skeleton as the rig reads it (`KnownRig::fit`).
    skeleton: Skeleton,
    features: Features,
    placement: Placement,
}

/// A clip encoded for `model`: with the rig it was trained with when it knows the skeleton
/// (as `mo-encode --latent` does), else the clip's own.
fn encode(clip: &Clip, model: Option<&FrozenAutoencoder>, device: &Device) -> Option<Encoded> {
    let go = || -> anyhow::Result<Encoded> {
        let (section, skeleton) = match model.and_then(|m| m.rigs.find(&clip.skeleton)) {
            Some(known) => (known.section.clone(), known.fit(&clip.skeleton)),
            None => match &clip.rest {
                Some(rest) => {
                    let options = RigOptions { rest_source: RestSource::Explicit { file: format!("{} (augmented rest)", clip.name) }, ..RigOptions::default() };
                    (AnyTopSection::new(&clip.skeleton, rest, &options)?, clip.skeleton.clone())
                }
                None => (AnyTopSection::of_clip(&clip.skeleton, &clip.motion, &clip.name)?, clip.skeleton.clone()),
            },
        };
        let e = section.rig.encode(&skeleton, &clip.motion)?;
        let prepared = PreparedSkeleton::new(&skeleton, section, NameTable::builtin()?, device)?;
        Ok(Encoded { prepared, skeleton, features: e.features, placement: e.placement })
    };
    go().map_err(|e| println!("(skipped {}: {e:#})", clip.name)).ok()
}

/// Every frame replaced by the clip's mean feature row: a still mean pose drifting at the mean
/// velocity, the trivial reconstruction.
fn mean_pose(f: &Features) -> Features {
    let width = f.joints * f.dims;
    let mut mean = vec![0f64; width];
    for row in f.data.chunks_exact(width) {
        mean.iter_mut().zip(row).for_each(|(m, &v)| *m += v as f64 / f.frames as f64);
    }
    let row: Vec<f32> = mean.iter().map(|&v| v as f32).collect();
    Features { data: row.repeat(f.frames), ..f.clone() }
}

/// Score `features` (decoded on `target` at its true placement) against `truth`.
fn score(target: &Clip, enc: &Encoded, features: &Features) -> Option<ReconstructionReport> {
    let go = || -> anyhow::Result<ReconstructionReport> {
        let result = enc.prepared.section.rig.decode(&enc.skeleton, features, &enc.placement)?;
        let truth = target.motion.first_frames(result.frames);
        let counted = rotation_joints(&target.skeleton);
        let rotations = Rotations { reference: &truth.rotations, result: &result.rotations, counted };
        let a = MetricClip::from_motion(&target.skeleton, &truth);
        let b = MetricClip::from_motion(&target.skeleton, &result);
        Ok(reconstruction(&a, &b, Some(&rotations), target.skeleton.rest_height(), &PhysicsOptions::default())?)
    };
    go().map_err(|e| println!("(not scored {}: {e:#})", target.name)).ok()
}

#[derive(Default)]
struct Mean {
    jr: f64,
    rt: f64,
    jp: f64,
    fs: f64,
    gp: f64,
    san: f64,
    n: usize,
}

impl Mean {
    fn add(&mut self, r: &ReconstructionReport) {
        let measure = |m: &menagerie::metrics::physics::Measure| m.normalised;
        self.jr += r.jr.value().copied().unwrap_or(f64::NAN);
        self.rt += measure(&r.rt);
        self.jp += measure(&r.jp);
        self.fs += r.fs.value().map(measure).unwrap_or(0.0);
        self.gp += measure(&r.gp);
        self.san += r.retargeting_error;
        self.n += 1;
    }

    fn row(&self, label: &str) -> String {
        let n = self.n.max(1) as f64;
        format!(
            "| {label} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} |",
            self.n,
            self.jr / n,
            self.rt / n,
            self.jp / n,
            self.fs / n,
            self.gp / n,
            self.san / n
        )
    }
}

/// Mean distance between two latent sequences over their common frames.
fn distance(a: &Latents, b: &Latents) -> f64 {
    let n = a.frames.min(b.frames);
    let d = a.dims;
    (0..n).map(|f| a.data[f * d..(f + 1) * d].iter().zip(&b.data[f * d..(f + 1) * d]).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt()).sum::<f64>()
        / n.max(1) as f64
}

/// The first two frames of the clip `model` took `clip`'s rest pose from, when it knows the
/// skeleton and the file is readable (the frames `AnyTopSection` measures a rig on).
/// The clip comes back on the trained offsets (`KnownRig::fit`), the skeleton the rest fits.
fn trained_rest(model: &FrozenAutoencoder, clip: &Clip) -> Option<Clip> {
    let known = model.rigs.find(&clip.skeleton)?;
    let (RestSource::TPose { file } | RestSource::FirstClip { file } | RestSource::Explicit { file }) = &known.section.rig.rest_source else { return None };
    let parsed = bvh::read_path(Path::new(file)).ok()?;
    let rest = Motion::from_bvh(&parsed, &Skeleton::from_bvh(&parsed)).first_frames(2);
    (rest.joints == clip.skeleton.len()).then(|| Clip {
        name: clip.name.clone(),
        skeleton: known.fit(&clip.skeleton),
        motion: clip.motion.clone(),
        rest: Some(rest),
    })
}

/// The clip's rest frames, when it has them, are augmented along with it (see `Clip::rest`).
fn variants(clip: &Clip, count: usize, seed: u64) -> Vec<Clip> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|k| {
            let opts = augment::Options { remove: Some(RemoveAmount::Random), add: 2, keep_feet: true };
            let plan = augment::plan(&clip.skeleton, &opts, &mut rng);
            let motion = plan.apply_motion(&clip.skeleton, &clip.motion);
            let rest = clip.rest.as_ref().map(|r| plan.apply_motion(&clip.skeleton, r));
            Clip { name: format!("{}~v{k}", clip.name), skeleton: plan.skeleton, motion, rest }
        })
        .collect()
}

fn main() {
    let device = Device::Cpu;
    let models = models(&device);
    let sets = sets();
    println!("## Reconstruction (encode, decode on the same skeleton)\n");
    println!("JR radians; RT, JP, GP divided by the skeleton's height; FS in heights per second; SAN = 1000 x MSE / height².\n");
    println!("| model / set / method | clips | JR | RT | JP | FS | GP | SAN |\n|---|---|---|---|---|---|---|---|");
    let mut transfer_rows = Vec::new();
    let mut distance_rows = Vec::new();
    for (model_name, model) in &models {
        for (set_name, clips) in &sets {
            let (mut rec, mut base, mut truth_fs) = (Mean::default(), Mean::default(), Mean::default());
            let (mut retarget, mut retarget_base) = (Mean::default(), Mean::default());
            let (mut same, mut other, mut nearest, mut total) = (0.0, 0.0, 0usize, 0usize);
            let mut encoded_latents: Vec<(Latents, Vec<Latents>)> = Vec::new();
            for clip in clips {
                let Some(enc) = encode(clip, Some(model), &device) else { continue };
                let Ok(z) = model.encode_features(&enc.features, &enc.prepared.graph, &device) else { continue };
                let Ok(back) = model.decode_latents(&z, &enc.prepared.graph, &device) else { continue };
                if let Some(r) = score(clip, &enc, &back) {
                    rec.add(&r);
                    // The data's own FS / GP: the floor a reconstruction can reach.
                    truth_fs.fs += r.reference_fs.value().map(|m| m.normalised).unwrap_or(0.0);
                    truth_fs.gp += r.reference_gp.normalised;
                    truth_fs.n += 1;
                }
                if let Some(r) = score(clip, &enc, &mean_pose(&enc.features)) {
                    base.add(&r);
                }
                // Onto skel-aug variants, whose own motion is the ground truth.
                let mut variant_latents = Vec::new();
                let base = trained_rest(model, clip);
                for v in variants(base.as_ref().unwrap_or(clip), 2, 11) {
                    let Some(venc) = encode(&v, Some(model), &device) else { continue };
                    if let Ok(on_v) = model.decode_latents(&z, &venc.prepared.graph, &device) {
                        if let Some(r) = score(&v, &venc, &on_v) {
                            retarget.add(&r);
                        }
                    }
                    if let Some(r) = score(&v, &venc, &mean_pose(&venc.features)) {
                        retarget_base.add(&r);
                    }
                    if let Ok(zv) = model.encode_features(&venc.features, &venc.prepared.graph, &device) {
                        variant_latents.push(zv);
                    }
                }
                encoded_latents.push((z, variant_latents));
            }
            // Topology independence: a clip's variants against the other clips of the set.
            for (i, (z, vs)) in encoded_latents.iter().enumerate() {
                for zv in vs {
                    let d_same = distance(z, zv);
                    let others: Vec<f64> = encoded_latents.iter().enumerate().filter(|(k, _)| *k != i).map(|(_, (o, _))| distance(zv, o)).collect();
                    if others.is_empty() {
                        continue;
                    }
                    same += d_same;
                    other += others.iter().sum::<f64>() / others.len() as f64;
                    nearest += usize::from(others.iter().all(|&o| d_same < o));
                    total += 1;
                }
            }
            println!("{}", rec.row(&format!("{model_name} / {set_name} / SATA")));
            println!("{}", base.row(&format!("{model_name} / {set_name} / mean pose")));
            let n = truth_fs.n.max(1) as f64;
            println!("| {model_name} / {set_name} / the data itself | {} | 0 | 0 | 0 | {:.4} | {:.4} | 0 |", truth_fs.n, truth_fs.fs / n, truth_fs.gp / n);
            transfer_rows.push(retarget.row(&format!("{model_name} / {set_name} / SATA")));
            transfer_rows.push(retarget_base.row(&format!("{model_name} / {set_name} / variant's mean pose")));
            let t = total.max(1) as f64;
            distance_rows.push(format!(
                "| {model_name} / {set_name} | {total} | {:.3} | {:.3} | {:.2} | {:.0}% |",
                same / t,
                other / t,
                (same / t) / (other / t).max(1e-12),
                100.0 * nearest as f64 / t
            ));
        }
    }
    println!("\n## Retargeting onto skel-aug variants (ground truth: the variant's own motion)\n");
    println!("| model / set / method | pairs | JR | RT | JP | FS | GP | SAN |\n|---|---|---|---|---|---|---|---|");
    transfer_rows.iter().for_each(|r| println!("{r}"));
    ground_truth_pairs(&models, &device);
    println!("\n## Topology independence of the latents\n");
    println!("Mean per-frame L2 distance from a variant's latents to its original's (same motion, other skeleton) and to the other clips of the set; 'nearest' = the original is the closest clip.\n");
    println!("| model / set | variants | same motion | other motions | ratio | nearest |\n|---|---|---|---|---|---|");
    distance_rows.iter().for_each(|r| println!("{r}"));
    speed(&models, &device);
}

/// Corpus pairs of one motion on two skeletons: CMU 131_01 and its scaled copy (same topology,
/// other proportions). SAN error of SATA's transfer against the target's mean pose.
fn ground_truth_pairs(models: &[(String, FrozenAutoencoder)], device: &Device) {
    let mut rows = Vec::new();
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bvh");
    let pairs = [("cmu_bvh11/131_01.bvh", "cmu_bvh11/scaled_131_01.bvh")];
    for (a, b) in pairs {
        let (Some(src), Some(dst)) = (read(&corpus.join(a)), read(&corpus.join(b))) else { continue };
        for (name, model) in models {
            let (Some(se), Some(de)) = (encode(&src, Some(model), device), encode(&dst, Some(model), device)) else { continue };
            let Ok(z) = model.encode_features(&se.features, &se.prepared.graph, device) else { continue };
            let Ok(on) = model.decode_latents(&z, &de.prepared.graph, device) else { continue };
            let mut m = Mean::default();
            let mut base = Mean::default();
            if let Some(r) = score(&dst, &de, &on) {
                m.add(&r);
            }
            if let Some(r) = score(&dst, &de, &mean_pose(&de.features)) {
                base.add(&r);
            }
            rows.push(m.row(&format!("{name} / {a} -> {b} / SATA")));
            rows.push(base.row(&format!("{name} / {a} -> {b} / target's mean pose")));
        }
    }
    if !rows.is_empty() {
        println!("\n## Retargeting between corpus skeletons with a ground truth\n");
        println!("| model / pair / method | pairs | JR | RT | JP | FS | GP | SAN |\n|---|---|---|---|---|---|---|---|");
        rows.iter().for_each(|r| println!("{r}"));
    }
}

/// Encode + decode of a 1000-frame clip (a synthetic quadruped clip repeated), median of runs.
fn speed(models: &[(String, FrozenAutoencoder)], device: &Device) {
    let (skeleton, motion) = menagerie::synth::creature("quadruped", 0).expect("synthetic quadruped");
    let n = motion.joints;
    let mut long = motion.clone();
    while long.frames < 1001 {
        long.rotations.extend_from_slice(&motion.rotations);
        long.translations.extend_from_slice(&motion.translations);
        long.frames += motion.frames;
    }
    let long = long.first_frames(1001);
    let clip = Clip { name: "quadruped x1000".into(), skeleton, motion: long, rest: None };
    let enc = encode(&clip, None, device).expect("encodable");
    println!("\n## Speed: 1000 frames, {n} joints (encode + decode, median of {} runs)\n", common::RUNS);
    println!("| model | encode ms | decode ms | total ms | frames/s |\n|---|---|---|---|---|");
    for (name, model) in models {
        let mut e = Vec::new();
        let mut d = Vec::new();
        for _ in 0..common::RUNS {
            let t = Instant::now();
            let z = model.encode_features(&enc.features, &enc.prepared.graph, device).expect("encode");
            e.push(t.elapsed());
            let t = Instant::now();
            model.decode_latents(&z, &enc.prepared.graph, device).expect("decode");
            d.push(t.elapsed());
        }
        let (me, md) = (common::ms(common::median(&e)), common::ms(common::median(&d)));
        println!("| {name} | {me:.0} | {md:.0} | {:.0} | {:.0} |", me + md, 1000.0 / ((me + md) / 1e3));
    }
}
