//! The edit journal: an append-only log beside the document so that a crash loses no edit.
//!
//! The journal of `terrain.json` is `terrain.json.journal`, JSON Lines (one object per line),
//! specified in `docs/document.md`. Since version 2 each line begins with its sequence number
//! (its line number, from 1) and a CRC-32 of the line without the `crc32` member:
//!
//! ```text
//! {"seq":1,"crc32":"b7cdd160","op":"open","journal":2,"base":"fnv1a64:3c0a5e6f4b2d9e11"}
//! {"seq":2,"crc32":"42c10edc","op":"do","edit":{"op":"set_height","at":"regions[0].figures[1]","height":42.5}}
//! {"seq":3,"crc32":"3b8b156e","op":"undo"}
//! {"seq":4,"crc32":"3493be07","op":"redo"}
//! ```
//!
//! A changed bit anywhere in a line fails its checksum, a lost or repeated line its sequence
//! number; either is refused with the line and what is wrong, or, when recovering
//! ([`read_recovering`]), ends the journal there. A version-1 journal (no `seq`, no `crc32`) is
//! read as before, without those checks, and continued in version 1 until the next save starts
//! a version-2 journal.
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

/// The journal format version written: 2, lines with a sequence number and a checksum.
pub const JOURNAL_VERSION: u32 = 2;

/// The oldest journal format read: 1, plain lines (replayed without the checks of version 2).
pub const OLDEST_JOURNAL_VERSION: u32 = 1;

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
        /// Where each entry's line starts (a byte offset), to end the journal before it.
        starts: Vec<u64>,
        /// Length of the complete (or, recovering, the good) lines.
        valid_len: u64,
        /// Whether an incomplete last line was dropped.
        torn: bool,
        /// The journal's format version.
        version: u32,
        /// What recovering dropped: the first bad line onwards.
        dropped: Option<Dropped>,
    },
}

/// The lines a recovering read left out: the first bad one and every one after it.
#[derive(Debug, Clone, PartialEq)]
pub struct Dropped {
    /// The first line left out (1-based).
    pub line: usize,
    /// How many complete lines were left out.
    pub lines: usize,
    /// What is wrong with the first of them.
    pub reason: String,
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

/// Reads the journal at `path` for the document whose fingerprint is `base`; a bad line is an
/// error.
pub fn read(path: &Path, base: &str) -> Result<Replay, JournalError> {
    read_with(path, base, false)
}

/// [`read`], except that a bad line after the first ends the journal: the entries before it are
/// returned, and what was left out is in [`Replay::Entries`]' `dropped`. A bad first line (no
/// document named) is still an error.
pub fn read_recovering(path: &Path, base: &str) -> Result<Replay, JournalError> {
    read_with(path, base, true)
}

fn read_with(path: &Path, base: &str, recover: bool) -> Result<Replay, JournalError> {
    let bytes = match crate::input::read_input(path, persist::MAX_JOURNAL_BYTES) {
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
    let complete = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let torn = complete < bytes.len();
    // Complete lines, each with where it starts; the newline is not part of the line.
    let mut lines = Vec::new();
    let mut at = 0;
    while at < complete {
        let end = at
            + bytes[at..complete]
                .iter()
                .position(|&b| b == b'\n')
                .unwrap_or(complete - at);
        lines.push((at, &bytes[at..end]));
        at = end + 1;
    }
    let Some(&(_, first)) = lines.first() else {
        // Not even the first line was completed: the journal was being created, nothing to replay.
        return Ok(Replay::Missing);
    };
    let (version, open) = match first.starts_with(FRAME_START.as_bytes()) {
        true => (JOURNAL_VERSION, framed(first, 1)),
        false => (OLDEST_JOURNAL_VERSION, plain(first)),
    };
    match open {
        Ok(Entry::Open { journal, base: found }) => {
            if journal != version {
                let message = match journal {
                    1 | 2 => format!(
                        "a version {journal} \"open\" line {} sequence numbers and checksums",
                        if journal == 1 { "with" } else { "without" }
                    ),
                    _ => format!("unsupported journal version {journal}"),
                };
                return Err(corrupt(1, message));
            }
            if found != base {
                return Ok(Replay::Stale(found));
            }
        }
        Ok(_) => return Err(corrupt(1, "the first line is not an \"open\" entry".into())),
        Err(e) => return Err(corrupt(1, e)),
    }
    let mut entries = Vec::new();
    let mut starts = Vec::new();
    let mut valid_len = complete as u64;
    let mut dropped = None;
    for (i, &(start, line)) in lines.iter().enumerate().skip(1) {
        let number = i + 1;
        let parsed = match version {
            OLDEST_JOURNAL_VERSION => plain(line),
            _ => framed(line, number),
        };
        let entry = parsed.and_then(|entry| match entry {
            Entry::Open { .. } => Err("an \"open\" entry out of place".to_owned()),
            Entry::History { .. } if i != 1 => Err("a \"history\" entry out of place".to_owned()),
            entry => Ok(entry),
        });
        match entry {
            Ok(entry) => {
                entries.push(entry);
                starts.push(start as u64);
            }
            Err(reason) if recover => {
                valid_len = start as u64;
                dropped = Some(Dropped {
                    line: number,
                    lines: lines.len() - i,
                    reason,
                });
                break;
            }
            Err(message) => return Err(corrupt(number, message)),
        }
    }
    Ok(Replay::Entries {
        entries,
        starts,
        valid_len,
        torn: torn && dropped.is_none(),
        version,
        dropped,
    })
}

/// How a version-2 line begins.
const FRAME_START: &str = "{\"seq\":";

/// A version-2 line, numbered `number`, as an entry: its sequence number and checksum checked,
/// then the entry read; or what is wrong with it.
fn framed(line: &[u8], number: usize) -> Result<Entry, String> {
    const SHAPE: &str = "not a version-2 journal line, which begins {\"seq\":N,\"crc32\":\"8 hex digits\",";
    let rest = line.strip_prefix(FRAME_START.as_bytes()).ok_or(SHAPE)?;
    let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
    let seq_text = &rest[..digits];
    let rest = rest[digits..].strip_prefix(b",\"crc32\":\"").ok_or(SHAPE)?;
    let (crc_text, rest) = (rest.get(..8).ok_or(SHAPE)?, &rest[8.min(rest.len())..]);
    let body = rest.strip_prefix(b"\",").ok_or(SHAPE)?;
    let stored = std::str::from_utf8(crc_text)
        .ok()
        .filter(|t| t.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f')))
        .and_then(|t| u32::from_str_radix(t, 16).ok())
        .ok_or(SHAPE)?;
    // The checksum covers the line without its crc32 member: `{"seq":N,` and the entry's members.
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(FRAME_START.as_bytes());
    hasher.update(seq_text);
    hasher.update(b",");
    hasher.update(body);
    let computed = hasher.finalize();
    if computed != stored {
        return Err(format!(
            "checksum mismatch (crc32 {stored:08x} stored, {computed:08x} computed): the line was changed after it was written"
        ));
    }
    let seq: u64 = std::str::from_utf8(seq_text)
        .ok()
        .and_then(|t| t.parse().ok())
        .ok_or(SHAPE)?;
    if seq != number as u64 {
        return Err(format!(
            "sequence number {seq} where {number} belongs: a line is missing or repeated before it"
        ));
    }
    // The entry is the line's members after seq and crc32, as an object of its own; its columns
    // are counted in the line.
    let offset = line.len() - body.len() - 1;
    let mut text = Vec::with_capacity(body.len() + 1);
    text.push(b'{');
    text.extend_from_slice(body);
    let text = utf8(&text, offset)?;
    entry(text, offset)
}

/// A version-1 line as an entry.
fn plain(line: &[u8]) -> Result<Entry, String> {
    entry(utf8(line, 0)?, 0)
}

fn utf8(bytes: &[u8], offset: usize) -> Result<&str, String> {
    std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "not UTF-8 text: an invalid byte at column {}",
            offset + e.valid_up_to() + 1
        )
    })
}

