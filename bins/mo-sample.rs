use menagerie::cli::{self, mo_sample};

fn main() -> std::process::ExitCode {
    cli::main::<mo_sample::Args>("mo-sample", mo_sample::run)
}
