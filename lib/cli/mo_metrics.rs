//! `mo-metrics`: the evaluation metrics of AnyTop, Motion2Motion and SATA, and physical
//! plausibility for any motion. This file only loads motion (BVH or NPY + skeleton, through
//! `cli::load`), turns it into `metrics::Clip`s with our FK, calls `lib/metrics`, and prints
//! JSON (every number named, units in a `units` table) or a table for humans.
//! Definitions and deviations: docs/metrics.md.

use crate::binding::Binding;
use crate::cli::bounds;
use crate::cli::load::{expand_inputs, load_motions, read_skeleton, DecodeFrom, LoadOptions, Loaded};
use crate::cli::CommonOpts;
use crate::document::AnyTopSection;
use crate::io;
use crate::metrics::fid::{fid, FidOptions};
use crate::metrics::generation::{self, GenerationOptions, PointClip};
use crate::metrics::movement;
use crate::metrics::physics::{Ground, PhysicsOptions};
use crate::metrics::{geometric, kinetic, physics, reconstruction, transfer, Clip};
use crate::repr::anytop::AnyTopOptions;
use anyhow::{bail, Context};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-metrics physics examples/data/biped.bvh examples/data/quadruped.bvh --format table
    mo-metrics reconstruction --reference examples/data/dragon.bvh --result examples/data/dragon.bvh
    mo-metrics transfer --source examples/data/biped.bvh --result examples/data/biped.bvh
    mo-metrics generation --gt examples/data/quadruped.bvh --gen examples/data/quadruped.bvh
    mo-encode examples/data/crab.bvh | mo-metrics physics - --skeleton examples/data/crab.bvh
    mo-metrics ood examples/data/dragon.bvh examples/data/crab.bvh --format table";

/// Score motion: generation, transfer, reconstruction and physical-plausibility metrics.
///
/// One tool for \"is this motion any good?\" on any skeleton, with the metrics of the papers we
/// implement (definitions, sources and every deviation: docs/metrics.md):
///
/// generation: AnyTop's (after GANimator/SinMDM) coverage, local/global/inter/intra diversity
/// and intra-diversity difference of generated samples against the ground-truth clips of one
/// skeleton, on root-relative joint positions in AnyTop's units.
///
/// transfer: Motion2Motion's FID on kinetic features (and on the 32 geometric features when the
/// skeleton's human roles can be found), frequency alignment and contact consistency of each
/// result against its source through the binding, diversity between results, throughput.
///
/// reconstruction: SATA's (after SAME/SAN) JR (rad), RT, JP, FS, GP and the retargeting error
/// 1000 x MSE / height^2 of a result against a reference on the same skeleton.
///
/// physics: foot skating, ground penetration, floating and jitter of any motion, no ground
/// truth needed.
///
/// Inputs are BVH files, NPY feature files (AnyTop 13-D or Motion2Motion 9-D, batches too)
/// decoded on --skeleton, or directories of them. Output is JSON on stdout (every number named;
/// units in \"units\"), or --format table.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-metrics", version, after_long_help = EXAMPLES)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Json, global = true)]
    pub format: Format,
    /// Skeleton of NPY inputs: a skeleton document (skel-info) or a BVH file.
    #[arg(long, value_name = "PATH", global = true)]
    pub skeleton: Option<PathBuf>,
    /// AnyTop features: pose from their rotations or (generated clips) their positions by IK.
    #[arg(long, value_enum, value_name = "FROM", default_value_t = DecodeFrom::Rotations, global = true)]
    pub from: DecodeFrom,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Json,
    Table,
}

