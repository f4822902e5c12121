use menagerie::cli::{self, mo_train};

fn main() -> std::process::ExitCode {
    let args = match cli::parse::<mo_train::Args>("mo-train") {
        Ok(a) => a,
        Err(code) => return code,
    };
    // Not `cli::main`: mo-train owns Ctrl-C (it checkpoints; an interrupted run exits 130).
    cli::finish("mo-train", mo_train::run(&args))
}
