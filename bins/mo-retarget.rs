use clap::Parser;
use menagerie::cli::{finish, mo_retarget};

fn main() -> std::process::ExitCode {
    let args = mo_retarget::Args::parse();
    finish("mo-retarget", mo_retarget::run(&args))
}
