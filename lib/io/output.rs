//! Writing a run's outputs: all of them or none, without ever replacing what `-o` names by
//! something else.
//!
//! * A regular file (or a new name) is written to a temporary file beside it, then renamed over
//!   it, so readers never see half a file.
//! * A symlink is followed and its target written that way: the link stays a link.
//! * A device, FIFO or socket is opened and written in place. Renaming a regular file over it
//!   would replace the node itself (as root, `-o /dev/null` would break the machine's
//!   `/dev/null`). A write error there (ENOSPC from a full device) is an error like any other.
//! * Several outputs are committed together: every temporary file is written first, then
//!   devices, then every rename, then stdout (which cannot be taken back). A failure before the
//!   renames removes the temporary files and leaves every target as it was.
//!
//! Live temporary files are kept in a registry so a signal handler can remove them
//! (`remove_temps`); the handler itself is installed by the binaries (`cli::run_tool`), which
//! know whether something else (mo-train) owns Ctrl-C.

use std::fs::{self, File, OpenOptions};
use std::io::{self, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// What went wrong with an output; `path` is the path as the user gave it.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("cannot write {path}")]
    Write {
        path: String,
        #[source]
        source: io::Error,
    },
    #[error("cannot write {path}: it is a directory")]
    Directory { path: String },
    #[error("cannot write {path}: more than {MAX_LINKS} symbolic links to follow")]
    LinkLoop { path: String },
    #[error("refusing to write {what} to a terminal: {hint}")]
    Terminal { what: String, hint: String },
    #[error("{first} and {second} both write to stdout: give one of them a file")]
    BothStdout { first: String, second: String },
    #[error("{first} and {second} both write to {path}")]
    BothFile { first: String, second: String, path: String },
}

/// Symlinks followed before giving up (Linux's own limit).
const MAX_LINKS: usize = 40;

/// `None` and `-` are stdout.
fn is_stdout(path: Option<&Path>) -> bool {
    path.is_none_or(|p| p.as_os_str() == "-")
}

/// Refuse binary output to a terminal (it is never what anyone wants and can upset it).
/// `hint` says how to write it elsewhere.
pub fn refuse_terminal(path: Option<&Path>, what: &str, hint: &str) -> Result<(), OutputError> {
    if is_stdout(path) && io::stdout().is_terminal() {
        return Err(OutputError::Terminal { what: what.to_string(), hint: hint.to_string() });
    }
    Ok(())
}

/// Refuse two outputs of one run on one path (`-` is stdout); `outputs` are (what, path) in
/// order, and the message names the first pair that clashes.
pub fn distinct(outputs: &[(&str, &Path)]) -> Result<(), OutputError> {
    for (i, (second, path)) in outputs.iter().enumerate() {
        if let Some((first, _)) = outputs[..i].iter().find(|(_, p)| p == path) {
            let (first, second) = (first.to_string(), second.to_string());
            return Err(match is_stdout(Some(path)) {
                true => OutputError::BothStdout { first, second },
                false => OutputError::BothFile { first, second, path: path.display().to_string() },
            });
        }
    }
    Ok(())
}

/// How one file output is written.
enum Plan {
    /// Temp file beside `target`, renamed over it.
    Atomic { target: PathBuf, keep_mode: Option<fs::Permissions> },
    /// Opened and written in place (device, FIFO, socket).
    Direct { target: PathBuf },
}

/// Follow symlinks to the file that is really written; decide how to write it.
fn plan(path: &Path) -> Result<Plan, OutputError> {
    let name = || path.display().to_string();
    let mut target = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        let meta = match fs::symlink_metadata(&target) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Plan::Atomic { target, keep_mode: None }),
            Err(e) => return Err(OutputError::Write { path: name(), source: e }),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let link = fs::read_link(&target).map_err(|e| OutputError::Write { path: name(), source: e })?;
            target = match target.parent() {
                Some(dir) if link.is_relative() => dir.join(link),
                _ => link,
            };
        } else if kind.is_dir() {
            return Err(OutputError::Directory { path: name() });
        } else if kind.is_file() {
            return Ok(Plan::Atomic { target, keep_mode: Some(meta.permissions()) });
        } else {
            return Ok(Plan::Direct { target });
        }
    }
    Err(OutputError::LinkLoop { path: name() })
}

