use clap::Parser;
use menagerie::cli::{finish, mo_dift};

fn main() -> std::process::ExitCode {
    let args = mo_dift::Args::parse();
    finish("mo-dift", mo_dift::run(&args))
}
