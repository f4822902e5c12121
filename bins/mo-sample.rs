use clap::Parser;
use menagerie::cli::{finish, mo_sample};

fn main() -> std::process::ExitCode {
    let args = mo_sample::Args::parse();
    finish("mo-sample", mo_sample::run(&args))
}
