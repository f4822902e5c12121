//! `skel-info`: BVH -> skeleton document (JSON) or a readable tree.

use crate::cli::CommonOpts;
use crate::document::of_file::RestPose;
use crate::document::SkeletonDocument;
use crate::io;
use crate::skeleton::topology;
use anyhow::Context;
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
            let (name, bytes) = io::read_named(path)?;
            Some(RestPose::of_bvh(&crate::cli::load::parse_motion(&bytes, &name, path)?, &name)?)
        }
        None => None,
    };
    let mut out = String::new();
    for path in &args.inputs {
        let (name, bytes) = io::read_named(path)?;
        let parsed = crate::cli::load::parse_motion(&bytes, &name, path)?;
        let (doc, no_record) = SkeletonDocument::of_file(&parsed, &name, args.dmax as usize, !args.no_anytop, rest_pose.as_ref())?;
        if let (Some(e), false) = (no_record, args.common.quiet) {
            eprintln!("skel-info: {name}: no AnyTop record: {e}");
        }
        match args.format {
            Format::Json => {
                let json = if args.pretty { serde_json::to_string_pretty(&doc) } else { serde_json::to_string(&doc) };
                out.push_str(&json.context("serialising the skeleton document")?);
                out.push('\n');
            }
            Format::Text => out.push_str(&doc.text_report()),
        }
    }
    Ok(io::write_output(args.common.output.as_deref(), out.as_bytes())?)
}
