//! Where results go: standard output, or a new file that appears whole or not at all. It exists because a
//! result file is evidence: a failed write (a full disk) must never leave a truncated or empty file behind,
//! and an existing file must never be overwritten.
//!
//! A file is written to a temporary file in the same directory (`tempfile::NamedTempFile`, a new name opened
//! with `O_EXCL`), flushed and synced, then given its name with `persist_noclobber`, which fails if the name
//! exists (`renameat2` with `RENAME_NOREPLACE`, or `link(2)` and `unlink(2)` where the file system has no such
//! rename), so nothing is ever clobbered, even by a file that appeared during the run. On any failure the
//! temporary file is removed when it is dropped. The target is checked before any work is done
//! ([`OutputTarget::new`]), so a long computation is not wasted on a name that would be refused.
//!
//! `--force` ([`Existing::Replace`], for re-runs in a Makefile; the command line passes it to every writer as a
//! value) lets an existing regular file be replaced: the new file
//! is still written to a temporary file and renamed over the old one only when it is complete (`persist`, an
//! atomic `rename(2)`), so a failed run leaves the old file as it was. A directory is never replaced.
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// How standard output is named in errors.
pub const STDOUT: &str = "<stdout>";

/// What a written file does to an existing file of its name: refuse it (the default), or replace it whole
/// (`--force`). A directory is refused either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Existing {
    #[default]
    Refuse,
    Replace,
}

impl Existing {
    /// `--force` given: [`Existing::Replace`].
    pub fn from_force(force: bool) -> Existing {
        if force {
            Existing::Replace
        } else {
            Existing::Refuse
        }
    }
}

/// Standard output, or a file that must not exist yet (or may be replaced, [`Existing::Replace`]).
#[derive(Clone, Debug)]
pub struct OutputTarget {
    path: Option<PathBuf>,
    existing: Existing,
}

impl OutputTarget {
    /// `None` and `-` are standard output. A path is refused now if it exists (unless `existing` replaces it)
    /// or its directory does not.
    pub fn new(path: Option<&Path>, option: &str, existing: Existing) -> Result<OutputTarget> {
        let path = path.filter(|p| p.as_os_str() != "-");
        if let Some(p) = path {
            check_new_file(p, option, existing)?;
        }
        Ok(OutputTarget { path: path.map(Path::to_path_buf), existing })
    }

    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Write everything, or fail without leaving a file.
    pub fn write(&self, text: &str) -> Result<()> {
        match &self.path {
            None => print(text),
            Some(p) => write_new_file(p, text.as_bytes(), self.existing),
        }
    }

    /// How the target is named in errors: the file, or `<stdout>`.
    pub fn name(&self) -> String {
        self.path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| STDOUT.into())
    }

    /// Stream output through `body` (for output too large to hold, `sweep`): standard output as it comes, or
    /// a file that still appears whole or not at all (the temporary file is linked to its name only when
    /// `body` succeeded). `body`'s I/O errors should name [`OutputTarget::name`].
    pub fn stream(&self, body: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
        let io = |source| Error::Io { file: self.name(), source };
        match &self.path {
            None => {
                let mut out = std::io::BufWriter::new(std::io::stdout().lock());
                body(&mut out)?;
                out.flush().map_err(io)
            }
            Some(p) => write_new_file_by(p, self.existing, |f| {
                let mut out = std::io::BufWriter::new(f);
                body(&mut out)?;
                out.flush().map_err(io)
            }),
        }
    }
}

/// Refuse an existing path (unless `existing` replaces it; a directory always) and a path whose directory does
/// not exist.
pub fn check_new_file(p: &Path, option: &str, existing: Existing) -> Result<()> {
    if let Ok(meta) = p.symlink_metadata() {
        if meta.is_dir() {
            return Err(Error::Usage(format!("{option} {}: is a directory, not a file", p.display())));
        }
        if existing == Existing::Refuse {
            return Err(Error::Usage(format!(
                "{option} {}: already exists; glossmeter never overwrites a file (choose another name, or give \
                 --force to replace it)",
                p.display()
            )));
        }
    }
    let dir = parent(p);
    if !dir.is_dir() {
        return Err(Error::Usage(format!("{option} {}: the directory {} does not exist", p.display(), dir.display())));
    }
    Ok(())
}

/// Write text to standard output; an error (a closed pipe, a full disk) is returned, never a panic.
pub fn print(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes()).and_then(|_| out.flush()).map_err(|source| Error::Io { file: STDOUT.into(), source })
}

