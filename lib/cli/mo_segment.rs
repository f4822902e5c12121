//! `mo-segment`: split a motion into actions. This file loads the motion (through `cli::load`),
//! turns it into one feature vector per frame (`frame_features`: the place where feature
//! providers plug in), runs `segment::segment`, and writes JSON that `mo-render --frame-labels`
//! reads.

use crate::cli::load::{load_motions, read_skeleton, DecodeFrom, LoadOptions};
use crate::cli::CommonOpts;
use crate::document::AnyTopSection;
use crate::io;
use crate::motion::Motion;
use crate::repr::anytop::{AnyTopOptions, RestSource};
use crate::segment::{self, Segmentation, SegmentOptions};
use crate::skeleton::Skeleton;
use anyhow::{bail, Context};
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    mo-segment examples/data/biped.bvh
    mo-segment examples/data/quadruped.bvh --k 2 --min-segment 20 -o quadruped_segments.json
    mo-segment examples/data/dragon.bvh --pca-dims 4 --window 0.5 --seed 7 > dragon_segments.json
    cat examples/data/crab.bvh | mo-segment - --k 4 --quiet";

/// Split a motion into actions: per-frame labels and contiguous segments (JSON).
///
/// Each frame of the motion becomes a feature vector (--features): 'raw' is the motion's own
/// AnyTop features, every joint's 13 values (root-relative position, 6D rotation, velocity,
/// foot contact) except the root's facing. The vectors are centred and projected on their top
/// --pca-dims principal components; each frame is then described by the mean and standard
/// deviation of its projections over --window seconds around it (single poses of a walk sweep
/// through the gait cycle; statistics over about a cycle describe the action); k-means
/// (k-means++ seeding, several restarts, --seed) groups the frames into --k clusters, and runs
/// shorter than --min-segment frames are merged into their longer neighbour.
///
/// Output: JSON with the file, its frame count and frame time, the options, the explained
/// variance of the kept components, one label per frame ('labels', numbered by first
/// appearance: frame 0 has label 0) and the contiguous 'segments' [{start, end, label}] with end
/// exclusive, in BVH frames. AnyTop features have one frame fewer than the BVH (a frame's
/// velocity needs the next one): the last frame takes the label before it. 'mo-render
/// --frame-labels FILE' tints frames by this output.
///
/// The input is a BVH file ('-' = stdin), or an NPY of AnyTop features decoded on --skeleton.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-segment", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// Motion to segment: a BVH file, or an NPY feature file with --skeleton ('-' = stdin).
    #[arg(value_name = "INPUT", default_value = "-")]
    pub input: PathBuf,
    /// Clusters (kinds of action) to find; segments with the same label are the same kind.
    #[arg(long, value_name = "K", default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=64))]
    pub k: u64,
    /// Principal components kept (0 = cluster the features as they are).
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub pca_dims: usize,
    /// Temporal context: mean and std of each component over this many seconds around a frame
    /// (0 = single frames).
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0, allow_negative_numbers = true)]
    pub window: f64,
    /// Shortest segment in frames; shorter runs are merged into their longer neighbour.
    #[arg(long, value_name = "FRAMES", default_value_t = 10)]
    pub min_segment: usize,
    /// What each frame is described by.
    #[arg(long, value_enum, value_name = "KIND", default_value_t = Features::Raw)]
    pub features: Features,
    /// K-means restarts from different seedings; the tightest clustering wins.
    #[arg(long, value_name = "N", default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub restarts: u64,
    /// Skeleton of an NPY input: a skeleton document (skel-info) or a BVH file. Its AnyTop
    /// record also fixes the rig features are computed with.
    #[arg(long, value_name = "PATH")]
    pub skeleton: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// Per-frame descriptions `mo-segment` can cluster.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Features {
    /// The motion's own AnyTop features without the root's facing (a baseline; no model needed).
    Raw,
}

impl Features {
    pub fn name(self) -> &'static str {
        match self {
            Features::Raw => "raw",
        }
    }
}

/// A motion to segment, with the AnyTop rig its features are computed on: what every feature
/// provider gets.
pub struct Input {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
    pub section: AnyTopSection,
}

impl Input {
    /// A motion with a rig built on its own first two frames (AnyTop's rule for a clip without
    /// a T-pose file, as `skel-info` builds it).
    pub fn new(name: String, skeleton: Skeleton, motion: Motion) -> anyhow::Result<Input> {
        if motion.frames < 2 {
            bail!("{name}: {} frame(s); segmenting needs at least 2 (AnyTop features need the next frame)", motion.frames);
        }
        let options = AnyTopOptions { rest_source: RestSource::FirstClip { file: name.clone() }, ..AnyTopOptions::default() };
        let section =
            AnyTopSection::new(&skeleton, &motion.first_frames(2), &options).with_context(|| format!("{name}: cannot build an AnyTop rig"))?;
        Ok(Input { name, skeleton, motion, section })
    }

    /// Seconds per frame (a broken frame time counts as 30 fps).
    pub fn frame_time(&self) -> f64 {
        if self.motion.frame_time.is_finite() && self.motion.frame_time > 0.0 { self.motion.frame_time } else { 1.0 / 30.0 }
    }
}

