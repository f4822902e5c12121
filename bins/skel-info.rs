use menagerie::cli::{self, skel_info};

fn main() -> std::process::ExitCode {
    cli::main::<skel_info::Args>("skel-info", skel_info::run)
}