/// Temporary files this process has created and not yet renamed or removed.
static TEMPS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temps() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Remove every live temporary file (from a signal handler's thread, or before exiting). The
/// registry stays locked until the guard drops, so a caller that exits while holding it
/// (`remove_temps_and_exit`) leaves no window for a new temp file to appear.
fn remove_locked(list: &mut Vec<PathBuf>) {
    for p in list.drain(..) {
        let _ = fs::remove_file(p);
    }
}

/// Remove every live temporary file.
pub fn remove_temps() {
    remove_locked(&mut temps());
}

/// Remove every live temporary file and exit with `code`, holding the registry so no other
/// thread creates one in between. For signal handlers (which run on their own thread with
/// `ctrlc`, so taking a lock is safe).
pub fn remove_temps_and_exit(code: i32) -> ! {
    let mut list = temps();
    remove_locked(&mut list);
    std::process::exit(code)
}

/// Create a fresh temporary file beside `target` (`.NAME.tmpPID`, or with a suffix when that
/// name is taken), registered before it exists.
fn create_temp(target: &Path) -> io::Result<(PathBuf, File)> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let file_name = target.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path has no file name"))?;
    let base = format!(".{}.tmp{}", file_name.to_string_lossy(), std::process::id());
    let mut list = temps();
    for k in 0..1000 {
        let tmp = dir.join(if k == 0 { base.clone() } else { format!("{base}.{k}") });
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => {
                list.push(tmp.clone());
                return Ok((tmp, f));
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(io::ErrorKind::AlreadyExists, "no free temporary file name beside it"))
}

/// Remove one temporary file and forget it.
fn discard_temp(tmp: &Path) {
    let mut list = temps();
    list.retain(|p| p != tmp);
    let _ = fs::remove_file(tmp);
}

/// Rename a temporary file into place and forget it (under the registry lock, so a signal
/// handler never removes a file that is already the target).
fn commit_temp(tmp: &Path, target: &Path) -> io::Result<()> {
    let mut list = temps();
    let result = fs::rename(tmp, target);
    list.retain(|p| p != tmp);
    if result.is_err() {
        let _ = fs::remove_file(tmp);
    }
    result
}

fn write_temp(mut f: File, bytes: &[u8], keep_mode: Option<&fs::Permissions>) -> io::Result<()> {
    f.write_all(bytes)?;
    if let Some(mode) = keep_mode {
        f.set_permissions(mode.clone())?;
    }
    f.sync_all()
}

fn write_direct(target: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = OpenOptions::new().write(true).open(target)?;
    f.write_all(bytes)?;
    f.flush()
}

fn write_stdout(bytes: &[u8]) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(bytes)?;
    out.flush()
}

fn unstage(staged: &[(PathBuf, &Path, &Path)]) {
    for (tmp, _, _) in staged {
        discard_temp(tmp);
    }
}

/// Write every output or none. `None` and `-` are stdout, written last in the order given.
pub fn write_all(outputs: &[(Option<&Path>, &[u8])]) -> Result<(), OutputError> {
    let failed = |path: &Path, source: io::Error| OutputError::Write { path: path.display().to_string(), source };
    let files: Vec<(&Path, &[u8])> = outputs.iter().filter(|(p, _)| !is_stdout(*p)).map(|(p, b)| (p.expect("a file"), *b)).collect();
    let plans = files.iter().map(|(p, _)| plan(p)).collect::<Result<Vec<_>, _>>()?;

    // Stage: every temporary file written and synced.
    // (temporary file, target, the path as given)
    let mut staged: Vec<(PathBuf, &Path, &Path)> = Vec::new();
    for ((path, bytes), plan) in files.iter().zip(&plans) {
        if let Plan::Atomic { target, keep_mode } = plan {
            let written = create_temp(target).and_then(|(tmp, f)| match write_temp(f, bytes, keep_mode.as_ref()) {
                Ok(()) => Ok(tmp),
                Err(e) => {
                    discard_temp(&tmp);
                    Err(e)
                }
            });
            match written {
                Ok(tmp) => staged.push((tmp, target, path)),
                Err(e) => {
                    unstage(&staged);
                    return Err(failed(path, e));
                }
            }
        }
    }
    // Devices next: they cannot be staged, and they are what fails (a full device).
    for ((path, bytes), plan) in files.iter().zip(&plans) {
        if let Plan::Direct { target } = plan {
            if let Err(e) = write_direct(target, bytes) {
                unstage(&staged);
                return Err(failed(path, e));
            }
        }
    }
    // Commit.
    for (k, (tmp, target, path)) in staged.iter().enumerate() {
        if let Err(e) = commit_temp(tmp, target) {
            unstage(&staged[k + 1..]);
            return Err(failed(path, e));
        }
    }
    for (_, bytes) in outputs.iter().filter(|(p, _)| is_stdout(*p)) {
        write_stdout(bytes).map_err(|e| OutputError::Write { path: "stdout".into(), source: e })?;
    }
    Ok(())
}

