use clap::Parser;
use menagerie::cli::{finish, skel_info};

fn main() -> std::process::ExitCode {
    let args = skel_info::Args::parse();
    finish("skel-info", skel_info::run(&args))
}
