use menagerie::cli::{self, mo_metrics};

fn main() -> std::process::ExitCode {
    cli::main::<mo_metrics::Args>("mo-metrics", mo_metrics::run)
}
