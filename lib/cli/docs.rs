//! Man pages and shell completions, generated from the same clap commands that parse the
//! arguments, so they cannot drift. They are committed under man/ and completions/ (users and
//! packagers get them without building), and `tests/it/generated_docs.rs` fails when they are
//! stale; `MENAGERIE_BLESS=1 cargo test --test it generated_docs` rewrites them.

use clap_complete::Shell;

/// (relative path, contents) of every generated file.
pub fn generated_files() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for cmd in super::all_commands() {
        let name = cmd.get_name().to_string();
        let mut man = Vec::new();
        // Writing into a Vec cannot fail.
        let _ = clap_mangen::Man::new(cmd.clone()).render(&mut man);
        files.push((format!("man/{name}.1"), man));
        for (shell, path) in
            [(Shell::Bash, format!("completions/{name}.bash")), (Shell::Zsh, format!("completions/_{name}")), (Shell::Fish, format!("completions/{name}.fish"))]
        {
            let mut out = Vec::new();
            let mut c = cmd.clone();
            clap_complete::generate(shell, &mut c, name.clone(), &mut out);
            files.push((path, out));
        }
    }
    files
}
