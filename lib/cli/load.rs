//! Reading motion for the tools that consume it: BVH files, glTF/GLB files, or NPY feature
//! tensors decoded on a skeleton (a skeleton document, or a BVH standing for the document
//! `skel-info` prints). A glTF file is read as the BVH it stands for (`parse_motion`), so every
//! tool that reads BVH reads glTF through this one door, and writes it through `motion_bytes`.
//!
//! `mo-encode --decode` and every tool that *looks at* motion (`mo-render`, `mo-metrics`) go
//! through the same code here, so an NPY decodes to the same joint positions everywhere.

use crate::document::{AnyTopSection, MotionInfo, SkeletonDocument};
use crate::io::npy::{self, NpyArray};
use crate::motion::Motion;
use crate::repr::anytop::{self, RigOptions, AnyTopRig, AnyTopStats, IkOptions, Placement, RestSource};
use crate::repr::{m2m, Features};
use crate::skeleton::{topology, Skeleton};
use crate::{bvh, gltf, io};
use anyhow::{anyhow, bail, Context};
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The glTF input options of this run (`--animation`, `--fps`), set once from `CommonOpts`.
static GLTF_OPTIONS: Mutex<Option<gltf::ReadOptions>> = Mutex::new(None);

/// Set how glTF inputs are read for the rest of the process.
pub fn set_gltf_options(options: gltf::ReadOptions) {
    *GLTF_OPTIONS.lock().unwrap_or_else(|e| e.into_inner()) = Some(options);
}

fn gltf_options() -> gltf::ReadOptions {
    GLTF_OPTIONS.lock().unwrap_or_else(|e| e.into_inner()).clone().unwrap_or_default()
}

/// Whether `bytes` from `path` are glTF: GLB's magic, a `.gltf`/`.glb` name, or JSON with the
/// `asset` object every glTF has (a glTF piped on stdin).
pub fn is_gltf(path: &Path, bytes: &[u8]) -> bool {
    #[derive(serde::Deserialize)]
    struct Probe {
        asset: Option<serde::de::IgnoredAny>,
    }
    gltf::looks_like_gltf(path, bytes)
        || (bytes.trim_ascii_start().starts_with(b"{") && serde_json::from_slice::<Probe>(bytes).is_ok_and(|p| p.asset.is_some()))
}

/// The skeleton and motion of a glTF file (`--animation`, `--fps` as given for this run).
pub fn read_gltf(bytes: &[u8], name: &str, path: &Path) -> anyhow::Result<(Skeleton, Motion)> {
    let base = if is_dash(path) { None } else { Some(path.parent().unwrap_or(Path::new("."))) };
    Ok(gltf::read(bytes, name, base, &gltf_options())?)
}

/// A motion file as BVH data: BVH parsed as it is, glTF (by name or content) as the BVH it
/// stands for (ZXY rotation channels, positions on the root and on joints that translate).
pub fn parse_motion(bytes: &[u8], name: &str, path: &Path) -> anyhow::Result<bvh::Bvh> {
    if is_gltf(path, bytes) {
        let (skeleton, motion) = read_gltf(bytes, name, path)?;
        Ok(motion.to_bvh(&skeleton))
    } else {
        Ok(bvh::parse_bytes(bytes, name)?)
    }
}

/// The motion file formats tools write.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionFormat {
    Bvh,
    /// Binary glTF: skin, animation and a stick mesh in one file (Blender, three.js, game engines).
    Glb,
    /// glTF JSON with the binary data inlined.
    Gltf,
}

impl MotionFormat {
    /// What a path's extension asks for (`.glb`, `.gltf`; anything else is BVH).
    pub fn of_path(path: &Path) -> MotionFormat {
        match path.extension().and_then(|x| x.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("glb") => MotionFormat::Glb,
            Some("gltf") => MotionFormat::Gltf,
            _ => MotionFormat::Bvh,
        }
    }

    /// The format for an output: the path's extension, or `stdout` for stdout (`None` or `-`).
    pub fn for_output(path: Option<&Path>, stdout: MotionFormat) -> MotionFormat {
        match path {
            Some(p) if !is_dash(p) => MotionFormat::of_path(p),
            _ => stdout,
        }
    }
}

