//! The edit journal: an append-only log beside the document so that a crash loses no edit.
//!
//! The journal of `terrain.json` is `terrain.json.journal`, JSON Lines (one object per line),
//! specified in `docs/document.md`:
//!
//! ```text
//! {"op":"open","journal":1,"base":"fnv1a64:3c0a5e6f4b2d9e11"}
//! {"op":"history","undo":[{"edit":…,"inverse":…}],"redo":[]}
//! {"op":"do","edit":{"op":"set_height","at":"regions[0].figures[1]","height":42.5}}
//! {"op":"undo"}
//! {"op":"redo"}
//! ```
//!
//! The first line names the exact document file the journal applies to by a hash of its bytes; a
//! journal whose base does not match (the document was saved, or replaced, after the journal was
//! written) is stale and is set aside, never replayed. `history` (optional, second line) carries
//! the undo and redo stacks over a save. Each later line is one applied operation, written and
//! flushed to disk (`fsync`) before the edit returns. A last line without its newline is a write
//! the crash interrupted: it was never acknowledged and is dropped.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::edit::Edit;
use crate::persist::{self, write_atomic_with_mode};

/// The journal format version.
pub const JOURNAL_VERSION: u32 = 1;

/// An edit with its inverse: one undo (or redo) step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UndoStep {
    /// The edit as applied.
    pub edit: Edit,
    /// The edit that undoes it.
    pub inverse: Edit,
}

/// One line of the journal.
#[allow(missing_docs)] // fields named for what they hold; each variant says what the line records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Entry {
    /// First line: format version and the document it applies to.
    Open {
        /// [`JOURNAL_VERSION`].
        journal: u32,
        /// [`fingerprint`] of the document file's bytes.
        base: String,
    },
    /// The undo and redo stacks at the time the document was saved (oldest first).
    History { undo: Vec<UndoStep>, redo: Vec<UndoStep> },
    /// An edit was applied.
    Do { edit: Edit },
    /// The last edit was undone.
    Undo,
    /// The last undone edit was redone.
    Redo,
}

/// The journal file of the document at `doc`.
pub fn path_for(doc: &Path) -> PathBuf {
    let mut name = doc.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".journal");
    doc.with_file_name(name)
}

/// The identity of a document file's bytes: `fnv1a64:` and the 64-bit FNV-1a hash in hex.
pub fn fingerprint(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("fnv1a64:{h:016x}")
}

/// What reading a journal found.
#[allow(missing_docs)] // named for what they hold.
#[derive(Debug)]
pub enum Replay {
    /// No journal file.
    Missing,
    /// A journal for another version of the document; its base is given.
    Stale(String),
    /// The entries after the `open` line, and the byte length of the complete lines (a torn last
    /// line is left out; `torn` says whether there was one).
    Entries {
        entries: Vec<Entry>,
        /// Length of the complete lines.
        valid_len: u64,
        /// Whether an incomplete last line was dropped.
        torn: bool,
    },
}

/// A journal that cannot be read.
#[allow(missing_docs)] // the fields say which file, where and why.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// Reading or writing failed. The reason is in the message only, not also a
    /// [`source`](std::error::Error::source) that a chain printer would repeat.
    #[error("journal {}: {cause}", path.display())]
    Io { path: PathBuf, cause: io::Error },
    /// A complete line is not a journal entry.
    #[error("journal {} line {line}: {message}", path.display())]
    Corrupt {
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        message: String,
    },
}

