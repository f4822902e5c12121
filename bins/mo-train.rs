use clap::Parser;
use menagerie::cli::mo_train;

fn main() -> std::process::ExitCode {
    let args = mo_train::Args::parse();
    // Not `cli::finish`: an interrupted run exits 130, not 2.
    mo_train::main(&args)
}