/// The bytes of a motion file in `format`; `name` is the output's, for messages.
pub fn motion_bytes(skeleton: &Skeleton, motion: &Motion, format: MotionFormat, name: &str) -> anyhow::Result<Vec<u8>> {
    Ok(match format {
        MotionFormat::Bvh => bvh::write_string(&motion.to_bvh(skeleton)).into_bytes(),
        MotionFormat::Glb => gltf::write_glb(skeleton, motion, name)?,
        MotionFormat::Gltf => gltf::write_gltf(skeleton, motion, name)?,
    })
}

/// A motion written to `path` (or stdout as `stdout` says), in the format the path asks for.
pub fn motion_file(skeleton: &Skeleton, motion: &Motion, path: Option<&Path>, stdout: MotionFormat) -> anyhow::Result<Vec<u8>> {
    let name = path.filter(|p| !is_dash(p)).map_or_else(|| "<stdout>".to_string(), |p| p.display().to_string());
    let format = MotionFormat::for_output(path, stdout);
    if format == MotionFormat::Glb {
        io::refuse_terminal(path, "binary glTF", "give -o FILE.glb or redirect stdout")?;
    }
    motion_bytes(skeleton, motion, format, &name)
}

/// Where AnyTop decoding takes the rotations from.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeFrom {
    /// The features' 6D rotations: exact for encoded features.
    Rotations,
    /// The features' joint positions, by inverse kinematics: for generated features.
    Positions,
}

/// `-` means stdin/stdout.
pub fn is_dash(p: &Path) -> bool {
    p.as_os_str() == "-"
}

/// What `--skeleton` names: a skeleton document, or a BVH file standing for the document
/// `skel-info` would print for it.
pub struct SkeletonArg {
    pub name: String,
    pub skeleton: Skeleton,
    pub document: SkeletonDocument,
    /// A BVH's motion (its rest frames and statistics); `None` for a document.
    pub motion: Option<Motion>,
    /// A BVH named like a T-pose.
    pub tpose: bool,
}

/// Read `--skeleton`, recognised by content.
pub fn read_skeleton(path: &Path) -> anyhow::Result<SkeletonArg> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read skeleton {name}"))?;
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF".as_slice()).unwrap_or(&bytes).trim_ascii_start();
    if is_gltf(path, &bytes) {
        let parsed = parse_motion(&bytes, &name, path)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        let document = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, topology::DEFAULT_DMAX);
        let motion = Some(Motion::from_bvh(&parsed, &skeleton));
        Ok(SkeletonArg { tpose: !is_dash(path) && anytop::names_tpose(&path.to_string_lossy()), name, skeleton, document, motion })
    } else if body.starts_with(b"{") {
        let text = std::str::from_utf8(body).with_context(|| format!("{name}: skeleton document is not UTF-8"))?;
        let document = SkeletonDocument::from_json(text).with_context(|| name.clone())?;
        let skeleton = document.skeleton().with_context(|| name.clone())?;
        Ok(SkeletonArg { name, skeleton, document, motion: None, tpose: false })
    } else if body.len() >= 9 && body[..9].eq_ignore_ascii_case(b"HIERARCHY") {
        let parsed = bvh::parse_bytes(&bytes, &name)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        skeleton.validate().with_context(|| name.clone())?;
        let document = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, topology::DEFAULT_DMAX);
        let motion = Some(Motion::from_bvh(&parsed, &skeleton));
        Ok(SkeletonArg { tpose: !is_dash(path) && anytop::names_tpose(&path.to_string_lossy()), name, skeleton, document, motion })
    } else {
        let start: String = body.iter().take(12).flat_map(|&b| std::ascii::escape_default(b)).map(char::from).collect();
        bail!("{name}: not a skeleton: expected a skeleton document (JSON from skel-info), a BVH or a glTF file, found '{start}'")
    }
}

/// A skeleton from a skeleton document (JSON) or a BVH file, recognised by content.
pub fn load_skeleton(path: &Path) -> anyhow::Result<Skeleton> {
    Ok(read_skeleton(path)?.skeleton)
}

