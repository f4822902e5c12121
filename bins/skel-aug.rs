use clap::Parser;
use menagerie::cli::{finish, skel_aug};

fn main() -> std::process::ExitCode {
    let args = skel_aug::Args::parse();
    finish("skel-aug", skel_aug::run(&args))
}
