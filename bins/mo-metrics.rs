use clap::Parser;
use menagerie::cli::{finish, mo_metrics};

fn main() -> std::process::ExitCode {
    let args = mo_metrics::Args::parse();
    finish("mo-metrics", mo_metrics::run(&args))
}
