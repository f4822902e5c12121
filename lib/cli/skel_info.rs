//! `skel-info`: BVH -> skeleton document (JSON) or a readable tree.

use crate::cli::CommonOpts;
use crate::document::{AnyTopSection, MotionInfo, SkeletonDocument};
use crate::motion::Motion;
use crate::repr::anytop::{self, RestSource};
use crate::skeleton::names::Side;
use crate::skeleton::{topology, Skeleton};
use crate::{bvh, io};
use anyhow::Context;
use std::fmt::Write as _;
use std::path::PathBuf;

const EXAMPLES: &str = "\
EXAMPLES:
    skel-info examples/data/biped.bvh --pretty
    skel-info examples/data/spider.bvh --format text
    cat examples/data/snake.bvh | skel-info - --dmax 3 -o snake.json
    skel-info examples/data/*.bvh > zoo.jsonl";

/// Print a BVH file's skeleton: graph, topology, names, sides, feet, rest pose.
///
/// Reads one or more BVH files (or '-' for stdin) and prints, for each, the skeleton document
/// (JSON, one document per input, separated by newlines) that the other menagerie tools read:
/// joint names (raw and normalised), parents, offsets, channels, End Sites, frame time,
/// AnyTop's topology descriptors (relations R, distances D capped at --dmax, kinematic chains,
/// end effectors, feet), sides, rest-pose positions, height and bone-length statistics. The
/// document holds enough to write the BVH hierarchy back without the original file. Its JSON
/// Schema is docs/skeleton.schema.json.
///
/// With --format text it prints a readable tree and a summary instead.
#[derive(clap::Parser, Debug)]
#[command(name = "skel-info", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH files to inspect ('-' = stdin).
    #[arg(value_name = "BVH", required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Json)]
    pub format: Format,
    /// Cap for graph distances D (AnyTop uses 5).
    #[arg(long, value_name = "N", default_value_t = topology::DEFAULT_DMAX as u8, value_parser = clap::value_parser!(u8).range(1..=64))]
    pub dmax: u8,
    /// Indent the JSON for humans.
    #[arg(long)]
    pub pretty: bool,
    /// Take AnyTop's natural rest pose from frame 0 of this BVH (same skeleton) instead of
    /// frame 0 of each input.
    #[arg(long, value_name = "BVH")]
    pub rest_pose: Option<PathBuf>,
    /// Leave out the AnyTop record (rig, rest-pose features P_S, normalisation statistics).
    #[arg(long)]
    pub no_anytop: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Json,
    Text,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    if args.inputs.iter().filter(|p| p.as_os_str() == "-").count() > 1 {
        anyhow::bail!("stdin ('-') can be read only once");
    }
    let rest_pose = match &args.rest_pose {
        Some(path) => {
            let name = io::display_name(path);
            let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
            let parsed = crate::cli::load::parse_motion(&bytes, &name, path)?;
            if parsed.frames == 0 {
                anyhow::bail!("--rest-pose {name}: the file has no frames (the rest pose is its frame 0)");
            }
            let skeleton = Skeleton::from_bvh(&parsed);
            Some((name, skeleton.clone(), Motion::from_bvh_frames(&parsed, &skeleton, 0..2)))
        }
        None => None,
    };
    let mut out = String::new();
    for path in &args.inputs {
        let name = io::display_name(path);
        let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
        let parsed = crate::cli::load::parse_motion(&bytes, &name, path)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        let mut doc = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, args.dmax as usize);
        if !args.no_anytop {
            doc.anytop = anytop_section(&parsed, &skeleton, &name, rest_pose.as_ref(), args.common.quiet)?;
        }
        match args.format {
            Format::Json => {
                let json = if args.pretty { serde_json::to_string_pretty(&doc) } else { serde_json::to_string(&doc) };
                out.push_str(&json.context("serialising the skeleton document")?);
                out.push('\n');
            }
            Format::Text => out.push_str(&text_report(&doc)),
        }
    }
    Ok(io::write_output(args.common.output.as_deref(), out.as_bytes())?)
}

/// AnyTop's record for one input: the rest pose is frame 0 of `--rest-pose` when given, else
/// frame 0 of the input itself (AnyTop's choice when there is no T-pose file), else, for a
/// file without frames, the OFFSET pose.
fn anytop_section(
    parsed: &bvh::Bvh,
    skeleton: &Skeleton,
    name: &str,
    rest_pose: Option<&(String, Skeleton, Motion)>,
    quiet: bool,
) -> anyhow::Result<Option<AnyTopSection>> {
    let motion = Motion::from_bvh(parsed, skeleton);
    let (rest, source) = match rest_pose {
        Some((file, rest_skeleton, rest)) => {
            let same = rest_skeleton.joints.len() == skeleton.joints.len()
                && rest_skeleton.joints.iter().zip(&skeleton.joints).all(|(a, b)| a.name == b.name && a.parent == b.parent);
            if !same {
                anyhow::bail!("--rest-pose {file} has a different skeleton than {name}");
            }
            (rest.clone(), RestSource::Explicit { file: file.clone() })
        }
        None if parsed.frames > 0 => {
            let file = name.to_string();
            let source = if anytop::names_tpose(&file) { RestSource::TPose { file } } else { RestSource::FirstClip { file } };
            (motion.first_frames(2), source)
        }
        None => (Motion::rest(skeleton), RestSource::Offsets),
    };
    // A skeleton AnyTop cannot describe (a single joint, bones of zero length) is still a
    // skeleton: describe it without the record and say why.
    match AnyTopSection::build(skeleton, &rest, source, &[&motion]) {
        Ok(section) => Ok(Some(section)),
        Err(e) => {
            if !quiet {
                eprintln!("skel-info: {name}: no AnyTop record: {e}");
            }
            Ok(None)
        }
    }
}

/// A readable tree and summary of one skeleton document.
pub fn text_report(doc: &SkeletonDocument) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}", doc.source);
    let children = {
        let mut c = vec![Vec::new(); doc.joints.len()];
        for (j, e) in doc.joints.iter().enumerate() {
            if let Some(p) = e.parent {
                c[p].push(j);
            }
        }
        c
    };
    let name_width = doc.joints.iter().map(|e| e.name.chars().count() + 2 * e.depth).max().unwrap_or(0).min(60);
    let norm_width = doc.joints.iter().map(|e| e.normalised.chars().count()).max().unwrap_or(0).min(40);
    // Depth-first with explicit stack; tree glyphs from each ancestor's "is last child" state.
    let mut stack: Vec<(usize, Vec<bool>)> = vec![(0, Vec::new())];
    while let Some((j, lasts)) = stack.pop() {
        let e = &doc.joints[j];
        let mut prefix = String::new();
        for (k, &last) in lasts.iter().enumerate() {
            prefix.push_str(if k + 1 == lasts.len() {
                if last {
                    "└─"
                } else {
                    "├─"
                }
            } else if last {
                "  "
            } else {
                "│ "
            });
        }
        let label = format!("{prefix}{}", e.name);
        let pad = name_width.saturating_sub(label.chars().count());
        let side = match e.side {
            Side::Left => "L",
            Side::Right => "R",
            Side::Centre => "·",
        };
        let mut marks = String::new();
        if e.foot {
            marks.push_str(" foot");
        }
        if e.end_effector {
            marks.push_str(" end");
        }
        let _ = writeln!(
            s,
            "  {label}{:pad$}  {:<norm_width$}  {side}  [{:>8.3} {:>8.3} {:>8.3}]  {}ch{marks}",
            "",
            e.normalised,
            e.offset[0],
            e.offset[1],
            e.offset[2],
            e.channels.len(),
        );
        let kids = &children[j];
        for (k, &c) in kids.iter().enumerate().rev() {
            let mut l = lasts.clone();
            l.push(k + 1 == kids.len());
            stack.push((c, l));
        }
    }
    let t = &doc.topology;
    let names = |idx: &[usize]| idx.iter().map(|&j| doc.joints[j].name.as_str()).collect::<Vec<_>>().join(", ");
    let _ = writeln!(
        s,
        "  joints: {}   chains: {}   end effectors: {}   max depth: {}",
        doc.joint_count,
        t.chains.len(),
        t.end_effectors.len(),
        doc.joints.iter().map(|e| e.depth).max().unwrap_or(0)
    );
    let _ = writeln!(s, "  feet ({:?}): {}", t.foot_rule, if t.feet.is_empty() { "none".into() } else { names(&t.feet) });
    let sides = |side: Side| doc.joints.iter().filter(|e| e.side == side).count();
    let _ = writeln!(s, "  sides: {} left, {} right, {} centre", sides(Side::Left), sides(Side::Right), sides(Side::Centre));
    let r = &doc.rest_pose;
    let _ = write!(s, "  rest pose: height {:.4}, extent {:.4}", r.height, r.extent);
    if let Some(b) = &r.bone_length {
        let _ = write!(s, ", bone length {:.4}..{:.4} (mean {:.4})", b.min, b.max, b.mean);
    }
    s.push('\n');
    if let Some(a) = &doc.anytop {
        let rig = &a.rig;
        let facing = match &rig.facing {
            crate::repr::anytop::Facing::FaceJoints(f) => format!("face joints {}", names(f)),
            crate::repr::anytop::Facing::BodyAxis { front, back } => {
                format!("body axis {} -> {}", doc.joints[*back].name, doc.joints[*front].name)
            }
        };
        let _ = writeln!(
            s,
            "  anytop: scale {:.5}, {facing}, {} contact joints, statistics {}",
            rig.scale_factor,
            rig.feet.len(),
            if a.stats.is_some() { "yes" } else { "no" }
        );
    }
    match &doc.motion {
        Some(m) => {
            let _ = writeln!(s, "  motion: {} frames at {:.3} fps ({:.2} s)", m.frames, m.fps, m.duration_s);
        }
        None => {
            let _ = writeln!(s, "  motion: none (frame time {})", doc.frame_time);
        }
    }
    s
}
