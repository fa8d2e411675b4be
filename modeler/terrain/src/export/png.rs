//! 16-bit grayscale PNG heightmaps with the height range recorded in the file.
//!
//! Pixel value `v` (0..=65535) stands for the height `min + v / 65535 · (max − min)` metres;
//! `min` and `max` are the terrain's lowest and highest heights, written as `tEXt` chunks
//! [`KEY_HEIGHT_MIN`] and [`KEY_HEIGHT_MAX`] (decimal, metres), with [`KEY_CELL_SIZE`] for the
//! ground scale. A flat terrain has `min = max` and every pixel 0. The quantisation step is
//! `(max − min) / 65535`.

use std::io::{BufRead, Seek, Write};

use super::ExportError;
use crate::heightmap::Heightmap;

/// `tEXt` keyword of the height of pixel value 0, in metres.
pub const KEY_HEIGHT_MIN: &str = "height_min_m";
/// `tEXt` keyword of the height of pixel value 65535, in metres.
pub const KEY_HEIGHT_MAX: &str = "height_max_m";
/// `tEXt` keyword of the side of a pixel on the ground, in metres.
pub const KEY_CELL_SIZE: &str = "cell_size_m";

/// The height range a PNG heightmap records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightRange {
    /// Height of pixel value 0.
    pub min: f32,
    /// Height of pixel value 65535.
    pub max: f32,
}

impl HeightRange {
    /// The height of pixel value `v`.
    pub fn height(&self, v: u16) -> f32 {
        (f64::from(self.min) + f64::from(v) / 65535.0 * (f64::from(self.max) - f64::from(self.min))) as f32
    }
}

/// The 16-bit step of height `h` in `min..=max` (0 for a flat range): PNG's and RAW16's.
pub(crate) fn quantise(h: f32, min: f32, max: f32) -> u16 {
    if max <= min {
        return 0;
    }
    let t = (f64::from(h) - f64::from(min)) / (f64::from(max) - f64::from(min));
    (t * 65535.0).round().clamp(0.0, 65535.0) as u16
}

fn encode_error(e: impl std::fmt::Display) -> ExportError {
    ExportError::Png(e.to_string())
}

/// Writes the heightmap as a 16-bit grayscale PNG and returns the range it recorded.
pub fn write_png(map: &Heightmap, out: impl Write) -> Result<HeightRange, ExportError> {
    super::check_finite(map)?;
    let (min, max) = map.range();
    let mut enc = png::Encoder::new(out, map.cols(), map.rows());
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Sixteen);
    enc.add_text_chunk(KEY_HEIGHT_MIN.into(), min.to_string())
        .map_err(encode_error)?;
    enc.add_text_chunk(KEY_HEIGHT_MAX.into(), max.to_string())
        .map_err(encode_error)?;
    enc.add_text_chunk(KEY_CELL_SIZE.into(), map.cell_size().to_string())
        .map_err(encode_error)?;
    enc.add_text_chunk("Software".into(), "penmodel".into())
        .map_err(encode_error)?;
    let mut writer = enc.write_header().map_err(encode_error)?;
    let mut data = Vec::with_capacity(map.heights().len() * 2);
    for &h in map.heights() {
        // PNG samples are big-endian.
        data.extend_from_slice(&quantise(h, min, max).to_be_bytes());
    }
    writer.write_image_data(&data).map_err(encode_error)?;
    writer.finish().map_err(encode_error)?;
    Ok(HeightRange { min, max })
}

/// Reads the height range a PNG written by [`write_png`] records (`None` if it has none).
pub fn read_png_range(input: impl BufRead + Seek) -> Result<Option<HeightRange>, ExportError> {
    let reader = png::Decoder::new(input).read_info().map_err(encode_error)?;
    let text = &reader.info().uncompressed_latin1_text;
    let get = |key: &str| {
        text.iter()
            .find(|t| t.keyword == key)
            .and_then(|t| t.text.parse::<f32>().ok())
    };
    Ok(get(KEY_HEIGHT_MIN)
        .zip(get(KEY_HEIGHT_MAX))
        .map(|(min, max)| HeightRange { min, max }))
}
