use menagerie::cli::{self, mo_retarget};

fn main() -> std::process::ExitCode {
    cli::main::<mo_retarget::Args>("mo-retarget", mo_retarget::run)
}
