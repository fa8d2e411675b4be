//! A frame as an RGBA8 PNG.

use std::io::Write;
use std::path::Path;

use super::OutputError;
use crate::Frame;

fn png_error(e: impl std::fmt::Display) -> OutputError {
    OutputError::Png(e.to_string())
}

/// Encodes `frame` as an 8-bit RGBA PNG into `out`.
pub fn encode_png(frame: &Frame, out: impl Write) -> Result<(), OutputError> {
    let mut enc = png::Encoder::new(out, frame.width(), frame.height());
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    // Fast compression: a frame is written per pen report in a headless session.
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().map_err(png_error)?;
    writer.write_image_data(frame.as_bytes()).map_err(png_error)?;
    writer.finish().map_err(png_error)
}

/// Writes `frame` as a PNG file at `path`.
pub fn write_png(frame: &Frame, path: &Path) -> Result<(), OutputError> {
    let mut bytes = Vec::new();
    encode_png(frame, &mut bytes)?;
    std::fs::write(path, bytes).map_err(|error| OutputError::Io {
        path: path.to_owned(),
        error,
    })
}