/// One entry's text as an entry, or why it is not one (the element, the reason and the column,
/// `offset` characters into its line).
fn entry(text: &str, offset: usize) -> Result<Entry, String> {
    persist::parse_json(text, "journal entry").map_err(|e| {
        let at = if e.path.is_empty() {
            String::new()
        } else {
            format!("{}: ", e.path)
        };
        format!("{at}{} (column {})", e.message, e.column + offset)
    })
}

/// An open journal, appended to.
#[derive(Debug)]
pub struct Writer {
    path: PathBuf,
    file: File,
    /// The format version of the journal appended to (a version-1 one is continued as such).
    version: u32,
    /// The sequence number of the next line.
    next: u64,
}

/// `entry` as line number `seq` of a journal of format `version`, with its newline.
pub(crate) fn line(entry: &Entry, version: u32, seq: u64) -> Vec<u8> {
    // Our entries always serialise (no non-string map keys); a failure would be a bug.
    let json = serde_json::to_vec(entry).unwrap_or_default();
    let mut bytes = match (version, json.split_first()) {
        (OLDEST_JOURNAL_VERSION, _) | (_, None) => json,
        (_, Some((_, members))) => {
            let seq = format!("{FRAME_START}{seq},");
            let mut hasher = crc32fast::Hasher::new();
            hasher.update(seq.as_bytes());
            hasher.update(members);
            let mut bytes = seq.into_bytes();
            bytes.extend_from_slice(format!("\"crc32\":\"{:08x}\",", hasher.finalize()).as_bytes());
            bytes.extend_from_slice(members);
            bytes
        }
    };
    bytes.push(b'\n');
    bytes
}

impl Writer {
    /// Starts a new journal at `path` for the document with fingerprint `base`, carrying the
    /// undo and redo stacks over, with the permission bits `mode` (the document's: the journal
    /// holds its content). Atomic: a crash leaves the old journal or the new one.
    pub fn create(path: &Path, base: &str, undo: &[UndoStep], redo: &[UndoStep], mode: u32) -> io::Result<Writer> {
        let mut bytes = line(
            &Entry::Open {
                journal: JOURNAL_VERSION,
                base: base.to_owned(),
            },
            JOURNAL_VERSION,
            1,
        );
        let mut next = 2;
        if !undo.is_empty() || !redo.is_empty() {
            bytes.extend(line(
                &Entry::History {
                    undo: undo.to_vec(),
                    redo: redo.to_vec(),
                },
                JOURNAL_VERSION,
                next,
            ));
            next += 1;
        }
        write_atomic_with_mode(path, &bytes, Some(mode))?;
        Writer::append_to(path, bytes.len() as u64, mode, JOURNAL_VERSION, next)
    }

    /// Opens an existing journal of format `version` for appending after its first `valid_len`
    /// bytes (dropping a torn last line, or the bad lines a recovery left out), its next line
    /// numbered `next`, giving it the permission bits `mode` (its document's) if it has others — one
    /// written before journals followed their documents' modes may be more readable.
    pub fn append_to(path: &Path, valid_len: u64, mode: u32, version: u32, next: u64) -> io::Result<Writer> {
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
            version,
            next,
        })
    }

    /// Appends one entry and flushes it to disk.
    pub fn append(&mut self, entry: &Entry) -> io::Result<()> {
        self.file.write_all(&line(entry, self.version, self.next))?;
        self.next += 1;
        self.file.sync_data()
    }

    /// The journal's file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}
