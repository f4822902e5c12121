use menagerie::cli::{self, mo_dift};

fn main() -> std::process::ExitCode {
    cli::main::<mo_dift::Args>("mo-dift", mo_dift::run)
}
