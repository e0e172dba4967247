//! Output files that appear whole or not at all: written to a temporary file beside the
//! destination and renamed over it only once complete, so a run that fails half-way (a
//! truncated frame, a full disk, Ctrl-C) leaves any earlier file at that path untouched.
//!
//! A destination that exists and is not a regular file or a folder — a device such as
//! `/dev/null` or `/dev/stdout`, a named pipe — is written straight to instead: renaming over
//! it would replace the device or pipe with a plain file (as root, `/dev/null` itself).

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use tempfile::NamedTempFile;

/// A file being written; [`AtomicFile::commit`] puts it in place. Dropped without a commit,
/// the temporary file is removed and the destination is as it was.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    sink: Sink,
}

/// Where the bytes go until [`AtomicFile::commit`].
#[derive(Debug)]
enum Sink {
    /// A temporary file beside the destination, renamed over it on commit.
    Temp(BufWriter<NamedTempFile>),
    /// The destination itself: a device or a pipe, which a rename would replace.
    Direct(BufWriter<File>),
}

/// Whether `path` exists and is neither a regular file nor a folder (following links).
fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

impl AtomicFile {
    /// Starts writing what will become `path` (its folder must exist).
    pub fn create(path: &Path) -> Result<AtomicFile> {
        if is_special(path) {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .with_context(|| format!("cannot open {}", path.display()))?;
            return Ok(AtomicFile {
                path: path.to_path_buf(),
                sink: Sink::Direct(BufWriter::new(file)),
            });
        }
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "out".into());
        let temp = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".partial")
            .tempfile_in(dir)
            .with_context(|| format!("cannot create {}", path.display()))?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            sink: Sink::Temp(BufWriter::new(temp)),
        })
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and renames the file into place (a device or pipe: flushes).
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        let temp = match self.sink {
            Sink::Direct(mut file) => {
                return file
                    .flush()
                    .with_context(|| format!("cannot write {}", path.display()));
            }
            Sink::Temp(temp) => temp,
        };
        let temp = temp
            .into_inner()
            .map_err(|e| e.into_error())
            .with_context(|| format!("cannot write {}", path.display()))?;
        temp.as_file()
            .sync_all()
            .with_context(|| format!("cannot write {}", path.display()))?;
        persist_keeping_mode(temp, &path)
    }
}

/// Renames `temp` onto `path`. The destination keeps its permissions; a new file gets
/// 0644 (read for all, as `File::create` gives under the usual umask), not the temporary
/// file's private 0600.
fn persist_keeping_mode(temp: NamedTempFile, path: &Path) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).map_or(0o644, |m| m.permissions().mode());
        let _ = temp
            .as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode));
    }
    temp.persist(path)
        .map_err(|e| e.error)
        .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(())
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.sink {
            Sink::Temp(temp) => temp.write(buf),
            Sink::Direct(file) => file.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match &mut self.sink {
            Sink::Temp(temp) => temp.flush(),
            Sink::Direct(file) => file.flush(),
        }
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)
        .with_context(|| format!("cannot write {}", path.display()))?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_uncommitted_file_leaves_the_old_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("states.csv");
        std::fs::write(&path, "good\n").unwrap();
        {
            let mut f = AtomicFile::create(&path).unwrap();
            f.write_all(b"partial").unwrap();
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "good\n");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temp file left"
        );
        write_atomic(&path, b"new\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new\n");
    }

    /// A named pipe at the destination is written to, not renamed over (the same path as a
    /// device such as `/dev/null`, which a test must not risk replacing).
    #[cfg(unix)]
    #[test]
    fn a_pipe_is_written_through_and_stays_a_pipe() {
        use std::os::unix::fs::FileTypeExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("states.fifo");
        let made = std::process::Command::new("mkfifo").arg(&path).status();
        assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", path.display());
        let reader = {
            let path = path.clone();
            std::thread::spawn(move || std::fs::read(path).unwrap())
        };
        write_atomic(&path, b"frame,q0\n0,1\n").unwrap();
        // Checked before joining: a pipe renamed over would leave the reader waiting.
        let kind = std::fs::metadata(&path).unwrap().file_type();
        assert!(kind.is_fifo(), "the pipe was replaced: {kind:?}");
        assert_eq!(reader.join().unwrap(), b"frame,q0\n0,1\n");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temp file left"
        );
    }
}
