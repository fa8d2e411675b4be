//! RAW16 heightmaps for Unity's terrain: `rows × cols` little-endian `u16`, row-major (index
//! `r·cols + c`), no header. Value `v` stands for `min + v / 65535 · (max − min)` metres, the
//! terrain's lowest and highest heights, exactly as the 16-bit PNG's pixels; the range, the size
//! and the scale go in the sidecar ([`super::Sidecar`]), since the file has no room for them.

use std::io::Write;

use super::{ExportError, HeightRange};
use crate::heightmap::Heightmap;

/// Writes the heightmap as RAW16 and returns the height range its values span.
pub fn write_raw16(map: &Heightmap, mut out: impl Write) -> Result<HeightRange, ExportError> {
    super::check_finite(map)?;
    let (min, max) = map.range();
    let mut bytes = Vec::with_capacity(map.heights().len() * 2);
    for &h in map.heights() {
        bytes.extend_from_slice(&super::png::quantise(h, min, max).to_le_bytes());
    }
    out.write_all(&bytes)?;
    out.flush()?;
    Ok(HeightRange { min, max })
}