/// How the samples of one NPY go back to motion.
pub enum Decoder {
    M2m,
    AnyTop {
        rig: Box<AnyTopRig>,
        /// Undo `--normalise` first.
        stats: Option<AnyTopStats>,
        /// One per sample.
        placements: Vec<Placement>,
        from: DecodeFrom,
    },
}

impl Decoder {
    /// Shape and value checks, so a batch is refused before anything is written; on failure,
    /// what is wrong and a hint (may be empty).
    pub fn check(&self, features: &Features, skeleton: &Skeleton) -> Result<(), (String, &'static str)> {
        match self {
            Decoder::M2m => m2m::check(features, skeleton).map_err(|e| {
                let hint = if features.dims == anytop::FEATURE_DIMS { ": AnyTop features? decode them without --repr m2m" } else { "" };
                (e.to_string(), hint)
            }),
            Decoder::AnyTop { .. } => check_anytop(features, skeleton),
        }
    }

    /// The representation's name, as `--repr` spells it.
    pub fn repr_name(&self) -> &'static str {
        match self {
            Decoder::M2m => "m2m",
            Decoder::AnyTop { .. } => "anytop",
        }
    }

    /// Decode sample `i`; a motion with a NaN or an infinity (a placement or features too large
    /// to pose) is an error, never a BVH that no reader takes.
    pub fn decode(&self, i: usize, features: &Features, skeleton: &Skeleton) -> Result<Motion, String> {
        let motion = self.decode_unchecked(i, features, skeleton)?;
        match motion.first_non_finite() {
            Some((frame, joint)) => Err(format!(
                "decoding gives a non-finite pose at frame {frame}, joint {joint} '{}' (the features or the placement hold numbers too large)",
                skeleton.joints.get(joint).map_or("?", |j| j.name.as_str())
            )),
            None => Ok(motion),
        }
    }

    fn decode_unchecked(&self, i: usize, features: &Features, skeleton: &Skeleton) -> Result<Motion, String> {
        match self {
            Decoder::M2m => m2m::decode(features, skeleton).map_err(|e| e.to_string()),
            Decoder::AnyTop { rig, stats, placements, from } => {
                let features = match stats {
                    Some(stats) => {
                        let mut f = features.clone();
                        stats.denormalise(&mut f).map_err(|e| format!("cannot undo the normalisation: {e}"))?;
                        Cow::Owned(f)
                    }
                    None => Cow::Borrowed(features),
                };
                let placement = &placements[i];
                match from {
                    DecodeFrom::Rotations => rig.decode(skeleton, &features, placement),
                    DecodeFrom::Positions => rig.decode_ik(skeleton, &features, placement, &IkOptions::default()),
                }
                .map_err(|e| e.to_string())
            }
        }
    }
}

/// AnyTop's shape and value checks, worded like m2m's.
fn check_anytop(features: &Features, skeleton: &Skeleton) -> Result<(), (String, &'static str)> {
    if features.dims != anytop::FEATURE_DIMS {
        let hint = if features.dims == m2m::DIMS { ": Motion2Motion features? decode them with --repr m2m" } else { "" };
        return Err((format!("AnyTop features have {} dims per joint, found {}", anytop::FEATURE_DIMS, features.dims), hint));
    }
    if features.joints != skeleton.len() {
        return Err((format!("the features have {} joints but the skeleton has {}", features.joints, skeleton.len()), ""));
    }
    if let Some((frame, joint, dim)) = features.first_non_finite() {
        let value = features.at(frame, joint)[dim];
        let name = &skeleton.joints[joint].name;
        return Err((format!("non-finite value {value} at frame {frame}, joint {joint} '{name}', dim {dim}"), ""));
    }
    Ok(())
}

/// Rank 3 -> one motion; rank 4 -> one per sample (`true`: the input was a batch).
pub fn split_samples(array: NpyArray, name: &str) -> anyhow::Result<(Vec<Features>, bool)> {
    match array.shape.as_slice() {
        shape if shape.len() >= 3 && shape[shape.len() - 3] == 0 => {
            bail!("{name}: the features hold no frames (shape {shape:?})")
        }
        &[frames, joints, dims] => Ok((vec![Features { frames, joints, dims, data: array.data }], false)),
        &[n, frames, joints, dims] => {
            if n == 0 {
                bail!("{name}: the batch holds no samples (shape {:?})", array.shape);
            }
            let per = frames * joints * dims;
            let samples = (0..n).map(|i| Features { frames, joints, dims, data: array.data[i * per..(i + 1) * per].to_vec() }).collect();
            Ok((samples, true))
        }
        shape => bail!("{name}: expected a [frames, joints, dims] or [samples, frames, joints, dims] array, found shape {shape:?} (rank {})", shape.len()),
    }
}

