use clap::Parser;
use menagerie::cli::{finish, mo_render};

fn main() -> std::process::ExitCode {
    let args = mo_render::Args::parse();
    finish("mo-render", mo_render::run(&args))
}