/// `--features raw`: `segment::raw_frame_features` of the clip's AnyTop encoding, one row per
/// BVH frame but the last.
pub fn raw_features(input: &Input) -> anyhow::Result<Vec<Vec<f64>>> {
    let encoded = input.section.rig.encode(&input.skeleton, &input.motion).map_err(|e| anyhow::anyhow!("{}: {e}", input.name))?;
    Ok(segment::raw_frame_features(&encoded.features))
}

/// One feature vector per frame of `input` for `--features`, row t describing BVH frame t (rows
/// may stop short of the last frames; `segment_input` gives those the last row's label; all rows
/// the same length, finite). New feature kinds (DIFT) are one more `Features` variant and one
/// more arm here, reading their own flags (model, step, layer, draws, `args.common.seed`) from
/// `args`.
pub fn frame_features(args: &Args, input: &Input) -> anyhow::Result<Vec<Vec<f64>>> {
    match args.features {
        Features::Raw => raw_features(input),
    }
}

/// `--window` seconds as frames at `frame_time` (0 = none).
pub fn window_frames(seconds: f64, frame_time: f64) -> usize {
    if seconds > 0.0 && frame_time > 0.0 { (seconds / frame_time).round() as usize } else { 0 }
}

/// Segment `features` of `input` and return the result in BVH frames (labels extended to every
/// frame of the motion, segments recomputed on them).
pub fn segment_input(input: &Input, features: &[Vec<f64>], options: &SegmentOptions, seed: u64) -> anyhow::Result<Segmentation> {
    if features.is_empty() {
        bail!("{}: no feature frames to segment", input.name);
    }
    let mut s = segment::segment(features, options, seed).with_context(|| format!("{}: cannot segment", input.name))?;
    s.labels = segment::extend_labels(&s.labels, input.motion.frames);
    s.segments = segment::segments(&s.labels);
    Ok(s)
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads();
    if !(args.window.is_finite() && args.window >= 0.0) {
        bail!("--window must be a number of seconds >= 0, found {}", args.window);
    }
    let input = load(args)?;
    let options = SegmentOptions {
        k: args.k as usize,
        pca_dims: args.pca_dims,
        window: window_frames(args.window, input.frame_time()),
        min_segment: args.min_segment,
        restarts: args.restarts as usize,
        ..SegmentOptions::default()
    };
    let started = std::time::Instant::now();
    let features = frame_features(args, &input)?;
    let result = segment_input(&input, &features, &options, args.common.seed)?;
    if args.common.verbose {
        eprintln!(
            "mo-segment: {}: {} frames, {} segments, {} clusters in {:.3} s",
            input.name,
            input.motion.frames,
            result.segments.len(),
            result.clusters,
            started.elapsed().as_secs_f64()
        );
    }
    let text = report(args, &input, &options, &result)?;
    io::write_output(args.common.output.as_deref(), text.as_bytes()).context("cannot write the segmentation")
}

fn load(args: &Args) -> anyhow::Result<Input> {
    let options = LoadOptions { skeleton: args.skeleton.as_deref(), from: Some(DecodeFrom::Rotations) };
    let mut loaded = load_motions(std::slice::from_ref(&args.input), &options)?;
    if loaded.len() != 1 {
        bail!("{}: expected one motion, found {} (an NPY batch? segment one sample at a time)", io::display_name(&args.input), loaded.len());
    }
    let l = loaded.remove(0);
    match &args.skeleton {
        // The skeleton's own record, so features match those mo-encode made with it.
        Some(path) => {
            let section = read_skeleton(path)?.record()?;
            if l.motion.frames < 2 {
                bail!("{}: {} frame(s); segmenting needs at least 2", l.name, l.motion.frames);
            }
            Ok(Input { name: l.name, skeleton: l.skeleton, motion: l.motion, section })
        }
        None => Input::new(l.name, l.skeleton, l.motion),
    }
}

/// The JSON report: one key per line, values compact (a per-frame label list stays one line).
fn report(args: &Args, input: &Input, options: &SegmentOptions, s: &Segmentation) -> anyhow::Result<String> {
    use serde_json::to_string;
    let explained = (s.explained_variance * 1e6).round() / 1e6;
    let fields: Vec<(&str, String)> = vec![
        ("file", to_string(&input.name)?),
        ("frames", to_string(&input.motion.frames)?),
        ("frame_time", to_string(&input.frame_time())?),
        ("features", to_string(&args.features.name())?),
        ("k", to_string(&options.k)?),
        ("clusters", to_string(&s.clusters)?),
        ("pca_dims", to_string(&s.pca_dims)?),
        ("explained_variance", to_string(&explained)?),
        ("window_frames", to_string(&options.window)?),
        ("min_segment", to_string(&options.min_segment)?),
        ("seed", to_string(&args.common.seed)?),
        ("labels", to_string(&s.labels)?),
        ("segments", to_string(&s.segments)?),
    ];
    let mut out = String::from("{\n");
    for (i, (key, value)) in fields.iter().enumerate() {
        let comma = if i + 1 < fields.len() { "," } else { "" };
        out.push_str(&format!("  \"{key}\": {value}{comma}\n"));
    }
    out.push_str("}\n");
    Ok(out)
}
