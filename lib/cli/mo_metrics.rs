//! `mo-metrics`: evaluation metrics (being written).

use crate::cli::CommonOpts;
use std::path::PathBuf;

/// Score motion: generation, transfer, reconstruction and physics metrics.
#[derive(clap::Parser, Debug)]
#[command(name = "mo-metrics", version)]
pub struct Args {
    /// Motion files.
    pub inputs: Vec<PathBuf>,
    #[command(flatten)]
    pub common: CommonOpts,
}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
