//! Where frames go: PNG files, an animated PNG of a sequence, or a window.
//!
//! The file outputs never touch a display, so they run headless (CI has none). The window
//! ([`window::Viewer`]) loads X11 or Wayland only when it is opened, and says so with an error
//! when there is no display.

pub(crate) mod frame;
pub mod png;
pub mod sequence;
pub(crate) mod stereo;
#[cfg(feature = "window")]
pub mod window;

use std::io;
use std::path::PathBuf;

use thiserror::Error;

pub use png::{encode_png, write_png};
pub use sequence::Sequence;
#[cfg(feature = "window")]
pub use window::{Pointer, Viewer, ViewerEvent, WindowError};

/// Why a frame could not be written.
#[allow(missing_docs)] // the fields say which file or frame and why.
#[derive(Debug, Error)]
pub enum OutputError {
    /// A file could not be created or written. The OS's error is in the message and not a
    /// `source`, so that a chain of errors (`{:#}`) says it once.
    #[error("cannot write {}: {error}", path.display())]
    Io { path: PathBuf, error: io::Error },
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
    /// A frame of a sequence differs in size from the first.
    #[error("frame {index} is {got:?}, the sequence is {expected:?}")]
    FrameSize {
        /// The frame's index.
        index: usize,
        got: (u32, u32),
        /// The first frame's size.
        expected: (u32, u32),
    },
}
