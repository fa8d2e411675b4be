//! The one gate every file penmodel reads goes through: regular files only, and no more bytes
//! than the kind of file may have (docs/reliability.md). Its own module, below both the
//! document's reading ([`crate::persist`]) and a base heightmap's ([`crate::import`]).

use std::fs::{self, File};
use std::io::{self, Read};
use std::path::Path;

/// The largest other input penmodel reads (a tree's maps, a silhouette PNG): 256 MiB, like a
/// document.
pub const MAX_INPUT_BYTES: u64 = 256 << 20;

/// Opens the input file at `path` for reading, refusing before any byte is read what is not a
/// regular file (a FIFO, which would block until someone writes to it; a device such as
/// `/dev/zero`, which never ends; a directory; a socket) and a file of more than `limit` bytes.
/// The one gate every file penmodel reads goes through; [`read_input`] reads it whole.
///
/// The file is opened non-blocking, so that opening a FIFO returns at once, and its type is
/// checked on the opened file, not on the name, so it cannot be swapped between the check and
/// the read.
pub fn open_input(path: &Path, limit: u64) -> io::Result<File> {
    let mut options = fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{}, not a regular file: penmodel reads regular files only",
                kind_of(&meta.file_type())
            ),
        ));
    }
    if meta.len() > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} bytes, more than the {} MiB this file may have (docs/reliability.md)",
                meta.len(),
                limit >> 20
            ),
        ));
    }
    Ok(file)
}

/// The whole of the input file at `path`, checked by [`open_input`]; a file that grows past
/// `limit` while it is read is refused too.
pub fn read_input(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let file = open_input(path, limit)?;
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("grew past the {} MiB this file may have while it was read", limit >> 20),
        ));
    }
    Ok(bytes)
}

/// What a file that is not a regular one is, in a message.
fn kind_of(t: &fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() { "a directory" } else { "not a file" }
}
