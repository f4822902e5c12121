//! Committed man pages and completions must match what the clap definitions generate now.
//! Regenerate with `MENAGERIE_BLESS=1 cargo test --test it generated_docs`.

use std::path::Path;

#[test]
fn man_pages_and_completions_are_fresh() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bless = std::env::var_os("MENAGERIE_BLESS").is_some();
    let mut stale = Vec::new();
    for (rel, want) in menagerie::cli::docs::generated_files() {
        let path = root.join(&rel);
        if bless {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, &want).unwrap();
            continue;
        }
        match std::fs::read(&path) {
            Ok(have) if have == want => {}
            _ => stale.push(rel),
        }
    }
    assert!(stale.is_empty(), "stale generated files (run `MENAGERIE_BLESS=1 cargo test --test it generated_docs`): {stale:?}");
}
