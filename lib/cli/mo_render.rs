//! `mo-render`: pictures of motion (being written).

use crate::cli::CommonOpts;
use std::path::PathBuf;

/// Draw motion: contact sheets (PNG), animations (GIF), a browser viewer (HTML).
#[derive(clap::Parser, Debug)]
#[command(name = "mo-render", version)]
pub struct Args {
    /// BVH files, or NPY files with --skeleton.
    pub inputs: Vec<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