impl SkeletonArg {
    /// The rest pose a rig is built on when nobody names one (AnyTop's rule, as `skel-info`
    /// applies it): frames 0-1 of the BVH, else the OFFSET pose of a document.
    pub fn own_rest(&self) -> (Motion, RestSource) {
        match &self.motion {
            Some(motion) if motion.frames > 0 => {
                let file = self.name.clone();
                (motion.first_frames(2), if self.tpose { RestSource::TPose { file } } else { RestSource::FirstClip { file } })
            }
            _ => (Motion::rest(&self.skeleton), RestSource::Offsets),
        }
    }

    /// The AnyTop record this skeleton stands for, without override flags: the document's own
    /// record, else one built on `own_rest` with the default options (no statistics).
    pub fn record(&self) -> anyhow::Result<AnyTopSection> {
        if let Some(section) = &self.document.anytop {
            return Ok(section.clone());
        }
        let (rest, rest_source) = self.own_rest();
        let options = RigOptions { rest_source, ..RigOptions::default() };
        AnyTopSection::new(&self.skeleton, &rest, &options).with_context(|| format!("{}: cannot build an AnyTop rig", self.name))
    }
}

/// One motion read from a file: a BVH, or one sample of an NPY decoded on a skeleton.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// File name, with `[i]` for the samples of an NPY batch.
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
}

/// How `load_motions` reads NPY inputs.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions<'a> {
    /// The skeleton NPY features are decoded on (document or BVH); BVH inputs ignore it.
    pub skeleton: Option<&'a Path>,
    /// AnyTop features: decode from rotations (default) or positions.
    pub from: Option<DecodeFrom>,
}

/// Files named by the command line: files as given, directories as the BVH, glTF (`.gltf`,
/// `.glb`) and NPY files directly inside them (sorted by name, so the order never depends on the file system).
pub fn expand_inputs(inputs: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let entries = std::fs::read_dir(input).with_context(|| format!("cannot list {}", input.display()))?;
            let mut files: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && p.extension().is_some_and(|x| ["bvh", "npy", "glb", "gltf"].iter().any(|e| x.eq_ignore_ascii_case(e))))
                .collect();
            if files.is_empty() {
                bail!("{}: the directory holds no .bvh, .glb, .gltf or .npy files", input.display());
            }
            files.sort();
            out.extend(files);
        } else {
            out.push(input.clone());
        }
    }
    if out.iter().filter(|p| is_dash(p)).count() > 1 {
        bail!("stdin ('-') can be read only once");
    }
    Ok(out)
}

/// One BVH clip of a tool's example clips (`mo-retarget`'s TARGETS, `mo-sample --examples`).
pub struct BvhClip {
    pub name: String,
    pub skeleton: Skeleton,
    pub motion: Motion,
}

/// Read one BVH clip; `tool` names the tool in the message an NPY file gets.
pub fn read_bvh_clip(path: &Path, tool: &str) -> anyhow::Result<BvhClip> {
    let name = io::display_name(path);
    let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
    if npy::looks_like_npy(path, &bytes) {
        bail!("{name}: {tool} reads BVH or glTF files (decode features first: mo-encode --decode)");
    }
    let parsed = parse_motion(&bytes, &name, path)?;
    let skeleton = Skeleton::from_bvh(&parsed);
    skeleton.validate().with_context(|| name.clone())?;
    let motion = Motion::from_bvh(&parsed, &skeleton);
    Ok(BvhClip { name, skeleton, motion })
}