/// One output: a file written as `write_all` writes it, or stdout for `None` and `-`.
pub fn write_one(path: Option<&Path>, bytes: &[u8]) -> Result<(), OutputError> {
    write_all(&[(path, bytes)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("menagerie-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).filter(|n| n.contains(".tmp")).collect()
    }

    #[test]
    fn all_or_nothing() {
        let dir = scratch("all");
        let a = dir.join("a.txt");
        let bad = dir.join("nodir").join("b.txt");
        let err = write_all(&[(Some(&a), b"a"), (Some(&bad), b"b")]).unwrap_err();
        assert!(err.to_string().contains("nodir/b.txt"), "{err}");
        assert!(!a.exists(), "the first output was written although the second failed");
        assert!(leftovers(&dir).is_empty());
        write_all(&[(Some(&a), b"a"), (Some(&dir.join("c.txt")), b"c")]).unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"a");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn outputs_on_one_path_are_refused() {
        let (a, b, dash) = (Path::new("a.npy"), Path::new("b.json"), Path::new("-"));
        assert!(distinct(&[("-o", a), ("--stats", b)]).is_ok());
        let err = distinct(&[("-o", a), ("--stats", b), ("--placement", a)]).unwrap_err();
        assert_eq!(err.to_string(), "-o and --placement both write to a.npy");
        let err = distinct(&[("-o", dash), ("--stats", b), ("--emit-skeleton", dash)]).unwrap_err();
        assert_eq!(err.to_string(), "-o and --emit-skeleton both write to stdout: give one of them a file");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_stays_a_link() {
        let dir = scratch("link");
        let real = dir.join("real.txt");
        fs::write(&real, "old").unwrap();
        let link = dir.join("link.txt");
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        write_one(Some(&link), b"new").unwrap();
        assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(fs::read(&real).unwrap(), b"new");
        // A dangling link creates its target.
        let dangling = dir.join("dangling.txt");
        std::os::unix::fs::symlink("made.txt", &dangling).unwrap();
        write_one(Some(&dangling), b"made").unwrap();
        assert!(fs::symlink_metadata(&dangling).unwrap().file_type().is_symlink());
        assert_eq!(fs::read(dir.join("made.txt")).unwrap(), b"made");
        // A loop is an error, not a hang.
        std::os::unix::fs::symlink("loop2", dir.join("loop1")).unwrap();
        std::os::unix::fs::symlink("loop1", dir.join("loop2")).unwrap();
        assert!(matches!(write_one(Some(&dir.join("loop1")), b"x"), Err(OutputError::LinkLoop { .. })));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temp_files_are_registered_until_renamed() {
        let dir = scratch("registry");
        let target = dir.join("t.txt");
        let (tmp, _f) = create_temp(&target).unwrap();
        assert!(temps().contains(&tmp), "a live temp file is in the registry");
        // What a signal handler does with the registry (on a copy: other tests run beside).
        let mut copy = vec![tmp.clone()];
        remove_locked(&mut copy);
        assert!(!tmp.exists() && copy.is_empty());
        let (tmp, _f) = create_temp(&target).unwrap();
        commit_temp(&tmp, &target).unwrap();
        assert!(!temps().contains(&tmp) && target.exists());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_directory_is_refused() {
        let dir = scratch("dir");
        assert!(matches!(write_one(Some(&dir), b"x"), Err(OutputError::Directory { .. })));
        fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_in_place() {
        let dir = scratch("fifo");
        let fifo = dir.join("pipe");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || fs::read(&fifo).unwrap())
        };
        write_one(Some(&fifo), b"through the pipe").unwrap();
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        use std::os::unix::fs::FileTypeExt;
        assert!(fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn keeps_the_mode_of_a_file_it_replaces() {
        let dir = scratch("mode");
        let f = dir.join("f.txt");
        fs::write(&f, "old").unwrap();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            fs::set_permissions(&f, fs::Permissions::from_mode(0o640)).unwrap();
            write_one(Some(&f), b"new").unwrap();
            assert_eq!(fs::metadata(&f).unwrap().permissions().mode() & 0o777, 0o640);
        }
        fs::remove_dir_all(&dir).unwrap();
    }
}
