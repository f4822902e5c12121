use menagerie::cli::{self, mo_segment};

fn main() -> std::process::ExitCode {
    cli::main::<mo_segment::Args>("mo-segment", mo_segment::run)
}
