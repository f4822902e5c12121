//! `mo-encode`: BVH motion -> feature tensors (NPY), and back (`--decode`).
//!
//! Everything learned or measured downstream sees motion through these tensors, so the tool is
//! the one place where representations meet files. A representation is a `Repr` variant with
//! an encode, a check and a decode; adding one (AnyTop's, next) means a variant and three
//! match arms here, nothing else in the file.
//!
//! Encoding runs across clips in parallel (rayon), each clip sequentially, so the output is
//! byte-identical whatever `--threads` says. Every input is checked before anything is
//! written, and files are written atomically, so an error never leaves a partial output.

use crate::cli::CommonOpts;
use crate::document::SkeletonDocument;
use crate::io::npy::{self, NpyArray};
use crate::motion::Motion;
use crate::repr::{m2m, Features};
use crate::skeleton::Skeleton;
use crate::{bvh, io};
use anyhow::{bail, Context};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
EXAMPLES:
    mo-encode examples/data/spider.bvh -o spider.npy
    skel-info examples/data/spider.bvh | mo-encode --decode --skeleton - spider.npy -o spider.bvh
    mo-encode examples/data/snake.bvh | mo-encode --decode --skeleton examples/data/snake.bvh
    mo-encode --repr m2m examples/data/bird.bvh examples/data/bird.bvh -o birds.npy
    mo-encode --decode --skeleton examples/data/bird.bvh birds.npy -o bird_{i}.bvh
    cat examples/data/fish.bvh | mo-encode - --threads 1 > fish.npy";

/// Encode BVH motion as feature tensors (NPY), or decode tensors back to BVH.
///
/// Encoding reads BVH files ('-' = stdin) and writes one little-endian float32 NPY: shape
/// [frames, joints, dims] for one file, [files, frames, joints, dims] for several (they must
/// agree in frames and joints). Tensors are in the BVH's own units and frame rate; numpy loads
/// them with numpy.load.
///
/// --repr m2m (Motion2Motion, 9 dims per joint): dims 0-5 are the joint's local rotation as 6D
/// (the first two rows of its rotation matrix); on the root (joint 0), dims 6-8 are its position
/// as dx, y, dz: x and z as per-frame differences, frame 0 holding the start position, y
/// absolute. Other joints' dims 6-8 are zero. Only the root translates: joints whose position
/// channels animate are decoded on their OFFSETs (a warning says so when encoding).
///
/// Decoding (--decode) reads one NPY file (default stdin) and writes BVH on the --skeleton's own
/// hierarchy, channel orders and frame time. --skeleton is a skeleton document from skel-info
/// or a BVH file (recognised by content). A 4-D batch writes one BVH per sample: give -o a
/// pattern with {i}, replaced by the sample index.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-encode", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files to encode ('-' = stdin); with --decode, one NPY file (default: stdin).
    #[arg(value_name = "INPUT", required_unless_present = "decode")]
    pub inputs: Vec<PathBuf>,
    /// Feature representation.
    #[arg(long, value_enum, default_value_t = Repr::M2m)]
    pub repr: Repr,
    /// Decode an NPY of features back to BVH on --skeleton.
    #[arg(long, requires = "skeleton")]
    pub decode: bool,
    /// Skeleton to decode onto: a skel-info document (JSON) or a BVH file ('-' = stdin).
    #[arg(long, value_name = "PATH", requires = "decode")]
    pub skeleton: Option<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

/// The feature representations `mo-encode` knows.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Repr {
    /// Motion2Motion: local 6D rotation of every joint + root position (x/z as velocities); 9 dims.
    M2m,
}