/// Reads the journal at `path` for the document whose fingerprint is `base`.
pub fn read(path: &Path, base: &str) -> Result<Replay, JournalError> {
    let bytes = match persist::read_input(path, persist::MAX_JOURNAL_BYTES) {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Replay::Missing),
        Err(cause) => {
            return Err(JournalError::Io {
                path: path.to_owned(),
                cause,
            });
        }
    };
    let corrupt = |line: usize, message: String| JournalError::Corrupt {
        path: path.to_owned(),
        line,
        message,
    };
    let valid_len = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let torn = valid_len < bytes.len();
    let text = std::str::from_utf8(&bytes[..valid_len]).map_err(|e| {
        // The line holding the first invalid byte, counted like the other errors' lines.
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        let column = at - bytes[..at].iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1) + 1;
        corrupt(line, format!("not UTF-8 text: an invalid byte at column {column}"))
    })?;
    let mut lines = text.lines().enumerate();
    let Some((_, first)) = lines.next() else {
        // Not even the first line was completed: the journal was being created, nothing to replay.
        return Ok(Replay::Missing);
    };
    match entry(first) {
        Ok(Entry::Open { journal, base: found }) => {
            if journal != JOURNAL_VERSION {
                return Err(corrupt(1, format!("unsupported journal version {journal}")));
            }
            if found != base {
                return Ok(Replay::Stale(found));
            }
        }
        Ok(_) => return Err(corrupt(1, "the first line is not an \"open\" entry".into())),
        Err(e) => return Err(corrupt(1, e)),
    }
    let mut entries = Vec::new();
    for (i, line) in lines {
        let entry = entry(line).map_err(|message| corrupt(i + 1, message))?;
        if matches!(entry, Entry::Open { .. }) || (matches!(entry, Entry::History { .. }) && i != 1) {
            return Err(corrupt(i + 1, "an \"open\" or \"history\" entry out of place".into()));
        }
        entries.push(entry);
    }
    Ok(Replay::Entries {
        entries,
        valid_len: valid_len as u64,
        torn,
    })
}

/// One line as an entry, or why it is not one (the element, the reason and the column).
fn entry(line: &str) -> Result<Entry, String> {
    persist::parse_json(line, "journal entry").map_err(|e| {
        let at = if e.path.is_empty() {
            String::new()
        } else {
            format!("{}: ", e.path)
        };
        format!("{at}{} (column {})", e.message, e.column)
    })
}

/// An open journal, appended to.
#[derive(Debug)]
pub struct Writer {
    path: PathBuf,
    file: File,
}

fn line(entry: &Entry) -> Vec<u8> {
    // Our entries always serialise (no non-string map keys); a failure would be a bug.
    let mut bytes = serde_json::to_vec(entry).unwrap_or_default();
    bytes.push(b'\n');
    bytes
}

impl Writer {
    /// Starts a new journal at `path` for the document with fingerprint `base`, carrying the
    /// undo and redo stacks over, with the permission bits `mode` (the document's: the journal
    /// holds its content). Atomic: a crash leaves the old journal or the new one.
    pub fn create(path: &Path, base: &str, undo: &[UndoStep], redo: &[UndoStep], mode: u32) -> io::Result<Writer> {
        let mut bytes = line(&Entry::Open {
            journal: JOURNAL_VERSION,
            base: base.to_owned(),
        });
        if !undo.is_empty() || !redo.is_empty() {
            bytes.extend(line(&Entry::History {
                undo: undo.to_vec(),
                redo: redo.to_vec(),
            }));
        }
        write_atomic_with_mode(path, &bytes, Some(mode))?;
        Writer::append_to(path, bytes.len() as u64, mode)
    }

    /// Opens an existing journal for appending after its first `valid_len` bytes (dropping a torn
    /// last line), giving it the permission bits `mode` (its document's) if it has others — one
    /// written before journals followed their documents' modes may be more readable.
    pub fn append_to(path: &Path, valid_len: u64, mode: u32) -> io::Result<Writer> {
        let file = OpenOptions::new().write(true).open(path)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let permissions = file.metadata()?.permissions();
            if permissions.mode() & 0o7777 != mode {
                match file.set_permissions(fs::Permissions::from_mode(mode)) {
                    // Someone else's journal, shared through the group: kept as its owner made it.
                    Err(e) if e.kind() == io::ErrorKind::PermissionDenied => {}
                    other => other?,
                }
            }
        }
        #[cfg(not(unix))]
        let _ = mode;
        if file.metadata()?.len() != valid_len {
            file.set_len(valid_len)?;
            file.sync_all()?;
        }
        let mut file = OpenOptions::new().append(true).open(path)?;
        file.flush()?;
        Ok(Writer {
            path: path.to_owned(),
            file,
        })
    }

    /// Appends one entry and flushes it to disk.
    pub fn append(&mut self, entry: &Entry) -> io::Result<()> {
        self.file.write_all(&line(entry))?;
        self.file.sync_data()
    }

    /// The journal's file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
