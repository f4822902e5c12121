use menagerie::cli::{self, skel_aug};

fn main() -> std::process::ExitCode {
    cli::main::<skel_aug::Args>("skel-aug", skel_aug::run)
}