/// Example clips of one skeleton and one frame rate: BVH files or directories of them (read in
/// parallel, kept in input order). `what` names them in messages ("target clips").
pub fn read_example_clips(inputs: &[PathBuf], tool: &str, what: &str) -> anyhow::Result<Vec<BvhClip>> {
    use rayon::prelude::*;
    let files = expand_inputs(inputs)?;
    let clips = files.par_iter().map(|p| read_bvh_clip(p, tool)).collect::<anyhow::Result<Vec<BvhClip>>>()?;
    let Some(first) = clips.first() else { bail!("no {what} were given") };
    for c in &clips[1..] {
        if let Some(why) = first.skeleton.first_difference(&c.skeleton) {
            bail!("{} and {} have different skeletons ({why}): all {what} must share one skeleton", first.name, c.name);
        }
    }
    let ft = first.motion.frame_time;
    if let Some(c) = clips.iter().find(|c| (c.motion.frame_time - ft).abs() > 1e-6 * ft) {
        bail!("{} runs at {:.3} fps but {} at {:.3} fps: give {what} of one frame rate", c.name, 1.0 / c.motion.frame_time, first.name, 1.0 / ft);
    }
    Ok(clips)
}

/// Read motions from BVH files and NPY feature files (recognised by content), in input order.
/// NPY inputs need `options.skeleton`; a batch `[n, frames, joints, dims]` gives n motions.
/// AnyTop features (13 dims) decode with the skeleton's AnyTop record and each clip at the rest
/// placement (features do not say where a clip stood); Motion2Motion features (9 dims) decode
/// as `mo-encode --repr m2m --decode` does.
pub fn load_motions(inputs: &[PathBuf], options: &LoadOptions) -> anyhow::Result<Vec<Loaded>> {
    use rayon::prelude::*;
    let skeleton = std::sync::OnceLock::new();
    let read_one = |path: &PathBuf| -> anyhow::Result<Vec<Loaded>> {
        let name = io::display_name(path);
        let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
        if npy::looks_like_npy(path, &bytes) {
            let path = options.skeleton.with_context(|| format!("{name} is an NPY feature file: give --skeleton (a skeleton document or BVH) to decode it"))?;
            let arg = match skeleton.get_or_init(|| read_skeleton(path).map_err(|e| format!("{e:#}"))) {
                Ok(arg) => arg,
                Err(e) => bail!("{e}"),
            };
            let array = npy::from_bytes(&bytes, &name)?;
            drop(bytes);
            decode_npy(array, &name, arg, options.from.unwrap_or(DecodeFrom::Rotations))
        } else {
            let parsed = parse_motion(&bytes, &name, path)?;
            drop(bytes);
            let skeleton = Skeleton::from_bvh(&parsed);
            skeleton.validate().with_context(|| name.clone())?;
            let motion = Motion::from_bvh(&parsed, &skeleton);
            Ok(vec![Loaded { name, skeleton, motion }])
        }
    };
    let loaded: Vec<anyhow::Result<Vec<Loaded>>> = inputs.par_iter().map(read_one).collect();
    let mut out = Vec::new();
    for l in loaded {
        out.extend(l?);
    }
    Ok(out)
}

/// The samples of one NPY as motions on `arg`'s skeleton.
fn decode_npy(array: NpyArray, name: &str, arg: &SkeletonArg, from: DecodeFrom) -> anyhow::Result<Vec<Loaded>> {
    let (samples, batch) = split_samples(array, name)?;
    let dims = samples[0].dims;
    let decoder = if dims == m2m::DIMS {
        Decoder::M2m
    } else {
        let section = arg.record()?;
        let placements = vec![section.rig.rest_placement(); samples.len()];
        Decoder::AnyTop { rig: Box::new(section.rig), stats: None, placements, from }
    };
    let label = |i: usize| if batch { format!("{name}[{i}]") } else { name.to_string() };
    let mut out = Vec::with_capacity(samples.len());
    for (i, f) in samples.iter().enumerate() {
        decoder.check(f, &arg.skeleton).map_err(|(e, hint)| anyhow!("{}: {e} ({} features, skeleton {}){hint}", label(i), decoder.repr_name(), arg.name))?;
        let motion = decoder.decode(i, f, &arg.skeleton).map_err(|e| anyhow!("{}: {e}", label(i)))?;
        out.push(Loaded { name: label(i), skeleton: arg.skeleton.clone(), motion });
    }
    Ok(out)
}
