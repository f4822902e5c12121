use menagerie::cli::{self, mo_encode};

fn main() -> std::process::ExitCode {
    cli::main::<mo_encode::Args>("mo-encode", mo_encode::run)
}
