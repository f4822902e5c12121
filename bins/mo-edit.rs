use menagerie::cli::{self, mo_edit};

fn main() -> std::process::ExitCode {
    cli::main::<mo_edit::Args>("mo-edit", mo_edit::run)
}
