//! `mo-encode`: work in progress.

use crate::cli::CommonOpts;

/// mo-encode (work in progress).
#[derive(clap::Parser, Debug)]
#[command(name = "mo-encode", version, after_long_help = EXAMPLES)]
pub struct Args {
    #[command(flatten)]
    pub common: CommonOpts,
}

const EXAMPLES: &str = "EXAMPLES:\n    mo-encode --version";

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
