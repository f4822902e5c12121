use clap::Parser;
use menagerie::cli::{finish, mo_encode};

fn main() -> std::process::ExitCode {
    let args = mo_encode::Args::parse();
    finish("mo-encode", mo_encode::run(&args))
}
