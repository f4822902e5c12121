//! `skel-aug`: skeletal augmentation of a BVH (motion carried over exactly) or a skeleton
//! document.

use crate::augment::source::Source;
use crate::augment::{self, RemoveAmount};
use crate::cli::CommonOpts;
use crate::io;
use anyhow::{bail, Context};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
EXAMPLES:
    skel-aug examples/data/biped.bvh --seed 1 -v -o biped_aug.bvh
    skel-aug examples/data/dragon.bvh --remove-rate 0.2 --add 3 -n 4 -o 'dragon_{i}.bvh'
    skel-aug examples/data/spider.bvh --no-remove --add 5 | skel-info - --format text
    skel-info examples/data/quadruped.bvh | skel-aug --seed 7 --pretty
    skel-aug examples/data/snake.bvh --allow-feet --remove-rate 0.2 -o snake_short.bvh
    cat examples/data/crab.bvh | skel-aug -n 3 -o 'crab_{i}.bvh'
    skel-aug examples/data/crab.bvh --no-remove -o crab.glb";

/// Augment a skeleton: remove end-effector chains, subdivide bones, keep the motion exact.
///
/// Reads one BVH (or glTF) file or skeleton document (JSON, recognised by a leading '{') and writes the
/// same kind back with a changed skeleton (AnyTop's skeletal augmentation, done as a real
/// edit of the hierarchy):
///
/// Remove (default): drop a fraction of the joints (--remove-rate, else a count drawn from the
/// seed between 10% and 30% of the joints) by cutting chains that end in end effectors. A chain
/// runs from an end effector up to, not including, the first joint that has several children,
/// is a foot or is the root; whole chains are taken in random order, and at most one is cut
/// short from its leaf end to hit the count. Feet, the root and branching joints are never
/// removed, so some skeletons (a centipede, whose legs all end in feet) cannot lose 10%; a
/// warning says so. The parent of a removed chain becomes an end effector and gets an End Site
/// where the removed bone ended.
///
/// Add (--add N, after any removal): insert N joints, each at the midpoint of a random bone:
/// the new joint (named <child>_mid) hangs from the bone's parent and the old joint from it,
/// the OFFSET is split in half, and the new joint has identity rotation in every frame, with
/// rotation channels in the split joint's Euler order. A split joint with position channels has
/// them shifted by the new OFFSET.
///
/// Every surviving joint keeps its exact world position in every frame; unchanged channels are
/// copied value for value. Joint order stays the file's (parents first, original order kept).
/// A skeleton document comes back rebuilt: names, sides, feet, R, D, chains and end effectors of
/// the new skeleton, with the input document's dmax. Its motion summary is dropped when the skeleton
/// changed (it needs the frames).
///
/// -n K writes K variants, each with its own random choices, to -o PATTERN where '{i}' becomes
/// 0..K-1. The same input, flags and --seed give byte-identical output.
#[derive(clap::Parser, Debug)]
#[command(name = "skel-aug", version, after_long_help = EXAMPLES)]
pub struct Args {
    /// BVH file or skeleton document (JSON) to augment ('-' = stdin).
    #[arg(value_name = "INPUT", default_value = "-")]
    pub input: PathBuf,
    /// Remove this fraction of the joints, in (0, 1), rounded, at least one [default: a count
    /// between 10% and 30% of the joints, drawn from the seed].
    #[arg(long, value_name = "R", allow_negative_numbers = true, conflicts_with = "no_remove")]
    pub remove_rate: Option<f64>,
    /// Remove nothing (to only --add).
    #[arg(long)]
    pub no_remove: bool,
    /// Insert N joints, each at the midpoint of a random bone (after any removal).
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = crate::cli::bounds::count(0, crate::cli::bounds::MAX_ADD_JOINTS))]
    pub add: usize,
    /// Let removal take feet too (for bodies that lie on the ground, like snakes, whose joints
    /// are all feet; AnyTop does the same for its snakes).
    #[arg(long)]
    pub allow_feet: bool,
    /// Write K variants with different random choices (-o must then contain '{i}').
    #[arg(short = 'n', long = "variants", value_name = "K", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=crate::cli::bounds::MAX_VARIANTS))]
    pub variants: u64,
    /// Indent JSON output for humans (skeleton documents only).
    #[arg(long)]
    pub pretty: bool,
    #[command(flatten)]
    pub common: CommonOpts,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    args.common.init_threads()?;
    let options = options(args)?;
    let count = usize::try_from(args.variants).context("too many variants")?;
    // Output paths first: a bad pattern fails before any work and before any output.
    let hint = format!("('{{i}}' becomes 0..{})", count.saturating_sub(1));
    let outputs = io::numbered_outputs(args.common.output.as_deref(), count, "variants", &hint).map_err(anyhow::Error::msg)?;

    let (name, bytes) = io::read_named(&args.input)?;
    let input = Source::parse(&bytes, &name, &args.input, &crate::cli::load::gltf_options())?;
    // Every variant is held until all are written (all or nothing); each has its frames.
    crate::budget::check("the variants' text", count as u128 * (bytes.len() as u128 + 64 * args.add as u128), 2)?;
    if let Source::Bvh(b) = &input {
        crate::budget::check_motion(&format!("{name}: the augmented motion"), b.frames, b.joints.len() + args.add)?;
    }
    let skeleton = input.skeleton(&name)?;

    let mut warned = BTreeSet::new();
    let mut texts = Vec::with_capacity(outputs.len());
    for (i, out) in outputs.iter().enumerate() {
        let mut rng = augment::variant_rng(args.common.seed, i);
        let plan = augment::plan(&skeleton, &options, &mut rng);
        let target = out.as_deref().map_or("stdout".to_string(), |p| p.display().to_string());
        if !args.common.quiet {
            for w in plan.shortfalls(&skeleton, args.add, options.keep_feet) {
                if warned.insert(w.clone()) {
                    eprintln!("skel-aug: warning: {name}: {w}");
                }
            }
        }
        if args.common.verbose {
            eprint!("skel-aug: {}", plan.describe(&name, &target));
        }
        let text = input.variant(&plan, i, args.common.seed, out.as_deref(), args.pretty)?;
        texts.push(text);
    }
    // All variants or none.
    let files: Vec<(Option<&Path>, &[u8])> = outputs.iter().zip(&texts).map(|(p, t)| (p.as_deref(), t.as_slice())).collect();
    Ok(io::write_all(&files)?)
}

fn options(args: &Args) -> anyhow::Result<augment::Options> {
    let remove = match (args.no_remove, args.remove_rate) {
        (true, _) => None,
        (false, None) => Some(RemoveAmount::Random),
        (false, Some(r)) if r > 0.0 && r < 1.0 => Some(RemoveAmount::Rate(r)),
        (false, Some(r)) => bail!("--remove-rate {r}: must be between 0 and 1, exclusive (use --no-remove to remove nothing)"),
    };
    Ok(augment::Options { remove, add: args.add, keep_feet: !args.allow_feet })
}
