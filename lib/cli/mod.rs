//! What every binary shares: the common options, the error-to-exit-code mapping, and the
//! clap commands of all tools (so man pages and completions are generated from the very
//! definitions that parse the arguments).
//!
//! Exit codes: 0 ok; 2 usage, I/O or data error; 130 for an interrupted `mo-train` ([`Exit`];
//! 1, a valid negative answer, arrives with the first tool that has one, e.g. a metrics check).
//! Errors print as one line, `tool: what went wrong: why`. A closed stdout (`| head`) is success.

pub mod bounds;
pub mod docs;
pub mod load;
pub mod mo_dift;
pub mod mo_edit;
pub mod mo_encode;
pub mod mo_metrics;
pub mod mo_render;
pub mod mo_retarget;
pub mod mo_sample;
pub mod mo_sample_examples;
pub mod mo_segment;
pub mod mo_train;
pub mod ood;
pub mod output;
pub mod skel_aug;
pub mod skel_info;

use std::path::PathBuf;
use std::process::ExitCode;

/// Options every tool accepts (flattened into each tool's arguments).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct CommonOpts {
    /// Write output here instead of stdout ('-' = stdout). Files are written atomically.
    #[arg(short = 'o', long, value_name = "PATH", global = true)]
    pub output: Option<PathBuf>,
    /// Seed for everything random; the same seed and input give byte-identical output.
    #[arg(long, value_name = "N", default_value_t = 0, global = true)]
    pub seed: u64,
    /// Print nothing on stderr but errors.
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// Print more about what is happening on stderr.
    #[arg(short, long, global = true, conflicts_with = "quiet")]
    pub verbose: bool,
    /// Worker threads (default: all cores; at most 256). Output never depends on this.
    #[arg(long, value_name = "N", global = true, value_parser = bounds::count(1, bounds::MAX_THREADS))]
    pub threads: Option<usize>,
    /// glTF inputs: the animation that becomes the motion, by name or by index from 0 (default: the first).
    #[arg(long, value_name = "NAME|INDEX", global = true)]
    pub animation: Option<String>,
    /// glTF inputs: sample the animation at this frame rate (default: at its keyframe times).
    #[arg(long, value_name = "FPS", global = true, value_parser = bounds::positive(1000.0))]
    pub fps: Option<f64>,
}

impl CommonOpts {
    /// Apply `--threads` to rayon's global pool, once per process (later calls, as in tests
    /// that run tools in one process, return the first one's result). A pool that cannot be
    /// built is an error: rayon would panic at its first use afterwards. Also hands the glTF
    /// input options to the one loader (`load::set_gltf_options`).
    pub fn init_threads(&self) -> anyhow::Result<()> {
        load::set_gltf_options(crate::gltf::ReadOptions {
            animation: self.animation.as_deref().map_or(crate::gltf::AnimationChoice::First, crate::gltf::AnimationChoice::parse),
            fps: self.fps,
            max_frames: bounds::MAX_FRAMES,
        });
        static BUILT: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
        let Some(n) = self.threads else { return Ok(()) };
        let built = BUILT.get_or_init(|| rayon::ThreadPoolBuilder::new().num_threads(n).build_global().map_err(|e| e.to_string()));
        built.clone().map_err(|e| anyhow::anyhow!("cannot start {n} worker threads: {e}"))
    }
}

impl CommonOpts {
    /// Messages on stderr for `tool`, as `-q` and `-v` say.
    pub fn say(&self, tool: &'static str) -> output::Say {
        output::Say { tool, quiet: self.quiet, verbose: self.verbose }
    }
}

/// Parse a tool's arguments. `--help` and `--version` print as clap prints them; a usage
/// error is one line, `tool: what went wrong (see --help)`, and exit code 2.
pub fn parse<A: clap::Parser>(tool: &str) -> Result<A, ExitCode> {
    A::try_parse().map_err(|e| {
        use clap::error::ErrorKind;
        match e.kind() {
            ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                let _ = e.print();
                ExitCode::SUCCESS
            }
            _ => {
                eprintln!("{tool}: {} (see --help)", usage_line(&e));
                ExitCode::from(2)
            }
        }
    })
}

/// clap's message without its usage block and tips: the lines before the first blank one,
/// joined, without the `error: ` prefix.
fn usage_line(e: &clap::Error) -> String {
    if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        return "a subcommand is required".to_string();
    }
    let text = e.render().to_string();
    let lines: Vec<&str> = text.lines().map(str::trim).take_while(|l| !l.is_empty()).collect();
    let line = lines.join(" ");
    line.strip_prefix("error: ").unwrap_or(&line).trim_end_matches('.').to_string()
}

/// A whole tool: parse the arguments, remove temporary output files on Ctrl-C, SIGTERM and
/// SIGHUP (then exit 130), run, and turn the result into an exit code.
pub fn main<A: clap::Parser>(tool: &str, run: impl FnOnce(&A) -> anyhow::Result<()>) -> ExitCode {
    let args = match parse::<A>(tool) {
        Ok(a) => a,
        Err(code) => return code,
    };
    // Fails only when a handler is already set (a test calling this twice): keep that one.
    let _ = ctrlc::set_handler(|| crate::io::output::remove_temps_and_exit(130));
    finish(tool, run(&args))
}

/// Run a tool's body and turn its result into an exit code, printing errors as one line.
pub fn finish(tool: &str, result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if is_broken_pipe(&e) {
                return ExitCode::SUCCESS;
            }
            let msg = format!("{e:#}").replace('\n', " ");
            eprintln!("{tool}: {msg}");
            ExitCode::from(exit_code(&e))
        }
    }
}

/// An error that ends a tool with its own exit code rather than 2, e.g. 130 for an
/// interrupted `mo-train` (as coreutils' `UError::code`).
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Exit {
    pub code: u8,
    pub message: String,
}

/// The exit code for `e`: an [`Exit`]'s anywhere in its chain, else 2.
pub fn exit_code(e: &anyhow::Error) -> u8 {
    e.chain().find_map(|c| c.downcast_ref::<Exit>()).map_or(2, |x| x.code)
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe))
}

/// Every tool's clap command, for man pages, completions and help tests.
pub fn all_commands() -> Vec<clap::Command> {
    use clap::CommandFactory;
    vec![
        skel_info::Args::command(),
        skel_aug::Args::command(),
        mo_encode::Args::command(),
        mo_retarget::Args::command(),
        mo_metrics::Args::command(),
        mo_render::Args::command(),
        mo_train::Args::command(),
        mo_sample::Args::command(),
        mo_dift::Args::command(),
        mo_segment::Args::command(),
        mo_edit::Args::command(),
    ]
}
