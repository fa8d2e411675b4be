//! The document on disk: JSON text in and out with errors that name the element, and durable
//! writes — a document, its journal, an export must survive a crash at any instant.
//!
//! The document types ([`crate::document`]) are plain data; their file side is here.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use atomic_write_file::AtomicWriteFile;
use serde::Deserialize;
use thiserror::Error;

use crate::document::{Document, OLDEST_VERSION, VERSION};
use crate::input;
use crate::json;
use crate::validate::{self, Defect, ValidationError};

/// Writes `bytes` to `path` so that a crash leaves either the old file or the new one, never a
/// mix: a temporary file in the same directory, flushed to disk, renamed over `path`, then the
/// directory flushed so the rename itself is durable. The file keeps the mode and owner of the
/// one it replaces; a new one gets 0666 less the umask, like a file any editor saves.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with_mode(path, bytes, None)
}

/// [`write_atomic`], the file given the permission bits `mode` when there is one (exactly: no
/// umask applies), as a journal is given its document's.
///
/// A `path` that is a symbolic link is resolved and its target written in place, as vim and
/// emacs save through a link: the temporary file goes into the target's directory and is
/// renamed over the target, which keeps its mode; the link stays a link. (Renamed over the link
/// itself, the link would become a regular file with the link's own mode, 0777, and the target
/// would never change.)
pub fn write_atomic_with_mode(path: &Path, bytes: &[u8], mode: Option<u32>) -> io::Result<()> {
    let target = resolve_link(path)?;
    let mut file = AtomicWriteFile::open(&target)?;
    #[cfg(unix)]
    if let Some(mode) = mode {
        use std::os::unix::fs::PermissionsExt;
        // Before anything is written into it: the content is never readable more widely.
        file.as_file().set_permissions(fs::Permissions::from_mode(mode))?;
    }
    #[cfg(not(unix))]
    let _ = mode;
    file.write_all(bytes)?;
    file.commit()
}

/// The largest document file read: 256 MiB. Documents are kilobytes to a few megabytes (a
/// figure is some hundred bytes of JSON; the examples are under 100 kB); one of 256 MiB would
/// already parse into gigabytes of figures, past what the terrain engine may use
/// ([`crate::validate::MAX_ENGINE_BYTES`]).
pub const MAX_DOCUMENT_BYTES: u64 = 256 << 20;

/// The largest journal read: 1 GiB. Its `history` line carries up to
/// [`crate::editor::HISTORY_LIMIT`] undo steps, which may each hold a whole element, so a journal
/// may outgrow its document; four maximal documents' worth.
pub const MAX_JOURNAL_BYTES: u64 = 1 << 30;

/// The links a path may go through before [`resolve_link`] gives up (Linux's own limit).
const MAX_LINKS: usize = 40;

/// The file `path` names once every symbolic link in its last component is followed: `path`
/// itself when it is no link (or does not exist), else the link's target, resolved in turn. The
/// target need not exist (saving through a dangling link creates it, as an editor does).
pub fn resolve_link(path: &Path) -> io::Result<PathBuf> {
    let mut at = path.to_owned();
    for _ in 0..MAX_LINKS {
        match fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = fs::read_link(&at)?;
                at = match at.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(at),
        }
    }
    Err(io::Error::other(format!(
        "more than {MAX_LINKS} symbolic links to follow (a loop?)"
    )))
}

/// Why a document could not be read.
#[allow(missing_docs)] // the fields say which file and why.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file could not be read. The reason is part of the message and not also a
    /// [`source`](std::error::Error::source), which a chain printer (anyhow's `{:#}`) would print
    /// a second time.
    #[error("cannot read {}: {cause}", path.display())]
    Io { path: PathBuf, cause: io::Error },
    /// The text is not JSON of the document's shape.
    #[error("{}: {message} (line {line}, column {column})", if path.is_empty() { "document" } else { path })]
    Parse {
        /// The element that failed, e.g. `regions[0].figures[1].height` (empty for the top level).
        path: String,
        message: String,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
    },
    /// The document is well formed but not valid.
    #[error(transparent)]
    Invalid(#[from] ValidationError),
}

