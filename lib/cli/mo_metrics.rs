//! `mo-metrics`: the evaluation metrics of AnyTop, Motion2Motion and SATA, and physical
//! plausibility for any motion. This file only loads motion (BVH or NPY + skeleton, through
//! `cli::load`), turns it into `metrics::WorldClip`s with our FK, calls `lib/metrics`, and prints
//! JSON (every number named, units in a `units` table) or a table for humans.
//! Definitions and deviations: docs/metrics.md.

use crate::binding::Binding;
use crate::cli::bounds;
use crate::cli::load::{expand_inputs, load_motions, read_skeleton, LoadOptions};
use crate::cli::CommonOpts;
use crate::io;
use crate::metrics::generation::GenerationOptions;
use crate::metrics::physics::{Ground, PhysicsOptions};
use crate::metrics::{checks, report};
use crate::motion::Clip;
use crate::repr::batch::PoseFrom;
use anyhow::{bail, Context};
use serde_json::Value;
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
    #[arg(long, value_enum, value_name = "FROM", default_value_t = PoseFrom::Rotations, global = true)]
    pub from: PoseFrom,
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
        /// Score against the diffusion model's unseen-skeleton denoiser (DIR/unseen; the
        /// built-in has one) and its limit: how mo-sample judges a skeleton the main denoiser
        /// was not trained on, which it samples with that denoiser.
        #[arg(long, conflicts_with = "latent")]
        unseen: bool,
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
    /// coverage with thresholds calibrated on the clips, foot contact (duty factor, share of
    /// frames with some feet down and some up), alternation, the footfall error: how far the
    /// feet's phases against each other lie from the clips', next to feet phased at random
    /// (`footfall_chance`), and swing: whether lifted feet move with the body's travel (1) or
    /// against it (-1, legs played backwards). Definitions: docs/metrics.md.
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
        #[command(flatten)]
        contact: Contact,
    },
}

/// Where the ground is and when a foot touches it (`mo-metrics physics`, `mo-edit foot-lock`).
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct Contact {
    /// Ground: 'zero' (y = 0), 'estimate' (lowest foot height over the clip) or a height.
    #[arg(long, value_name = "G", default_value = "zero")]
    ground: Ground,
    /// Contact height threshold, as a fraction of the skeleton's size.
    #[arg(long, value_name = "F", default_value_t = 0.05, allow_negative_numbers = true)]
    contact_height: f64,
    /// Contact speed threshold, as a fraction of the skeleton's size per second.
    #[arg(long, value_name = "F", default_value_t = 0.5, allow_negative_numbers = true)]
    contact_speed: f64,
}

