//! Raw float32: `rows × cols` little-endian IEEE 754 `f32`, row-major (index `r·cols + c`),
//! heights in metres, no header.

use std::io::{self, Read, Write};

use crate::heightmap::Heightmap;

/// Writes the heights as raw little-endian float32.
pub fn write_raw(map: &Heightmap, mut out: impl Write) -> Result<(), super::ExportError> {
    super::check_finite(map)?;
    let mut bytes = Vec::with_capacity(map.heights().len() * 4);
    for h in map.heights() {
        bytes.extend_from_slice(&h.to_le_bytes());
    }
    out.write_all(&bytes)?;
    Ok(out.flush()?)
}

/// Reads `cols × rows` raw little-endian float32 heights.
pub fn read_raw(mut input: impl Read, cols: u32, rows: u32) -> io::Result<Vec<f32>> {
    let mut bytes = vec![0u8; cols as usize * rows as usize * 4];
    input.read_exact(&mut bytes)?;
    Ok(bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}