/// Why a document could not be saved.
#[allow(missing_docs)] // the fields say which file and why.
#[derive(Debug, Error)]
pub enum SaveError {
    /// The document is not valid; nothing was written.
    #[error(transparent)]
    Invalid(#[from] ValidationError),
    /// Writing failed; the previous file, if any, is intact. The reason is in the message only,
    /// as for [`LoadError::Io`].
    #[error("cannot write {}: {cause}", path.display())]
    Io { path: PathBuf, cause: io::Error },
}

#[derive(Deserialize)]
struct VersionOnly {
    version: serde_json::Value,
}

/// Whether a document states terrain settings: a left-out entry means the defaults in version 4
/// and seed 000's taxicab distances before, so an older document must not state one.
#[derive(Deserialize)]
struct TerrainStated {
    #[serde(default)]
    terrain: Option<serde::de::IgnoredAny>,
}

impl Document {
    /// Parses and validates a document.
    pub fn from_json(text: &str) -> Result<Document, LoadError> {
        // Editors on some systems start UTF-8 text with a byte-order mark; it is no JSON, and
        // users expect the file to open (issue 47).
        let text = strip_bom(text);
        // The version decides how to read the rest, so it is checked before the shape.
        let version: VersionOnly = parse(text)?;
        match version.version.as_u64() {
            Some(v) if (u64::from(OLDEST_VERSION)..=u64::from(VERSION)).contains(&v) => {}
            _ => {
                let shown = clip_quoted(&version.version.to_string());
                return Err(ValidationError::new("version", Defect::Version(shown)).into());
            }
        }
        let mut doc: Document = parse(text)?;
        // Version 1 had no rock fields, version 2 no rivers, 3 no terrain settings; all read as the
        // current version and are saved as such.
        if doc.version < 2 && !doc.rocks.is_empty() {
            return Err(ValidationError::new("rocks", Defect::NeedsVersion(2)).into());
        }
        if doc.version < 3 && !doc.rivers.is_empty() {
            return Err(ValidationError::new("rivers", Defect::NeedsVersion(3)).into());
        }
        if doc.version < 3 && doc.ridges.is_some() {
            return Err(ValidationError::new("ridges", Defect::NeedsVersion(3)).into());
        }
        if doc.version < 4 {
            // The text parsed as a document, so it parses as this; a failure would only mean no entry.
            if serde_json::from_str::<TerrainStated>(text).is_ok_and(|t| t.terrain.is_some()) {
                return Err(ValidationError::new("terrain", Defect::NeedsVersion(4)).into());
            }
            if let Some(i) = doc.regions.iter().position(|r| r.metric.is_some()) {
                return Err(ValidationError::new(format!("regions[{i}].metric"), Defect::NeedsVersion(4)).into());
            }
            // Terrain made before version 4 keeps seed 000's distances, to the bit.
            doc.terrain.metric = crate::document::Metric::Taxicab;
        }
        if doc.version < 4 && !doc.trees.is_empty() {
            return Err(ValidationError::new("trees", Defect::NeedsVersion(4)).into());
        }
        if doc.version < 4 && !doc.groves.is_empty() {
            return Err(ValidationError::new("groves", Defect::NeedsVersion(4)).into());
        }
        if doc.version < 5 && doc.terrain.erosion.is_some_and(|e| e.fluvial.is_some()) {
            return Err(ValidationError::new("terrain.erosion.fluvial", Defect::NeedsVersion(5)).into());
        }
        if doc.version < 6 && doc.terrain.base.is_some() {
            return Err(ValidationError::new("terrain.base", Defect::NeedsVersion(6)).into());
        }
        doc.version = VERSION;
        validate::document(&doc)?;
        Ok(doc)
    }

