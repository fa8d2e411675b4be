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

use crate::document::{Document, VERSION};
use crate::json;
use crate::validate::{self, Defect, ValidationError};

/// Writes `bytes` to `path` so that a crash leaves either the old file or the new one, never a
/// mix: a temporary file in the same directory, flushed to disk, renamed over `path`, then the
/// directory flushed so the rename itself is durable. The file keeps the mode and owner of the
/// one it replaces; a new one gets 0666 less the umask, like a file any editor saves.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicWriteFile::open(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// Why a document could not be read.
#[allow(missing_docs)] // the fields say which file and why.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io { path: PathBuf, source: io::Error },
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
    /// Writing failed; the previous file, if any, is intact.
    #[error("cannot write {}: {source}", path.display())]
    Io { path: PathBuf, source: io::Error },
}

#[derive(Deserialize)]
struct VersionOnly {
    version: serde_json::Value,
}

impl Document {
    /// Parses and validates a document.
    pub fn from_json(text: &str) -> Result<Document, LoadError> {
        // The version decides how to read the rest, so it is checked before the shape.
        let version: VersionOnly = parse(text)?;
        match version.version.as_u64() {
            Some(v) if v == u64::from(VERSION) => {}
            _ => {
                return Err(ValidationError::new("version", Defect::Version(version.version.to_string())).into());
            }
        }
        let doc: Document = parse(text)?;
        validate::document(&doc)?;
        Ok(doc)
    }

    /// The document as JSON text, in the layout of `docs/document.md` (short arrays on one line).
    pub fn to_json(&self) -> String {
        json::pretty(self)
    }

    /// Reads and validates the document at `path`.
    pub fn load(path: &Path) -> Result<Document, LoadError> {
        let text = fs::read_to_string(path).map_err(|source| LoadError::Io {
            path: path.to_owned(),
            source,
        })?;
        Document::from_json(&text)
    }

    /// Validates the document and writes it to `path` atomically: a temporary file in the same
    /// directory is written and flushed to disk, renamed over `path`, and the directory flushed.
    /// Returns the bytes written.
    pub fn save(&self, path: &Path) -> Result<Vec<u8>, SaveError> {
        validate::document(self)?;
        let bytes = self.to_json().into_bytes();
        write_atomic(path, &bytes).map_err(|source| SaveError::Io {
            path: path.to_owned(),
            source,
        })?;
        Ok(bytes)
    }
}

/// Reads and validates the document at `path`, returning its bytes too (the journal names the
/// file it applies to by their fingerprint).
pub fn read_document(path: &Path) -> Result<(Document, Vec<u8>), LoadError> {
    let bytes = fs::read(path).map_err(|source| LoadError::Io {
        path: path.to_owned(),
        source,
    })?;
    let text = std::str::from_utf8(&bytes).map_err(|e| LoadError::Io {
        path: path.to_owned(),
        source: io::Error::new(io::ErrorKind::InvalidData, e),
    })?;
    let doc = Document::from_json(text)?;
    Ok((doc, bytes))
}

fn parse<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, LoadError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        LoadError::Parse {
            path: if path == "." { String::new() } else { path },
            message: strip_position(&inner.to_string()),
            line: inner.line(),
            column: inner.column(),
        }
    })?;
    Ok(value)
}

/// serde_json's message without its " at line L column C" suffix (reported separately).
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}
