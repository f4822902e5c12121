use clap::Parser;
use menagerie::cli::{finish, mo_segment};

fn main() -> std::process::ExitCode {
    let args = mo_segment::Args::parse();
    finish("mo-segment", mo_segment::run(&args))
}