fn parent(p: &Path) -> &Path {
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Write `bytes` to the new file `path`, atomically (see the module documentation).
pub fn write_new_file(path: &Path, bytes: &[u8], existing: Existing) -> Result<()> {
    write_new_file_with(path, bytes, existing, |f, b| f.write_all(b))
}

/// [`write_new_file`] with the writing step given, so that tests can make it fail like a full disk.
pub fn write_new_file_with(
    path: &Path,
    bytes: &[u8],
    existing: Existing,
    write: impl FnOnce(&mut File, &[u8]) -> std::io::Result<()>,
) -> Result<()> {
    let io = |source| Error::Io { file: path.display().to_string(), source };
    write_new_file_by(path, existing, |f| write(f, bytes).map_err(io))
}

/// Create the new file `path` atomically with the contents `body` writes (see the module documentation):
/// on any error of `body`, of the flush or of the link, no file is left behind.
pub fn write_new_file_by(path: &Path, existing: Existing, body: impl FnOnce(&mut File) -> Result<()>) -> Result<()> {
    let io = |source| Error::Io { file: path.display().to_string(), source };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "output".into());
    let prefix = format!(".{name}.glossmeter-");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // A result file is made as `File::create` makes one (0666 less the umask), not private as a temporary
    // file is by default (0600).
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(parent(path)).map_err(io)?;
    // On an error here `tmp` is dropped, which removes the temporary file.
    body(tmp.as_file_mut())?;
    tmp.as_file_mut().flush().and_then(|_| tmp.as_file().sync_all()).map_err(io)?;
    if existing == Existing::Replace {
        if path.is_dir() {
            return Err(Error::Usage(format!("{}: is a directory, not a file", path.display())));
        }
        return tmp.persist(path).map(drop).map_err(|e| io(e.error));
    }
    tmp.persist_noclobber(path).map(drop).map_err(|e| {
        // `e.file` (the temporary file) is dropped with `e`, which removes it.
        if e.error.kind() == std::io::ErrorKind::AlreadyExists {
            Error::Usage(format!(
                "{}: already exists; glossmeter never overwrites a file (choose another name, or give --force to \
                 replace it)",
                path.display()
            ))
        } else {
            io(e.error)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("glossmeter-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn force_replaces_a_file_whole_and_a_failed_write_keeps_the_old_one() {
        let d = dir("force");
        let p = d.join("readings.csv");
        std::fs::write(&p, "old").unwrap();
        assert!(check_new_file(&p, "-o", Existing::Refuse).unwrap_err().to_string().contains("--force"));
        check_new_file(&p, "-o", Existing::Replace).unwrap();
        write_new_file(&p, b"new", Existing::Replace).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        // A write that fails half-way leaves the previous file as it was, and no temporary file.
        let r = write_new_file_with(&p, b"0123456789", Existing::Replace, |f, b| {
            f.write_all(&b[..5])?;
            Err(std::io::Error::from(std::io::ErrorKind::StorageFull))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        assert_eq!(entries(&d), ["readings.csv"]);
        // A directory is never replaced.
        assert!(check_new_file(&d, "-o", Existing::Replace).unwrap_err().to_string().contains("directory"));
        assert!(check_new_file(&p, "-o", Existing::Refuse).is_err());
    }

    #[test]
    fn a_failed_write_leaves_no_file_and_an_error() {
        let d = dir("full");
        let p = d.join("readings.json");
        // A disk that fills after half the bytes: the old `BufWriter` path left a 0-byte file and exit 0.
        let r = write_new_file_with(&p, b"0123456789", Existing::Refuse, |f, b| {
            f.write_all(&b[..5])?;
            Err(std::io::Error::from(std::io::ErrorKind::StorageFull))
        });
        let e = r.unwrap_err().to_string();
        assert!(e.contains("readings.json"), "{e}");
        assert!(entries(&d).is_empty(), "no target and no temporary file: {:?}", entries(&d));
    }

    #[test]
    fn an_existing_file_is_never_overwritten_even_if_it_appears_during_the_run() {
        let d = dir("race");
        let p = d.join("out.txt");
        assert!(OutputTarget::new(Some(&p), "-o", Existing::Refuse).is_ok());
        std::fs::write(&p, "user data").unwrap();
        assert!(OutputTarget::new(Some(&p), "-o", Existing::Refuse).is_err(), "checked before the work");
        let e = write_new_file(&p, b"new", Existing::Refuse).unwrap_err().to_string();
        assert!(e.contains("already exists"), "{e}");
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "user data");
        assert_eq!(entries(&d), vec!["out.txt".to_string()]);
        write_new_file(&d.join("fresh.txt"), b"whole", Existing::Refuse).unwrap();
        assert_eq!(std::fs::read_to_string(d.join("fresh.txt")).unwrap(), "whole");
    }

    #[cfg(unix)]
    #[test]
    fn a_written_file_has_the_permissions_of_a_created_one() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("mode");
        write_new_file(&d.join("ours.txt"), b"x", Existing::Refuse).unwrap();
        std::fs::File::create(d.join("plain.txt")).unwrap();
        let mode = |n: &str| std::fs::metadata(d.join(n)).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode("ours.txt"), mode("plain.txt"));
    }

    #[test]
    fn a_missing_directory_is_refused_before_the_work() {
        let e = OutputTarget::new(Some(Path::new("/nonexistent-dir-glossmeter/x.json")), "-o", Existing::Refuse)
            .unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
    }
}