    /// The document as JSON text, in the layout of `docs/document.md` (short arrays on one line).
    pub fn to_json(&self) -> String {
        json::pretty(self)
    }

    /// Reads and validates the document at `path`.
    pub fn load(path: &Path) -> Result<Document, LoadError> {
        Ok(read_document(path)?.0)
    }

    /// Validates the document and writes it to `path` atomically: a temporary file in the same
    /// directory is written and flushed to disk, renamed over `path`, and the directory flushed.
    /// Returns the bytes written.
    pub fn save(&self, path: &Path) -> Result<Vec<u8>, SaveError> {
        validate::document(self)?;
        let bytes = self.to_json().into_bytes();
        write_atomic(path, &bytes).map_err(|cause| SaveError::Io {
            path: path.to_owned(),
            cause,
        })?;
        Ok(bytes)
    }
}

/// Reads and validates the document at `path`, returning its bytes too (the journal names the
/// file it applies to by their fingerprint).
pub fn read_document(path: &Path) -> Result<(Document, Vec<u8>), LoadError> {
    let bytes = input::read_input(path, MAX_DOCUMENT_BYTES).map_err(|cause| LoadError::Io {
        path: path.to_owned(),
        cause,
    })?;
    let text = std::str::from_utf8(&bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        LoadError::Io {
            path: path.to_owned(),
            cause: io::Error::new(
                io::ErrorKind::InvalidData,
                format!("not UTF-8 text: an invalid byte on line {line} (byte offset {at})"),
            ),
        }
    })?;
    let mut doc = Document::from_json(text)?;
    // The base heightmap is named relative to the document's folder.
    let grid = doc.grid;
    if let Some(base) = &mut doc.terrain.base {
        let dir = path.parent().unwrap_or(Path::new(""));
        crate::import::load_base(base, dir, &grid).map_err(|e| {
            ValidationError::new("terrain.base.path", crate::validate::TerrainDefect::Base(e.to_string()))
        })?;
        crate::validate::base(&doc)?;
    }
    Ok((doc, bytes))
}

/// `text` without a leading UTF-8 byte-order mark (U+FEFF), which JSON does not allow.
pub fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

fn parse<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, LoadError> {
    parse_json(text, "document").map_err(|e| LoadError::Parse {
        path: e.path,
        message: e.message,
        line: e.line,
        column: e.column,
    })
}

/// JSON text that is not of the expected shape: where, and why in the document's words.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JsonError {
    /// The element, e.g. `regions[0].figures[1].height`; empty when the text itself is at fault
    /// (a syntax error is located by its line and column, not by the element being read).
    pub path: String,
    pub message: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

/// Parses one JSON value of type `T` (a `what`, for messages) from the whole of `text`: anything
/// after it but whitespace is an error, so a file holding a document and then garbage, or two
/// documents, is refused rather than half read.
pub(crate) fn parse_json<'de, T: Deserialize<'de>>(text: &'de str, what: &str) -> Result<T, JsonError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // An unknown key is part of the path, and may be 10 MB long.
        let path = clip_quoted(&e.path().to_string());
        describe(&path, &e.into_inner())
    })?;
    de.end().map_err(|e| JsonError {
        path: String::new(),
        message: format!("unexpected text after the end of the {what}"),
        line: e.line(),
        column: e.column(),
    })?;
    Ok(value)
}

