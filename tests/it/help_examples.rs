//! Every `--help` ends with an EXAMPLES block of real pipelines; this runs each of them (in a
//! scratch directory that sees the project's examples/) and requires success.

use std::path::Path;
use std::process::Command;

#[test]
fn every_help_ends_with_examples_that_run() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_skel-info")).parent().unwrap().to_path_buf();
    let work = std::env::temp_dir().join(format!("menagerie-help-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    std::os::unix::fs::symlink(root.join("examples"), work.join("examples")).unwrap();
    let path = format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap_or_default());
    let mut ran = 0;
    for mut cmd in menagerie::cli::all_commands() {
        let name = cmd.get_name().to_string();
        let help = cmd.render_long_help().to_string();
        let (_, examples) = help.rsplit_once("EXAMPLES:").unwrap_or_else(|| panic!("{name} --help has no EXAMPLES block"));
        let lines: Vec<&str> = examples.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        assert!(!lines.is_empty(), "{name}: empty EXAMPLES block");
        for line in lines {
            assert!(line.starts_with(&name) || line.contains(&format!("| {name}")), "{name}: example does not use the tool: {line}");
            let out = Command::new("bash").arg("-o").arg("pipefail").arg("-c").arg(line).current_dir(&work).env("PATH", &path).output().unwrap();
            assert!(out.status.success(), "{name} example failed: {line}\nstderr: {}", String::from_utf8_lossy(&out.stderr));
            let writes_file = [" -o ", ">", " --sheet ", " --gif ", " --html ", " --out ", " --bvh "].iter().any(|w| line.contains(w));
            assert!(!out.stdout.is_empty() || writes_file, "{name} example printed nothing: {line}");
            ran += 1;
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    eprintln!("ran {ran} help examples");
}
