use clap::Parser;
use menagerie::cli::{finish, mo_train};

fn main() -> std::process::ExitCode {
    let args = mo_train::Args::parse();
    finish("mo-train", mo_train::run(&args))
}
