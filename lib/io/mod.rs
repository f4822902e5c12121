//! Where bytes come from and go to: `-` is stdin/stdout everywhere, and files are written
//! atomically (temp file in the same directory, then rename) so a crash or an error never
//! leaves half a file behind (`output` says how, and what happens to devices and symlinks).

pub mod npy;
pub mod output;
pub use output::{refuse_terminal, write_all, OutputError};
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// Read a whole input; `-` reads stdin.
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    if path.as_os_str() == "-" {
        let mut buf = Vec::new();
        io::stdin().lock().read_to_end(&mut buf)?;
        Ok(buf)
    } else {
        std::fs::read(path)
    }
}

/// Human name of an input for messages (`<stdin>` for `-`).
pub fn display_name(path: &Path) -> String {
    if path.as_os_str() == "-" {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    }
}

/// An input that could not be read, named as messages name it.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {name}")]
pub struct ReadError {
    pub name: String,
    #[source]
    pub source: io::Error,
}

/// An input's name for messages (`display_name`) and its bytes (`read_input`): what every tool
/// does first with a path it is given, with the one message for a failure.
pub fn read_named(path: &Path) -> Result<(String, Vec<u8>), ReadError> {
    let name = display_name(path);
    match read_input(path) {
        Ok(bytes) => Ok((name, bytes)),
        Err(source) => Err(ReadError { name, source }),
    }
}

/// Write `bytes` to `path` (see `output`), or to stdout when `path` is `-` or `None`.
pub fn write_output(path: Option<&Path>, bytes: &[u8]) -> Result<(), OutputError> {
    output::write_one(path, bytes)
}

/// Output path for item `i` of a batch: `{i}` in the pattern is replaced by the index.
/// A batch of more than one item needs the placeholder, so files never overwrite each other.
pub fn numbered_output(pattern: &Path, i: usize, count: usize) -> Result<PathBuf, String> {
    let text = pattern.to_string_lossy();
    if text.contains("{i}") {
        Ok(PathBuf::from(text.replace("{i}", &i.to_string())))
    } else if count <= 1 {
        Ok(pattern.to_path_buf())
    } else {
        Err(format!("{count} outputs need a numbered output path such as 'out_{{i}}.bvh', got '{text}'"))
    }
}

/// The outputs of a batch of `count` items: files numbered from `output`'s `{i}` pattern, or
/// stdout (`None`, for `None` and `-`) when there is one item. Several items on stdout are
/// refused; the message says "`count` `what` need ..." and ends with `hint`.
pub fn numbered_outputs(output: Option<&Path>, count: usize, what: &str, hint: &str) -> Result<Vec<Option<PathBuf>>, String> {
    match output {
        Some(p) if p.as_os_str() != "-" => (0..count).map(|i| numbered_output(p, i, count).map(Some)).collect(),
        _ if count > 1 => Err(format!("{count} {what} need a numbered output path such as -o 'out_{{i}}.bvh' {hint}")),
        _ => Ok(vec![None]),
    }
}

#[cfg(test)]
mod tests {
    use super::numbered_output;
    use std::path::{Path, PathBuf};

    #[test]
    fn output_patterns() {
        let batch = |o: Option<&str>, n| super::numbered_outputs(o.map(Path::new), n, "variants", "(hint)");
        assert_eq!(batch(None, 1).unwrap(), vec![None]);
        assert_eq!(batch(Some("-"), 1).unwrap(), vec![None]);
        assert_eq!(batch(None, 2).unwrap_err(), "2 variants need a numbered output path such as -o 'out_{i}.bvh' (hint)");
        assert!(batch(Some("-"), 2).is_err());
        assert!(batch(Some("a.bvh"), 2).is_err());
        assert_eq!(batch(Some("a_{i}.bvh"), 2).unwrap(), vec![Some(PathBuf::from("a_0.bvh")), Some(PathBuf::from("a_1.bvh"))]);
    }

    #[test]
    fn numbered_outputs() {
        assert_eq!(numbered_output(Path::new("a_{i}.bvh"), 3, 5).unwrap(), Path::new("a_3.bvh"));
        assert_eq!(numbered_output(Path::new("a.bvh"), 0, 1).unwrap(), Path::new("a.bvh"));
        assert!(numbered_output(Path::new("a.bvh"), 0, 2).is_err());
    }
}