#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// How far skeletons lie from a learned model's training skeletons (the out-of-distribution
    /// score behind the warning of mo-sample, mo-dift, mo-segment, mo-encode --latent and
    /// mo-retarget --method latent).
    ///
    /// Per skeleton: the score (the distance to the nearest training skeleton: graph, rest
    /// proportions and joint names, each about 0 for the same skeleton and 1 for unrelated
    /// ones), whether it is in range (score <= limit), the nearest training skeleton and the
    /// parts of the distance. With --verbose also each training skeleton's nearest other one.
    /// Definitions and the calibration of the limit: docs/ood.md.
    Ood {
        /// Skeletons: BVH files or skeleton documents.
        #[arg(value_name = "SKELETON", required = true, num_args = 1..)]
        skeletons: Vec<PathBuf>,
        /// Model directory [default: the built-in diffusion model, or with --latent the
        /// built-in latent model].
        #[arg(long, value_name = "DIR")]
        model: Option<PathBuf>,
        /// Score against a latent model (SATA: mo-encode --latent, mo-retarget --method latent).
        #[arg(long)]
        latent: bool,
    },
    /// AnyTop's generation metrics: generated samples against ground-truth clips of one skeleton.
    ///
    /// Features per frame: the positions of joints 1..J-1 relative to the root (x, z
    /// root-relative in the clip's facing frame, y minus the root height), in AnyTop's scaled
    /// units, as the reference computes them from its 13-D features. Coverage (%) counts the
    /// ground-truth windows of --window frames that some generated window matches within
    /// --threshold (mean joint distance); local diversity is the mean distance of generated
    /// windows to their nearest ground-truth window; global diversity the cost of the best
    /// segmentation of each sample into ground-truth segments of at least --min-segment frames
    /// per frame; inter diversity the distance between consecutive samples; intra diversity
    /// the distance between two random windows of a sample, and its difference from the ground
    /// truth's. Values are mean and std over samples.
    ///
    /// The `movement` block tells a statue from a walk, for the samples and for three
    /// baselines made from the ground truth (its clips each left out in turn, their static mean
    /// pose, random crops): motion energy (joint speed relative to the root, body sizes per
    /// second) and its ratio to the clips', the distance of each pose to the nearest clip pose,
    /// coverage with thresholds calibrated on the clips, and foot contact (duty factor, share
    /// of frames with some feet down and some up). Definitions: docs/metrics.md.
    Generation {
        /// Ground-truth clips (files or directories).
        #[arg(long, value_name = "PATH", required = true, num_args = 1..)]
        gt: Vec<PathBuf>,
        /// Generated samples (files or directories; an NPY batch gives one sample per row).
        #[arg(long = "gen", value_name = "PATH", required = true, num_args = 1..)]
        generated: Vec<PathBuf>,
        /// Window length of coverage and local diversity, in frames.
        #[arg(long, value_name = "FRAMES", default_value_t = 15, value_parser = bounds::count(0, bounds::MAX_FRAMES))]
        window: usize,
        /// Coverage threshold on the mean joint distance (AnyTop's units).
        #[arg(long, value_name = "D", default_value_t = 0.349)]
        threshold: f64,
        /// Shortest segment of the global-diversity segmentation, in frames.
        #[arg(long, value_name = "FRAMES", default_value_t = 30, value_parser = bounds::count(0, bounds::MAX_FRAMES))]
        min_segment: usize,
    },
    /// Motion2Motion's transfer metrics: results against their source and the target's examples.
    ///
    /// FID_k: Fréchet distance between the kinetic features (per joint: horizontal and vertical
    /// kinetic energy, energy expenditure) of the examples (real set) and of the results,
    /// normalised by the real set's mean and std. FID_g: the same on the 32 geometric features,
    /// only when the target's human roles (hips, knees, ankles, shoulders, elbows, wrists, neck)
    /// can be found by name. Frequency alignment: cosine similarity of the power spectra of
    /// bound joints, source vs result. Contact consistency: agreement of the foot contacts of
    /// bound feet. Diversity: mean joint distance between results (needs two or more).
    /// Throughput: result frames per second when --seconds gives the time they took.
    Transfer {
        /// The source motion.
        #[arg(long, value_name = "PATH")]
        source: PathBuf,
        /// Result motions on the target skeleton (files or directories).
        #[arg(long, value_name = "PATH", required = true, num_args = 1..)]
        result: Vec<PathBuf>,
        /// Binding source joint -> target joint (ours or the reference's mapping JSON)
        /// [default: joints with the same (normalised) names].
        #[arg(long, value_name = "JSON")]
        binding: Option<PathBuf>,
        /// The target's example clips, the real set of the FIDs (files or directories).
        #[arg(long, value_name = "PATH", num_args = 1..)]
        examples: Vec<PathBuf>,
        /// Seconds the results took to make (for throughput).
        #[arg(long, value_name = "S")]
        seconds: Option<f64>,
        /// Cut examples and results into windows of this many frames for the FIDs (a set of
        /// one or two clips has no covariance; the windows make sets). 0 = whole clips.
        #[arg(long, value_name = "FRAMES", default_value_t = 0, value_parser = bounds::count(0, bounds::MAX_FRAMES))]
        fid_window: usize,
    },
    /// SATA's reconstruction metrics: a result against a reference motion on the same skeleton.
    ///
    /// JR: mean geodesic angle between local joint rotations (rad), over joints that have
    /// children. RT: mean distance between root positions. JP: mean joint position distance. FS
    /// and GP: foot skating and ground penetration of the result. Retargeting error: 1000 x mean
    /// squared joint position error / height^2 (SAN/SAME). Lengths are in the reference's
    /// units; --height overrides the skeleton's rest height.
    Reconstruction {
        /// The ground truth.
        #[arg(long, value_name = "PATH")]
        reference: PathBuf,
        /// The motion to score (same skeleton, same frame count).
        #[arg(long, value_name = "PATH")]
        result: PathBuf,
        /// Height used by the retargeting error [default: the reference skeleton's rest height].
        #[arg(long, value_name = "H")]
        height: Option<f64>,
    },
    /// The paper's table row: mean and std over skeletons of per-skeleton generation results.
    ///
    /// Reads the JSON reports `mo-metrics generation` printed (one per skeleton) and gives, for
    /// every metric, the mean and std over skeletons of the per-skeleton means, as AnyTop's
    /// tables report them.
    Aggregate {
        /// Generation reports (JSON files, '-' = stdin).
        #[arg(value_name = "REPORT", required = true, num_args = 1..)]
        reports: Vec<PathBuf>,
    },
    /// Physical plausibility of any motion: foot skating, ground penetration, floating, jitter.
    ///
    /// A foot is in contact when it is within --contact-height x the skeleton's size of the
    /// ground and slower than --contact-speed x size per second. Foot skating: mean horizontal
    /// speed of feet in contact. Ground penetration: mean depth below the ground over joints and
    /// frames. Floating: mean height of the lowest foot over frames where no foot touches.
    /// Jitter: mean jerk magnitude (third derivative of position). Skeletons without feet get
    /// \"not_applicable\" with the reason for the foot-based values.
    Physics {
        /// Motion files or directories.
        #[arg(value_name = "INPUT", default_value = "-")]
        inputs: Vec<PathBuf>,
        /// Ground: 'zero' (y = 0), 'estimate' (lowest foot height over the clip) or a height.
        #[arg(long, value_name = "G", default_value = "zero", value_parser = parse_ground)]
        ground: GroundArg,
        /// Contact height threshold, as a fraction of the skeleton's size.
        #[arg(long, value_name = "F", default_value_t = 0.05, allow_negative_numbers = true)]
        contact_height: f64,
        /// Contact speed threshold, as a fraction of the skeleton's size per second.
        #[arg(long, value_name = "F", default_value_t = 0.5, allow_negative_numbers = true)]
        contact_speed: f64,
    },
}

