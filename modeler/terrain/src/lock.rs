//! The advisory lock that makes one [`Editor`](crate::editor::Editor) the only writer of a
//! document for as long as it has it open.
//!
//! The lock is `flock(2)` (exclusive, non-blocking) on a sidecar file beside the document:
//! `terrain.json.lock` for `terrain.json`. Not on the document itself, because every save
//! replaces the document by a rename, and a lock on the replaced file's inode would lock nothing
//! any more. The holder writes its process ID into the sidecar, so that a refused writer can say
//! who holds it. The sidecar is left in place when the lock is released: removing it would let a
//! writer that opened it just before lock an unlinked file while a third locks a new one.
//!
//! `flock` is std's [`File::try_lock`] (stable since Rust 1.89, the workspace's
//! `rust-version`; `flock(LOCK_EX | LOCK_NB)` on Linux): no crate needed, and it is released by
//! the kernel when the process ends, however it ends. Advisory: only programs that take it are
//! kept out — every writer here does ([`Editor::open`](crate::editor::Editor::open),
//! [`Editor::create`](crate::editor::Editor::create), `save_as`); readers
//! ([`Editor::open_read_only`](crate::editor::Editor::open_read_only): `render`, `generate`, …)
//! take none and are never blocked.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The lock file of the document at `doc`: its name with `.lock` appended.
pub fn path_for(doc: &Path) -> PathBuf {
    let mut name = doc.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".lock");
    doc.with_file_name(name)
}

/// Why a document could not be locked.
#[allow(missing_docs)] // the fields say which file and why.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process (or another editor in this one) has the document open for writing.
    #[error(
        "{} is open for writing by another process ({holder}; lock {}): close it there first, or open it read-only (`penmodel render`, `generate`)",
        doc.display(),
        lock.display()
    )]
    Held {
        doc: PathBuf,
        lock: PathBuf,
        holder: String,
    },
    /// The lock file could not be created, read or locked.
    #[error("cannot write {}: its lock file {}: {cause}", doc.display(), lock.display())]
    Io {
        doc: PathBuf,
        lock: PathBuf,
        cause: io::Error,
    },
}

/// A held lock on a document; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct DocumentLock {
    /// The locked file; closing it releases the lock.
    _file: File,
    doc: PathBuf,
}

impl DocumentLock {
    /// Locks the document at `doc` for writing, creating its lock file with `mode` (permission
    /// bits; the umask still applies), or says who holds it.
    pub fn acquire(doc: &Path, mode: u32) -> Result<DocumentLock, LockError> {
        let lock = path_for(doc);
        let io_error = |cause| LockError::Io {
            doc: doc.to_owned(),
            lock: lock.clone(),
            cause,
        };
        // Not truncated on open: the holder's PID must survive a refused writer's attempt.
        let mut file = open_lock_file(&lock, mode).map_err(io_error)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut text = String::new();
                // What the holder wrote: its PID, or nothing if it is between lock and write.
                let _ = (&file).take(64).read_to_string(&mut text);
                let holder = match text.trim().parse::<u32>() {
                    Ok(pid) => format!("PID {pid}"),
                    Err(_) => "PID unknown: the lock file names none".to_owned(),
                };
                return Err(LockError::Held {
                    doc: doc.to_owned(),
                    lock,
                    holder,
                });
            }
            Err(TryLockError::Error(cause)) => return Err(io_error(cause)),
        }
        let pid = format!("{}\n", std::process::id());
        file.set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(pid.as_bytes()))
            .map_err(io_error)?;
        Ok(DocumentLock {
            _file: file,
            doc: doc.to_owned(),
        })
    }

    /// The document this lock is for.
    pub fn document(&self) -> &Path {
        &self.doc
    }
}

fn open_lock_file(lock: &Path, mode: u32) -> io::Result<File> {
    let mut options = OpenOptions::new();
    options.read(true).write(true).create(true).truncate(false);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, mode);
    #[cfg(not(unix))]
    let _ = mode;
    let file = options.open(lock)?;
    // A lock file that is a link, a FIFO or a folder is not ours to write a PID into.
    if !file.metadata()?.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the lock file is not a regular file",
        ));
    }
    Ok(file)
}

/// The permission bits of the file at `path`, or 0666 (less the umask, when created) if there is
/// none: what a lock file or journal beside it is created with.
pub fn mode_of(path: &Path) -> u32 {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        fs::metadata(path).map_or(0o666, |m| m.permissions().mode() & 0o777)
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        0o666
    }
}