/// serde_json's error in the document's words.
fn describe(path: &str, e: &serde_json::Error) -> JsonError {
    use serde_json::error::Category;
    let raw = strip_position(&e.to_string());
    // The path names the element being read; an element the reader could not name (a map key
    // being read, an internally tagged edit) is `?`, so the path stops before it.
    let mut path = match path.find('?') {
        Some(i) => path[..i].trim_end_matches('.').to_owned(),
        None if path == "." => String::new(),
        None => path.to_owned(),
    };
    let message = if raw.starts_with("recursion limit exceeded") {
        path.clear();
        format!(
            "nested too deeply (more than 128 arrays and objects; figures may be nested at most {} deep)",
            crate::validate::MAX_DEPTH
        )
    } else if raw == "trailing characters" && !path.is_empty() {
        // Inside a value this is a fixed-length array with more elements: points are the only ones.
        "a point is [x, y]: two numbers, found more".to_owned()
    } else if let Some(n) = raw
        .strip_prefix("invalid length ")
        .and_then(|r| r.strip_suffix(", expected an array of length 2"))
    {
        format!("a point is [x, y]: two numbers, found {n}")
    } else {
        if matches!(e.classify(), Category::Syntax | Category::Eof) {
            // Where the reader was is not where the text is wrong (a comma missing inside a figure
            // is reported while reading `regions`); the line and column say where.
            path.clear();
        }
        words(&clip_quoted(&raw))
    };
    JsonError {
        path,
        message,
        line: e.line(),
        column: e.column(),
    }
}

/// Characters of a quoted value a message shows: a message quotes what it refuses (a string
/// where a number belongs, an unknown key, a version), and a 10 MB string must not make a 10 MB
/// message.
const QUOTED_SHOWN: usize = 40;

/// Characters of a whole message, past which it is cut (a version given as a huge array or
/// object has no one long quoted run to shorten).
const MESSAGE_SHOWN: usize = 200;

/// `text` with every quoted run ("…", `…`) longer than [`QUOTED_SHOWN`] characters cut to its
/// start and an ellipsis, and the whole cut after [`MESSAGE_SHOWN`] characters.
fn clip_quoted(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(1024));
    let mut open: Option<(char, usize)> = None;
    let mut escaped = false;
    for c in text.chars() {
        match open {
            None => {
                if c == '"' || c == '`' {
                    open = Some((c, 0));
                }
                out.push(c);
            }
            Some((q, n)) => {
                let closes = c == q && !escaped;
                escaped = !escaped && c == '\\';
                if closes {
                    if n > QUOTED_SHOWN {
                        out.push('…');
                    }
                    out.push(c);
                    open = None;
                } else {
                    if n < QUOTED_SHOWN {
                        out.push(c);
                    }
                    open = Some((q, n + 1));
                }
            }
        }
    }
    match out.char_indices().nth(MESSAGE_SHOWN) {
        Some((at, _)) => format!("{}…", &out[..at]),
        None => out,
    }
}

/// Replaces the Rust type names serde puts in its messages with what they are in the file.
fn words(message: &str) -> String {
    const NAMES: [(&str, &str); 12] = [
        (
            "struct VersionOnly with 1 element",
            "a document (a JSON object with \"version\", \"grid\" and \"regions\")",
        ),
        (
            "struct VersionOnly",
            "a document (a JSON object with \"version\", \"grid\" and \"regions\")",
        ),
        (
            "struct Document",
            "a document (a JSON object with \"version\", \"grid\" and \"regions\")",
        ),
        (
            "struct Grid",
            "a grid (an object with \"cols\", \"rows\" and \"cell_size\")",
        ),
        (
            "struct Region",
            "a region (an object with \"boundary\" and \"figures\")",
        ),
        (
            "struct Figure",
            "a figure (an object with \"kind\", \"points\", \"height\" and \"slope\")",
        ),
        (
            "struct UndoStep",
            "an undo step (an object with \"edit\" and \"inverse\")",
        ),
        (
            "internally tagged enum Entry",
            "a journal entry (an object with \"op\")",
        ),
        ("internally tagged enum Edit", "an edit (an object with \"op\")"),
        ("expected f64", "expected a number"),
        ("expected u32", "expected a whole number from 0 to 4294967295"),
        ("expected usize", "expected a whole number ≥ 0"),
    ];
    let mut out = message.to_owned();
    for (from, to) in NAMES {
        out = out.replace(from, to);
    }
    out
}

/// serde_json's message without its " at line L column C" suffix (reported separately).
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}