impl Contact {
    pub fn options(&self) -> Result<PhysicsOptions, crate::metrics::MetricError> {
        PhysicsOptions::new(self.ground, self.contact_height, self.contact_speed)
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let started = std::time::Instant::now();
    let report = match &args.command {
        Command::Physics { inputs, contact } => {
            let opts = contact.options()?;
            report::physics_report(&load(args, inputs)?, &opts)?
        }
        Command::Reconstruction { reference, result, height } => run_reconstruction(args, reference, result, *height)?,
        Command::Transfer { source, result, binding, examples, seconds, fid_window } => {
            run_transfer(args, source, result, binding.as_deref(), examples, *seconds, *fid_window)?
        }
        Command::Aggregate { reports } => report::aggregate_report(&report::read_reports(reports)?)?,
        Command::Ood { skeletons, model, latent, unseen } => run_ood(args, skeletons, model.as_deref(), *latent, *unseen)?,
        Command::Generation { gt, generated, window, threshold, min_segment } => {
            let opts =
                GenerationOptions { window: *window, threshold: *threshold, min_segment: *min_segment, seed: args.common.seed, ..GenerationOptions::default() };
            run_generation(args, gt, generated, &opts)?
        }
    };
    args.common.say("mo-metrics").info(format_args!("done in {:.3} s", started.elapsed().as_secs_f64()));
    let text = match args.format {
        Format::Json => serde_json::to_string_pretty(&report).context("building the JSON")? + "\n",
        Format::Table => report::table(&report),
    };
    Ok(io::write_output(args.common.output.as_deref(), text.as_bytes())?)
}

fn run_ood(args: &Args, skeletons: &[PathBuf], model: Option<&Path>, latent: bool, unseen: bool) -> anyhow::Result<Value> {
    let device = candle_core::Device::Cpu;
    let known = if latent {
        super::ood::Known::latent(model, &crate::sata::clips::frozen_or_default(model, &device)?.rigs)?
    } else if unseen {
        let Some(denoiser) = crate::diffusion::unseen::frozen_or_default(model, &device)? else {
            bail!(
                "--unseen: {} has no unseen-skeleton denoiser (an unseen/ model directory inside it)",
                model.map_or("the model".into(), |d| d.display().to_string())
            );
        };
        super::ood::Known::unseen_denoiser(model, &denoiser.info)?
    } else {
        super::ood::Known::denoiser(model, &crate::diffusion::checkpoint::frozen_or_default(model, &device)?.info)?
    };
    if known.reference.profiles.is_empty() {
        bail!("{} records no training skeletons to compare with", known.model);
    }
    let skeletons = skeletons.iter().map(|p| read_skeleton(p).map(|f| (f.name, f.skeleton))).collect::<Result<Vec<_>, _>>()?;
    Ok(known.reference.report(&known.model, &skeletons, args.common.verbose)?)
}

fn load(args: &Args, inputs: &[PathBuf]) -> anyhow::Result<Vec<Clip>> {
    let files = expand_inputs(inputs)?;
    let options = LoadOptions { skeleton: args.skeleton.as_deref(), from: Some(args.from) };
    let loaded = load_motions(&files, &options)?;
    if loaded.is_empty() {
        bail!("no motion in {}", inputs.iter().map(|p| io::display_name(p)).collect::<Vec<_>>().join(", "));
    }
    Ok(loaded)
}

fn load_one(args: &Args, path: &Path) -> anyhow::Result<Clip> {
    let mut loaded = load(args, &[path.to_path_buf()])?;
    if loaded.len() != 1 {
        bail!("{}: expected one motion, found {} (an NPY batch?)", io::display_name(path), loaded.len());
    }
    Ok(loaded.remove(0))
}

fn run_reconstruction(args: &Args, reference: &Path, result: &Path, height: Option<f64>) -> anyhow::Result<Value> {
    let mut a = load_one(args, reference)?;
    let b = load_one(args, result)?;
    if let Some(note) = checks::reconstruction_pair(&mut a, &b)? {
        args.common.say("mo-metrics").note(note);
    }
    let height = match height {
        Some(h) if h.is_finite() && h > 0.0 => h,
        Some(h) => bail!("--height must be a positive number, found {h}"),
        None => a.skeleton.rest_height(),
    };
    Ok(report::reconstruction_report(&a, &b, height)?)
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
    checks::one_target(&results)?;
    let pairs = match binding {
        Some(path) => Binding::read_resolved(path, &src, target)?.0,
        None => report::same_name_pairs(&src, target),
    };
    checks::some_pairs(&src, target, &pairs)?;
    let examples = if examples.is_empty() { Vec::new() } else { load(args, examples)? };
    let transfer = report::Transfer { source: &src, results: &results, pairs: &pairs, examples: &examples, seconds, fid_window };
    Ok(report::transfer_report(&transfer)?)
}

fn run_generation(args: &Args, gt: &[PathBuf], generated: &[PathBuf], opts: &GenerationOptions) -> anyhow::Result<Value> {
    let gt = load(args, gt)?;
    let gen = load(args, generated)?;
    checks::one_skeleton(&gt, &gen)?;
    // One rig for all clips, so positions share AnyTop's scale: the skeleton's own record
    // (--skeleton), else one built on the first ground-truth clip as AnyTop would.
    let section = match &args.skeleton {
        Some(p) => read_skeleton(p)?.record()?,
        None => checks::generation_rig(&gt[0])?,
    };
    Ok(report::generation_report(&gt, &gen, &section, opts)?)
}
