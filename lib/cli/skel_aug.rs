//! `skel-aug`: work in progress.

use crate::cli::CommonOpts;

/// skel-aug (work in progress).
#[derive(clap::Parser, Debug)]
#[command(name = "skel-aug", version, after_long_help = EXAMPLES)]
pub struct Args {
    #[command(flatten)]
    pub common: CommonOpts,
}

const EXAMPLES: &str = "EXAMPLES:\n    skel-aug --version";

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("not implemented yet")
}
