//! Durable writes: a document, its journal, an export must survive a crash at any instant.

use std::io::{self, Write};
use std::path::Path;

use atomic_write_file::AtomicWriteFile;

/// Writes `bytes` to `path` so that a crash leaves either the old file or the new one, never a
/// mix: a temporary file in the same directory, flushed to disk, renamed over `path`, then the
/// directory flushed so the rename itself is durable. The file keeps the mode and owner of the
/// one it replaces; a new one gets 0666 less the umask, like a file any editor saves.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicWriteFile::open(path)?;
    file.write_all(bytes)?;
    file.commit()
}