/// `--ground`, kept as a clap value.
#[derive(Clone, Copy, Debug)]
pub enum GroundArg {
    Zero,
    Estimate,
    Height(f64),
}

pub fn parse_ground(s: &str) -> Result<GroundArg, String> {
    match s {
        "zero" => Ok(GroundArg::Zero),
        "estimate" => Ok(GroundArg::Estimate),
        h => match h.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(GroundArg::Height(v)),
            _ => Err(format!("expected zero, estimate or a height, found '{s}'")),
        },
    }
}

impl GroundArg {
    fn ground(self) -> Ground {
        match self {
            GroundArg::Zero => Ground::Zero,
            GroundArg::Estimate => Ground::Estimate,
            GroundArg::Height(h) => Ground::Height(h),
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let started = std::time::Instant::now();
    let report = match &args.command {
        Command::Physics { inputs, ground, contact_height, contact_speed } => {
            let opts = physics_options(*ground, *contact_height, *contact_speed)?;
            run_physics(args, inputs, &opts)?
        }
        Command::Reconstruction { reference, result, height } => run_reconstruction(args, reference, result, *height)?,
        Command::Transfer { source, result, binding, examples, seconds, fid_window } => {
            run_transfer(args, source, result, binding.as_deref(), examples, *seconds, *fid_window)?
        }
        Command::Aggregate { reports } => run_aggregate(reports)?,
        Command::Ood { skeletons, model, latent } => run_ood(args, skeletons, model.as_deref(), *latent)?,
        Command::Generation { gt, generated, window, threshold, min_segment } => {
            let opts =
                GenerationOptions { window: *window, threshold: *threshold, min_segment: *min_segment, seed: args.common.seed, ..GenerationOptions::default() };
            run_generation(args, gt, generated, &opts)?
        }
    };
    if args.common.verbose {
        eprintln!("mo-metrics: done in {:.3} s", started.elapsed().as_secs_f64());
    }
    let text = match args.format {
        Format::Json => serde_json::to_string_pretty(&report).context("building the JSON")? + "\n",
        Format::Table => table(&report),
    };
    Ok(io::write_output(args.common.output.as_deref(), text.as_bytes())?)
}

fn run_ood(args: &Args, skeletons: &[PathBuf], model: Option<&Path>, latent: bool) -> anyhow::Result<Value> {
    let device = candle_core::Device::Cpu;
    let known = if latent {
        super::ood::Known::latent(model, &super::latent::load_model(model, &device)?.rigs)?
    } else {
        super::ood::Known::denoiser(model, &crate::diffusion::checkpoint::frozen_or_default(model, &device)?.info)?
    };
    if known.reference.profiles.is_empty() {
        bail!("{} records no training skeletons to compare with", known.model);
    }
    let mut scored = Vec::new();
    for path in skeletons {
        let arg = read_skeleton(path)?;
        scored.push(json!({ "skeleton": arg.name, "ood": known.score(&arg.name, &arg.skeleton)? }));
    }
    let mut report = json!({ "model": known.model, "limit": crate::ood::LIMIT, "skeletons": scored });
    if args.common.verbose {
        let within: Vec<Value> = known.reference.nearest_within().into_iter().map(|(a, b, d)| json!({ "skeleton": a, "nearest": b, "distance": d })).collect();
        report["training"] = Value::Array(within);
    }
    Ok(report)
}

pub fn physics_options(ground: GroundArg, contact_height: f64, contact_speed: f64) -> anyhow::Result<PhysicsOptions> {
    if !(contact_height.is_finite() && contact_height > 0.0) || !(contact_speed.is_finite() && contact_speed > 0.0) {
        bail!("--contact-height and --contact-speed must be positive numbers");
    }
    Ok(PhysicsOptions { contact_height, contact_speed, ground: ground.ground() })
}

fn load(args: &Args, inputs: &[PathBuf]) -> anyhow::Result<Vec<Loaded>> {
    let files = expand_inputs(inputs)?;
    let options = LoadOptions { skeleton: args.skeleton.as_deref(), from: Some(args.from) };
    let loaded = load_motions(&files, &options)?;
    if loaded.is_empty() {
        bail!("no motion in {}", inputs.iter().map(|p| io::display_name(p)).collect::<Vec<_>>().join(", "));
    }
    Ok(loaded)
}

fn load_one(args: &Args, path: &Path) -> anyhow::Result<Loaded> {
    let mut loaded = load(args, &[path.to_path_buf()])?;
    if loaded.len() != 1 {
        bail!("{}: expected one motion, found {} (an NPY batch?)", io::display_name(path), loaded.len());
    }
    Ok(loaded.remove(0))
}

/// A loaded motion as world positions, with a defined error for non-finite values.
fn clip_of(l: &Loaded) -> anyhow::Result<Clip> {
    let clip = Clip::from_motion(&l.skeleton, &l.motion);
    if let Some((f, j)) = clip.first_non_finite() {
        bail!("{}: non-finite position at frame {f}, joint {j} '{}'", l.name, l.skeleton.joints[j].name);
    }
    Ok(clip)
}

/// Units of every number the reports hold, by key.
fn units(keys: &[(&str, &str)]) -> Value {
    let mut m = Map::new();
    for (k, u) in keys {
        m.insert(k.to_string(), json!(u));
    }
    Value::Object(m)
}

fn run_physics(args: &Args, inputs: &[PathBuf], opts: &PhysicsOptions) -> anyhow::Result<Value> {
    use rayon::prelude::*;
    let loaded = load(args, inputs)?;
    let reports: Vec<anyhow::Result<Value>> = loaded
        .par_iter()
        .map(|l| {
            let clip = clip_of(l)?;
            let report = physics::physics(&clip, opts).with_context(|| l.name.clone())?;
            let mut v = serde_json::to_value(&report)?;
            if let Value::Object(m) = &mut v {
                m.insert("file".into(), json!(l.name));
            }
            Ok(v)
        })
        .collect();
    let files = reports.into_iter().collect::<anyhow::Result<Vec<Value>>>()?;
    Ok(json!({
        "metric": "physics",
        "files": files,
    }))
}

fn run_reconstruction(args: &Args, reference: &Path, result: &Path, height: Option<f64>) -> anyhow::Result<Value> {
    let mut a = load_one(args, reference)?;
    let b = load_one(args, result)?;
    if a.skeleton.len() != b.skeleton.len() {
        bail!("{} has {} joints but {} has {}: reconstruction compares motions on one skeleton", a.name, a.skeleton.len(), b.name, b.skeleton.len());
    }
    // Features (and latents) of an F-frame clip describe F - 1 frames: the last one only gives
    // velocities. So every encode -> decode round trip is one frame short; compare what it has.
    if b.motion.frames + 1 == a.motion.frames {
        if !args.common.quiet {
            eprintln!("mo-metrics: note: {} has one frame fewer than {} (a decoded round trip); comparing its {} frames", b.name, a.name, b.motion.frames);
        }
        a.motion = a.motion.first_frames(b.motion.frames);
    }
    if a.motion.frames != b.motion.frames {
        bail!("{} has {} frames but {} has {}: reconstruction compares frame by frame", a.name, a.motion.frames, b.name, b.motion.frames);
    }
    let height = match height {
        Some(h) if h.is_finite() && h > 0.0 => h,
        Some(h) => bail!("--height must be a positive number, found {h}"),
        None => a.skeleton.rest_height(),
    };
    let (ca, cb) = (clip_of(&a)?, clip_of(&b)?);
    let counted = reconstruction::rotation_joints(&a.skeleton);
    let rotations = reconstruction::Rotations { reference: &a.motion.rotations, result: &b.motion.rotations, counted };
    let report =
        reconstruction::reconstruction(&ca, &cb, Some(&rotations), height, &PhysicsOptions::default()).with_context(|| format!("{} vs {}", a.name, b.name))?;
    Ok(json!({
        "metric": "reconstruction",
        "reference": a.name,
        "result": b.name,
        "report": report,
    }))
}

fn run_transfer(
    args: &Args,
    source: &Path,
    results: &[PathBuf],
    binding: Option<&Path>,
    examples: &[PathBuf],
    seconds: Option<f64>,
    fid_window: usize,
) -> anyhow::Result<Value> {
    let src = load_one(args, source)?;
    let results = load(args, results)?;
    let target = &results[0];
    for r in &results[1..] {
        if r.skeleton.len() != target.skeleton.len() {
            bail!("{} has {} joints but {} has {}: all results must be on one skeleton", r.name, r.skeleton.len(), target.name, target.skeleton.len());
        }
    }
    let pairs: Vec<(usize, usize)> = match binding {
        Some(path) => {
            let name = io::display_name(path);
            let text =
                String::from_utf8(io::read_input(path).with_context(|| format!("cannot read {name}"))?).map_err(|_| anyhow::anyhow!("{name}: not UTF-8"))?;
            let b = Binding::from_json(&text, &name)?;
            b.resolve(&name, &src.skeleton, &src.name, &target.skeleton, &target.name)?
        }
        None => same_name_pairs(&src, target),
    };
    if pairs.is_empty() {
        bail!("{} and {} share no joint names: give --binding", src.name, target.name);
    }
    let src_clip = clip_of(&src)?;
    let clips = results.iter().map(clip_of).collect::<anyhow::Result<Vec<Clip>>>()?;
    let mut per_result = Vec::new();
    for (l, c) in results.iter().zip(&clips) {
        let freq = transfer::frequency_alignment(&src_clip, c, &pairs).with_context(|| l.name.clone())?;
        let contact = transfer::contact_consistency(&src_clip, c, &pairs, &PhysicsOptions::default()).with_context(|| l.name.clone())?;
        let motion = transfer::motion_ratio(&src_clip, c, &pairs).with_context(|| l.name.clone())?;
        per_result.push(json!({ "file": l.name, "frequency_alignment": freq, "contact_consistency": contact, "motion_ratio": motion }));
    }
    let mut out = json!({
        "metric": "transfer",
        "source": src.name,
        "bound_pairs": pairs.len(),
        "results": per_result,
    });
    let m = out.as_object_mut().expect("object");
    m.insert(
        "diversity".into(),
        match transfer::diversity(&clips) {
            Ok(d) => serde_json::to_value(d)?,
            Err(e) => json!({ "not_applicable": e.to_string() }),
        },
    );
    if let Some(s) = seconds {
        let frames: usize = clips.iter().map(|c| c.frames).sum();
        m.insert("throughput".into(), json!(transfer::throughput(frames, s)?));
    }
    if !examples.is_empty() {
        let ex = load(args, examples)?;
        for e in &ex {
            if e.skeleton.len() != target.skeleton.len() {
                bail!(
                    "example {} has {} joints but the results have {}: the examples are clips of the target skeleton",
                    e.name,
                    e.skeleton.len(),
                    target.skeleton.len()
                );
            }
        }
        let ex_clips = ex.iter().map(clip_of).collect::<anyhow::Result<Vec<Clip>>>()?;
        let (ex_sets, result_sets) = (windows(&ex_clips, fid_window), windows(&clips, fid_window));
        let kin = |cs: &[Clip]| -> anyhow::Result<Vec<Vec<f64>>> { cs.iter().map(|c| kinetic::kinetic_features(c).context("kinetic features")).collect() };
        m.insert("fid_kinetic".into(), fid_value(&kin(&ex_sets)?, &kin(&result_sets)?)?);
        let fid_g = match geometric::human_roles(&clips[0]) {
            Ok(roles) => {
                let opts = geometric::GeometricOptions::default();
                let g = |cs: &[Clip]| -> anyhow::Result<Vec<Vec<f64>>> { cs.iter().map(|c| Ok(geometric::geometric_features(c, &roles, &opts)?)).collect() };
                fid_value(&g(&ex_sets)?, &g(&result_sets)?)?
            }
            Err(why) => json!({ "not_applicable": format!("no human roles on the target skeleton: {why}") }),
        };
        m.insert("fid_geometric".into(), fid_g);
    }
    m.insert(
        "units".into(),
        units(&[
            ("frequency_alignment", "cosine similarity in [0, 1]"),
            ("contact_consistency", "fraction of frames in [0, 1]"),
            ("motion_ratio", "result speed over source speed, each per skeleton size (1 = moves as much)"),
            ("diversity", "target length units"),
            ("throughput", "result frames per second"),
            ("fid_kinetic", "Fréchet distance of normalised features (dimensionless)"),
            ("fid_geometric", "Fréchet distance of normalised features (dimensionless)"),
        ]),
    );
    Ok(out)
}

/// Clips cut into consecutive windows of `len` frames (the remainder dropped); `len` 0 keeps
/// whole clips.
fn windows(clips: &[Clip], len: usize) -> Vec<Clip> {
    if len == 0 {
        return clips.to_vec();
    }
    let mut out = Vec::new();
    for c in clips {
        for k in 0..c.frames / len {
            let mut w = c.clone();
            w.frames = len;
            w.positions = c.positions[k * len * c.joints..(k + 1) * len * c.joints].to_vec();
            out.push(w);
        }
    }
    out
}

/// FID, or why it has no value (too few clips), as JSON.
fn fid_value(real: &[Vec<f64>], generated: &[Vec<f64>]) -> anyhow::Result<Value> {
    // One vector has no covariance: the distance would only say the two means differ, and
    // normalising by the real set's spread is impossible.
    if real.len() < 2 || generated.len() < 2 {
        return Ok(json!({ "not_applicable": format!(
            "FID needs at least 2 real and 2 generated clips, found {} and {}: give more clips or --fid-window FRAMES",
            real.len(),
            generated.len()
        ) }));
    }
    Ok(match fid(real, generated, &FidOptions::default()) {
        Ok(f) => serde_json::to_value(f)?,
        Err(crate::metrics::MetricError::TooLittle(why)) => json!({ "not_applicable": why }),
        Err(e) => return Err(e.into()),
    })
}

/// Joints of the target whose normalised name matches a source joint's.
fn same_name_pairs(src: &Loaded, tgt: &Loaded) -> Vec<(usize, usize)> {
    use crate::skeleton::lookup::find_joint;
    (0..src.skeleton.len()).filter_map(|i| find_joint(&tgt.skeleton, &src.skeleton.joints[i].name).ok().map(|j| (i, j))).collect()
}

fn run_generation(args: &Args, gt: &[PathBuf], generated: &[PathBuf], opts: &GenerationOptions) -> anyhow::Result<Value> {
    let gt = load(args, gt)?;
    let gen = load(args, generated)?;
    let first = &gt[0];
    for l in gt.iter().chain(&gen) {
        if l.skeleton.len() != first.skeleton.len() || l.skeleton.joints.iter().zip(&first.skeleton.joints).any(|(a, b)| a.parent != b.parent) {
            bail!("{} and {} are not on the same skeleton: generation metrics compare clips of one skeleton", l.name, first.name);
        }
    }
    // One rig for all clips, so positions share AnyTop's scale: the skeleton's own record
    // (--skeleton), else one built on the first ground-truth clip as AnyTop would.
    let section = match &args.skeleton {
        Some(p) => read_skeleton(p)?.record()?,
        None => AnyTopSection::new(&first.skeleton, &first.motion.first_frames(2), &AnyTopOptions::default())
            .with_context(|| format!("{}: cannot build an AnyTop rig", first.name))?,
    };
    let points = |ls: &[Loaded]| -> anyhow::Result<Vec<PointClip>> {
        use rayon::prelude::*;
        ls.par_iter().map(|l| point_clip(&section, l)).collect()
    };
    let (gt_points, gen_points) = (points(&gt)?, points(&gen)?);
    let report = generation::generation_metrics(&gen_points, &gt_points, opts)?;
    let movement = movement_report(&gt, &gen, &gt_points, &gen_points, opts.seed)?;
    Ok(json!({
        "metric": "generation",
        "skeleton": first.name,
        "gt_clips": gt.len(),
        "generated_samples": gen.len(),
        "report": report,
        "movement": movement,
        "units": units(&[
            ("coverage", "percent of ground-truth windows"),
            ("energy", "body sizes per second (joints relative to the root, 5-frame average)"),
            ("energy_ratio", "energy / the clips' mean energy"),
            ("energy_ratio_range", "lowest and highest ratio of one motion"),
            ("nearest_pose", "pairwise joint distances / body size, mean absolute difference"),
            ("calibrated_coverage", "percent of ground-truth windows within the calibrated threshold"),
            ("threshold", "mean joint distance, AnyTop units (a quantile of the clips' own nearest-window distances)"),
            ("duty_factor", "share of frames a foot is in contact"),
            ("mixed_contact", "share of frames with some feet down and some up"),
            ("local_diversity", "mean joint distance, AnyTop units (mean SMPL bone = 0.209)"),
            ("global_diversity", "mean joint distance per frame, AnyTop units"),
            ("inter_diversity", "mean joint distance, AnyTop units"),
            ("intra_diversity", "mean joint distance, AnyTop units"),
            ("gt_intra_diversity", "mean joint distance, AnyTop units"),
            ("intra_diversity_diff", "mean joint distance, AnyTop units"),
        ]),
    }))
}

/// The movement metrics (`metrics::movement`) of the samples and of baselines made from the
/// clips: the clips left out one at a time, their static mean pose and random crops (at
/// least as many as the samples, two per clip) as long as the samples.
fn movement_report(gt: &[Loaded], gen: &[Loaded], gt_points: &[PointClip], gen_points: &[PointClip], seed: u64) -> anyhow::Result<Value> {
    let world = |ls: &[Loaded]| -> anyhow::Result<Vec<Clip>> { ls.iter().map(clip_of).collect() };
    let (gt_world, gen_world) = (world(gt)?, world(gen)?);
    let reference = movement::Reference::new(&gt_world, gt_points, &movement::MovementOptions::default()).context("movement metrics")?;
    let frames = gen_world.iter().map(|c| c.frames).max().unwrap_or(120);
    let count = gen_world.len();
    let samples = reference.score(&gen_world, gen_points, None)?;
    let clips = reference.clips_baseline()?;
    let (mean_world, mean_points) = reference.mean_pose(count, frames);
    let mean_pose = reference.score(&mean_world, &mean_points, None)?;
    let (crop_world, crop_points) = reference.random_crops(count, frames, seed);
    let crops = reference.score(&crop_world, &crop_points, None)?;
    Ok(json!({
        "threshold": reference.threshold,
        "samples": samples,
        "baselines": { "clips": clips, "mean_pose": mean_pose, "random_crops": crops },
    }))
}

/// The metrics a generation report carries, in table order.
const GENERATION_METRICS: [&str; 7] =
    ["coverage", "local_diversity", "global_diversity", "inter_diversity", "intra_diversity", "gt_intra_diversity", "intra_diversity_diff"];

fn run_aggregate(paths: &[PathBuf]) -> anyhow::Result<Value> {
    let mut skeletons = Vec::new();
    let mut means: Vec<Vec<f64>> = vec![Vec::new(); GENERATION_METRICS.len()];
    for path in paths {
        let name = io::display_name(path);
        let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
        let v: Value = serde_json::from_slice(&bytes).map_err(|e| anyhow::anyhow!("{name}: not JSON: {e}"))?;
        if v.get("metric").and_then(Value::as_str) != Some("generation") {
            bail!("{name}: not a report of `mo-metrics generation` (no \"metric\": \"generation\")");
        }
        for (k, key) in GENERATION_METRICS.iter().enumerate() {
            let m = v["report"][key]["mean"].as_f64().with_context(|| format!("{name}: report.{key}.mean is missing or not a number"))?;
            means[k].push(m);
        }
        skeletons.push(v["skeleton"].as_str().unwrap_or(&name).to_string());
    }
    let mut fin = Map::new();
    for (k, key) in GENERATION_METRICS.iter().enumerate() {
        fin.insert(key.to_string(), serde_json::to_value(generation::MeanStd::of(&means[k]))?);
    }
    Ok(json!({
        "metric": "generation-aggregate",
        "skeletons": skeletons,
        "final": fin,
        "units": units(&[("coverage", "percent of ground-truth windows"), ("local_diversity", "AnyTop units"), ("global_diversity", "AnyTop units"),
            ("inter_diversity", "AnyTop units"), ("intra_diversity", "AnyTop units"), ("gt_intra_diversity", "AnyTop units"), ("intra_diversity_diff", "AnyTop units")]),
    }))
}

/// AnyTop's evaluation features of one clip: joints 1..J-1, dims 0..3 of the 13-D features
/// (root-relative x, z in the facing frame; y absolute), with y minus the root height.
fn point_clip(section: &AnyTopSection, l: &Loaded) -> anyhow::Result<PointClip> {
    if l.motion.frames < 2 {
        bail!("{}: {} frame(s): generation metrics need clips of at least two frames", l.name, l.motion.frames);
    }
    let encoded = section.rig.encode(&l.skeleton, &l.motion).with_context(|| format!("{}: cannot encode", l.name))?;
    let f = &encoded.features;
    PointClip::from_anytop_features(f.frames, f.joints, &f.data).with_context(|| l.name.clone())
}

/// A JSON report as aligned `name  value  unit` lines, for humans.
fn table(report: &Value) -> String {
    // Every `units` table in the report, inner ones (the library's) over outer ones.
    fn gather(v: &Value, into: &mut Map<String, Value>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::Object(u)) = m.get("units") {
                    into.extend(u.clone());
                }
                m.iter().filter(|(k, _)| *k != "units").for_each(|(_, x)| gather(x, into));
            }
            Value::Array(a) => a.iter().for_each(|x| gather(x, into)),
            _ => {}
        }
    }
    let mut units = Map::new();
    gather(report, &mut units);
    let mut rows: Vec<(String, String, String)> = Vec::new();
    flatten("", report, &units, &mut rows);
    let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
    // Numbers line up; a long string (a file name) does not widen the column for all.
    let w1 = rows.iter().map(|r| r.1.len()).filter(|&l| l <= 24).max().unwrap_or(0);
    let mut out = String::new();
    for (k, v, u) in rows {
        let line = format!("{k:<w0$}  {v:<w1$}  {u}");
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

fn flatten(prefix: &str, v: &Value, units: &Map<String, Value>, rows: &mut Vec<(String, String, String)>) {
    // The unit of a leaf is its own key's, or its parent's for the parts of a measure.
    let unit_of = |key: &str| -> String {
        let parts: Vec<&str> = key.split('.').map(|p| p.split('[').next().unwrap_or(p)).collect();
        let leaf = parts.last().copied().unwrap_or("");
        let owner = match leaf {
            "value" | "mean" | "std" | "per_pair" | "normalised" if parts.len() >= 2 => parts[parts.len() - 2],
            _ => leaf,
        };
        let unit = units.get(owner).and_then(Value::as_str).unwrap_or("");
        if leaf == "normalised" {
            unit.replace("clip length units", "skeleton sizes").replace("target length units", "skeleton sizes")
        } else {
            unit.to_string()
        }
    };
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                if k == "units" {
                    continue;
                }
                let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                flatten(&key, x, units, rows);
            }
        }
        Value::Array(a) if a.iter().all(|x| x.is_number() || x.is_string()) && a.len() <= 16 => {
            let text = a.iter().map(|x| x.as_str().map_or_else(|| fmt_number(x), str::to_string)).collect::<Vec<_>>().join(", ");
            rows.push((prefix.to_string(), format!("[{text}]"), unit_of(prefix)));
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                flatten(&format!("{prefix}[{i}]"), x, units, rows);
            }
        }
        Value::Number(_) => rows.push((prefix.to_string(), fmt_number(v), unit_of(prefix))),
        Value::String(s) => rows.push((prefix.to_string(), s.clone(), String::new())),
        Value::Bool(b) => rows.push((prefix.to_string(), b.to_string(), String::new())),
        Value::Null => rows.push((prefix.to_string(), "-".into(), String::new())),
    }
}

fn fmt_number(v: &Value) -> String {
    match v.as_f64() {
        Some(x) if v.is_f64() => format!("{x:.6}"),
        _ => v.to_string(),
    }
}
