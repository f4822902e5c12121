use menagerie::cli::{self, mo_render};

fn main() -> std::process::ExitCode {
    cli::main::<mo_render::Args>("mo-render", mo_render::run)
}