impl Repr {
    pub fn name(self) -> &'static str {
        match self {
            Repr::M2m => "m2m",
        }
    }

    /// Feature dims per joint.
    pub fn dims(self) -> usize {
        match self {
            Repr::M2m => m2m::DIMS,
        }
    }

    pub fn encode(self, motion: &Motion, _skeleton: &Skeleton) -> Features {
        match self {
            Repr::M2m => m2m::encode(motion),
        }
    }

    /// Shape and value checks, so a batch is refused before anything is written.
    pub fn check(self, features: &Features, skeleton: &Skeleton) -> Result<(), String> {
        match self {
            Repr::M2m => m2m::check(features, skeleton).map_err(|e| e.to_string()),
        }
    }

    pub fn decode(self, features: &Features, skeleton: &Skeleton) -> Result<Motion, String> {
        match self {
            Repr::M2m => m2m::decode(features, skeleton).map_err(|e| e.to_string()),
        }
    }

    /// What the representation loses on this clip, as a warning (None when nothing).
    fn loss_warning(self, motion: &Motion, skeleton: &Skeleton) -> Option<String> {
        match self {
            Repr::M2m => {
                // Far below the 1e-4-of-size round-trip promise, far above text rounding.
                let tolerance = 1e-5 * skeleton.rest_extent().max(f64::MIN_POSITIVE);
                let c = m2m::max_bone_translation_change(motion, skeleton, tolerance)?;
                Some(format!(
                    "{} joint(s) translate away from their OFFSET (up to {:.6} units: '{}' at frame {}); m2m carries only the root's translation, so decoding puts them on their OFFSETs",
                    c.joints, c.distance, skeleton.joints[c.joint].name, c.frame
                ))
            }
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads();
    if args.decode {
        decode(args)
    } else {
        encode(args)
    }
}

/// One encoded clip.
struct Encoded {
    name: String,
    features: Features,
    /// Joint names and parents, to warn when a batch mixes skeletons of the same shape.
    hierarchy: Vec<(String, Option<usize>)>,
    warning: Option<String>,
}

fn encode_one(path: &Path, repr: Repr) -> anyhow::Result<Encoded> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
    let parsed = bvh::parse_bytes(&bytes, &name)?;
    drop(bytes);
    let skeleton = Skeleton::from_bvh(&parsed);
    let motion = Motion::from_bvh(&parsed, &skeleton);
    drop(parsed);
    let features = repr.encode(&motion, &skeleton);
    let warning = repr.loss_warning(&motion, &skeleton);
    let hierarchy = skeleton.joints.iter().map(|j| (j.name.clone(), j.parent)).collect();
    Ok(Encoded { name, features, hierarchy, warning })
}

fn encode(args: &Args) -> anyhow::Result<()> {
    if args.inputs.iter().filter(|p| p.as_os_str() == "-").count() > 1 {
        bail!("stdin ('-') can be read only once");
    }
    refuse_terminal(args.common.output.as_deref())?;
    // Clips in parallel, results in argument order; the first failing argument is reported.
    let results: Vec<anyhow::Result<Encoded>> = args.inputs.par_iter().map(|p| encode_one(p, args.repr)).collect();
    let clips = results.into_iter().collect::<anyhow::Result<Vec<Encoded>>>()?;

    let Some(first) = clips.first() else { bail!("no BVH files to encode") };
    for clip in &clips[1..] {
        if clip.features.shape() != first.features.shape() {
            bail!(
                "cannot stack {} {:?} and {} {:?}: a batch needs the same frames and joints (encode them separately, or cut the clips to one length)",
                first.name,
                first.features.shape(),
                clip.name,
                clip.features.shape()
            );
        }
    }
    for clip in &clips {
        if !args.common.quiet {
            if let Some(w) = &clip.warning {
                eprintln!("mo-encode: warning: {}: {w}", clip.name);
            }
            if clip.hierarchy != first.hierarchy {
                eprintln!("mo-encode: warning: {} and {} have the same shape but different joint names or parents", first.name, clip.name);
            }
        }
        if args.common.verbose {
            let [f, j, d] = clip.features.shape();
            eprintln!("mo-encode: {}: {f} frames, {j} joints -> {} features [{f}, {j}, {d}]", clip.name, args.repr.name());
        }
    }

    let mut shape = first.features.shape().to_vec();
    if clips.len() > 1 {
        shape.insert(0, clips.len());
    }
    let parts: Vec<&[f32]> = clips.iter().map(|c| c.features.data.as_slice()).collect();
    let mut bytes = Vec::new();
    npy::write_f32_parts(&mut bytes, &shape, &parts).context("building the NPY")?;
    let target = args.common.output.as_deref();
    io::write_output(target, &bytes).with_context(|| format!("cannot write {}", output_name(target)))
}

/// Binary on a terminal is never what anyone wants (and can upset it).
fn refuse_terminal(output: Option<&Path>) -> anyhow::Result<()> {
    let to_stdout = output.is_none_or(|p| p.as_os_str() == "-");
    if to_stdout && std::io::stdout().is_terminal() {
        bail!("refusing to write a binary NPY to a terminal: use -o FILE.npy or a pipe");
    }
    Ok(())
}

fn output_name(p: Option<&Path>) -> String {
    match p {
        Some(p) if p.as_os_str() != "-" => p.display().to_string(),
        _ => "stdout".to_string(),
    }
}

