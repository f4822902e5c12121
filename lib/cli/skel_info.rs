//! `skel-info`: BVH -> skeleton document (JSON) or a readable tree.

use crate::cli::CommonOpts;
use crate::document::{MotionInfo, SkeletonDocument};
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
    #[command(flatten)]
    pub common: CommonOpts,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Json,
    Text,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads();
    if args.inputs.iter().filter(|p| p.as_os_str() == "-").count() > 1 {
        anyhow::bail!("stdin ('-') can be read only once");
    }
    let mut out = String::new();
    for path in &args.inputs {
        let name = io::display_name(path);
        let bytes = io::read_input(path).with_context(|| format!("cannot read {name}"))?;
        let parsed = bvh::parse_bytes(&bytes, &name)?;
        let skeleton = Skeleton::from_bvh(&parsed);
        let doc = SkeletonDocument::build(&skeleton, MotionInfo::of(&parsed, &skeleton), &name, args.dmax as usize);
        match args.format {
            Format::Json => {
                let json = if args.pretty { serde_json::to_string_pretty(&doc) } else { serde_json::to_string(&doc) };
                out.push_str(&json.context("serialising the skeleton document")?);
                out.push('\n');
            }
            Format::Text => out.push_str(&text_report(&doc)),
        }
    }
    io::write_output(args.common.output.as_deref(), out.as_bytes())
        .with_context(|| format!("cannot write {}", args.common.output.as_ref().map_or("stdout".into(), |p| p.display().to_string())))
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
                if last { "└─" } else { "├─" }
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
    let _ = writeln!(s, "  joints: {}   chains: {}   end effectors: {}   max depth: {}", doc.joint_count, t.chains.len(), t.end_effectors.len(), doc.joints.iter().map(|e| e.depth).max().unwrap_or(0));
    let _ = writeln!(s, "  feet ({:?}): {}", t.foot_rule, if t.feet.is_empty() { "none".into() } else { names(&t.feet) });
    let sides = |side: Side| doc.joints.iter().filter(|e| e.side == side).count();
    let _ = writeln!(s, "  sides: {} left, {} right, {} centre", sides(Side::Left), sides(Side::Right), sides(Side::Centre));
    let r = &doc.rest_pose;
    let _ = write!(s, "  rest pose: height {:.4}, extent {:.4}", r.height, r.extent);
    if let Some(b) = &r.bone_length {
        let _ = write!(s, ", bone length {:.4}..{:.4} (mean {:.4})", b.min, b.max, b.mean);
    }
    s.push('\n');
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