/// A skeleton from a skeleton document (JSON) or a BVH file, recognised by content.
pub fn load_skeleton(path: &Path) -> anyhow::Result<Skeleton> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read skeleton {name}"))?;
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF".as_slice()).unwrap_or(&bytes).trim_ascii_start();
    if body.starts_with(b"{") {
        let text = std::str::from_utf8(body).with_context(|| format!("{name}: skeleton document is not UTF-8"))?;
        let doc = SkeletonDocument::from_json(text).with_context(|| name.clone())?;
        Ok(doc.skeleton().with_context(|| name.clone())?)
    } else if body.len() >= 9 && body[..9].eq_ignore_ascii_case(b"HIERARCHY") {
        let parsed = bvh::parse_bytes(&bytes, &name)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        skeleton.validate().with_context(|| name.clone())?;
        Ok(skeleton)
    } else {
        let start: String = body.iter().take(12).flat_map(|&b| std::ascii::escape_default(b)).map(char::from).collect();
        bail!("{name}: not a skeleton: expected a skeleton document (JSON from skel-info) or a BVH file, found '{start}'")
    }
}

fn decode(args: &Args) -> anyhow::Result<()> {
    let input = match args.inputs.as_slice() {
        [] => PathBuf::from("-"),
        [one] => one.clone(),
        many => bail!("--decode reads one NPY file, got {}", many.len()),
    };
    let skeleton_path = args.skeleton.as_deref().context("--decode needs --skeleton")?;
    if input.as_os_str() == "-" && skeleton_path.as_os_str() == "-" {
        bail!("stdin ('-') can be read only once: the NPY and the skeleton cannot both come from it");
    }
    let skeleton = load_skeleton(skeleton_path)?;
    let skeleton_name = io::display_name(skeleton_path);
    let name = io::display_name(&input);
    let bytes = io::read_input(&input).with_context(|| format!("cannot read {name}"))?;
    let array = npy::from_bytes(&bytes, &name)?;
    drop(bytes);
    let (samples, batch) = split_samples(array, &name)?;

    // Check everything before writing anything.
    let label = |i: usize| if batch { format!("{name}: sample {i}") } else { name.clone() };
    for (i, f) in samples.iter().enumerate() {
        args.repr.check(f, &skeleton).map_err(|e| anyhow::anyhow!("{}: {e} ({} features, skeleton {skeleton_name})", label(i), args.repr.name()))?;
    }
    let target = args.common.output.as_deref();
    let to_stdout = target.is_none_or(|p| p.as_os_str() == "-");
    let paths: Vec<Option<PathBuf>> = if to_stdout {
        if samples.len() > 1 {
            bail!("{name} holds a batch of {} samples: give -o a pattern such as 'out_{{i}}.bvh' to write one BVH per sample", samples.len());
        }
        vec![None]
    } else {
        let pattern = target.expect("checked above");
        (0..samples.len())
            .map(|i| io::numbered_output(pattern, i, samples.len()).map(Some).map_err(anyhow::Error::msg))
            .collect::<anyhow::Result<_>>()?
    };

    let texts: Vec<anyhow::Result<String>> = samples
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let motion = args.repr.decode(f, &skeleton).map_err(|e| anyhow::anyhow!("{}: {e}", label(i)))?;
            Ok(bvh::write_string(&motion.to_bvh(&skeleton)))
        })
        .collect();
    let texts = texts.into_iter().collect::<anyhow::Result<Vec<String>>>()?;
    if args.common.verbose {
        eprintln!("mo-encode: {name}: {} sample(s) of {} frames decoded on {skeleton_name}", samples.len(), samples.first().map_or(0, |f| f.frames));
    }

    let mut written: Vec<PathBuf> = Vec::new();
    for (text, path) in texts.iter().zip(&paths) {
        let result = io::write_output(path.as_deref(), text.as_bytes());
        if let Err(e) = result {
            // All or nothing: a failed batch leaves none of its files behind.
            for p in &written {
                let _ = std::fs::remove_file(p);
            }
            return Err(e).with_context(|| format!("cannot write {}", output_name(path.as_deref())));
        }
        if let Some(p) = path {
            written.push(p.clone());
        }
    }
    Ok(())
}

/// Rank 3 -> one motion; rank 4 -> one per sample (`true`: the input was a batch).
fn split_samples(array: NpyArray, name: &str) -> anyhow::Result<(Vec<Features>, bool)> {
    match array.shape.as_slice() {
        &[frames, joints, dims] => Ok((vec![Features { frames, joints, dims, data: array.data }], false)),
        &[n, frames, joints, dims] => {
            if n == 0 {
                bail!("{name}: the batch holds no samples (shape {:?})", array.shape);
            }
            let per = frames * joints * dims;
            let samples = (0..n).map(|i| Features { frames, joints, dims, data: array.data[i * per..(i + 1) * per].to_vec() }).collect();
            Ok((samples, true))
        }
        shape => bail!(
            "{name}: expected a [frames, joints, dims] or [samples, frames, joints, dims] array, found shape {shape:?} (rank {})",
            shape.len()
        ),
    }
}
