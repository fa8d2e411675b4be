//! Float32 single-band GeoTIFF heightmaps, written and read by hand.
//!
//! Why not the `tiff` crate: what we write is one uncompressed strip of `f32` samples and 14
//! tags (~100 lines here), and what we read back is the same baseline layout; the crate would
//! bring a codec stack (LZW, Deflate, JPEG) we do not use and an API that has changed across
//! its 0.x releases for custom tags. A compressed or tiled file (as GDAL may write) is refused
//! with a message naming `gdal_translate -co COMPRESS=NONE`.
//!
//! The file: little-endian classic TIFF; the samples right after the 8-byte header (image row
//! r = grid row r, top to bottom), then the one IFD with its out-of-line values. Georeferencing
//! (GeoTIFF 1.1): `ModelPixelScale` (33550) = `(s, s, 0)`, `ModelTiepoint` (33922) = raster
//! `(0, 0, 0)` at model `(X, Y, 0)`, the upper-left corner, and a `GeoKeyDirectory` (34735):
//! projected model, pixel-is-area, linear unit metre, and the projected CRS's EPSG code when
//! one is given (else none: a local, unknown CRS). GDAL reads this as the geotransform
//! `(X, s, 0, Y, 0, −s)`: grid rows run south.

use std::io::Write;

use super::{ExportError, HeightRange};
use crate::heightmap::Heightmap;

/// Where the GeoTIFF's upper-left corner is and in which CRS.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GeoRef {
    /// The upper-left corner of the upper-left cell, `[x, y]` metres in the CRS.
    pub origin: [f64; 2],
    /// The projected CRS's EPSG code; `None`: local, unknown.
    pub epsg: Option<u32>,
}

const SHORT: u16 = 3;
const LONG: u16 = 4;
const DOUBLE: u16 = 12;

/// TIFF tag numbers read or written here.
mod tag {
    pub const WIDTH: u16 = 256;
    pub const LENGTH: u16 = 257;
    pub const BITS: u16 = 258;
    pub const COMPRESSION: u16 = 259;
    pub const PHOTOMETRIC: u16 = 262;
    pub const STRIP_OFFSETS: u16 = 273;
    pub const SAMPLES: u16 = 277;
    pub const ROWS_PER_STRIP: u16 = 278;
    pub const STRIP_BYTES: u16 = 279;
    pub const PLANAR: u16 = 284;
    pub const TILE_WIDTH: u16 = 322;
    pub const SAMPLE_FORMAT: u16 = 339;
    pub const PIXEL_SCALE: u16 = 33550;
    pub const TIEPOINT: u16 = 33922;
    pub const GEO_KEYS: u16 = 34735;
    pub const GDAL_NODATA: u16 = 42113;
}

enum Value {
    Shorts(Vec<u16>),
    Long(u32),
    Doubles(Vec<f64>),
}

/// Writes the heightmap as a float32 GeoTIFF and returns its height range.
pub fn write_geotiff(map: &Heightmap, geo: GeoRef, mut out: impl Write) -> Result<HeightRange, ExportError> {
    super::check_finite(map)?;
    let (min, max) = map.range();
    let data_len = map.heights().len() as u64 * 4;
    // Classic TIFF's offsets are 32-bit: the samples, the IFD and its values must fit.
    if data_len + 4096 > u64::from(u32::MAX) {
        return Err(ExportError::TooLarge(data_len));
    }
    let s = map.cell_size();
    let mut keys: Vec<u16> = vec![1, 1, 0, 0];
    let mut key = |id: u16, value: u16| keys.extend_from_slice(&[id, 0, 1, value]);
    key(1024, 1); // GTModelTypeGeoKey: projected
    key(1025, 1); // GTRasterTypeGeoKey: pixel is area
    if let Some(epsg) = geo.epsg {
        // ProjectedCSTypeGeoKey; codes above 65535 do not fit a GeoKey (none exist).
        key(3072, u16::try_from(epsg).unwrap_or(32767));
    }
    key(3076, 9001); // ProjLinearUnitsGeoKey: metre
    keys[3] = (keys.len() as u16 - 4) / 4;
    let entries: Vec<(u16, Value)> = vec![
        (tag::WIDTH, Value::Long(map.cols())),
        (tag::LENGTH, Value::Long(map.rows())),
        (tag::BITS, Value::Shorts(vec![32])),
        (tag::COMPRESSION, Value::Shorts(vec![1])),
        (tag::PHOTOMETRIC, Value::Shorts(vec![1])),
        (tag::STRIP_OFFSETS, Value::Long(8)),
        (tag::SAMPLES, Value::Shorts(vec![1])),
        (tag::ROWS_PER_STRIP, Value::Long(map.rows())),
        (tag::STRIP_BYTES, Value::Long(data_len as u32)),
        (tag::PLANAR, Value::Shorts(vec![1])),
        (tag::SAMPLE_FORMAT, Value::Shorts(vec![3])),
        (tag::PIXEL_SCALE, Value::Doubles(vec![s, s, 0.0])),
        (
            tag::TIEPOINT,
            Value::Doubles(vec![0.0, 0.0, 0.0, geo.origin[0], geo.origin[1], 0.0]),
        ),
        (tag::GEO_KEYS, Value::Shorts(keys)),
    ];
    let ifd_at = 8 + data_len as u32;
    let ifd_len = 2 + entries.len() as u32 * 12 + 4;
    let mut extra: Vec<u8> = Vec::new();
    let mut ifd: Vec<u8> = Vec::with_capacity(ifd_len as usize);
    ifd.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for (id, value) in &entries {
        let (kind, count, bytes): (u16, u32, Vec<u8>) = match value {
            Value::Shorts(v) => (SHORT, v.len() as u32, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
            Value::Long(v) => (LONG, 1, v.to_le_bytes().to_vec()),
            Value::Doubles(v) => (DOUBLE, v.len() as u32, v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        };
        ifd.extend_from_slice(&id.to_le_bytes());
        ifd.extend_from_slice(&kind.to_le_bytes());
        ifd.extend_from_slice(&count.to_le_bytes());
        if bytes.len() <= 4 {
            let mut inline = [0u8; 4];
            inline[..bytes.len()].copy_from_slice(&bytes);
            ifd.extend_from_slice(&inline);
        } else {
            let at = ifd_at + ifd_len + extra.len() as u32;
            ifd.extend_from_slice(&at.to_le_bytes());
            extra.extend_from_slice(&bytes);
            // Values start on a word boundary.
            if extra.len() % 2 == 1 {
                extra.push(0);
            }
        }
    }
    ifd.extend_from_slice(&0u32.to_le_bytes()); // no next IFD
    let mut bytes = Vec::with_capacity(8 + data_len as usize + ifd.len() + extra.len());
    bytes.extend_from_slice(b"II");
    bytes.extend_from_slice(&42u16.to_le_bytes());
    bytes.extend_from_slice(&ifd_at.to_le_bytes());
    for h in map.heights() {
        bytes.extend_from_slice(&h.to_le_bytes());
    }
    bytes.extend_from_slice(&ifd);
    bytes.extend_from_slice(&extra);
    out.write_all(&bytes)?;
    out.flush()?;
    Ok(HeightRange { min, max })
}

/// A float32 GeoTIFF read back: its size, heights (row-major), cell size and origin if tagged.
#[derive(Debug, Clone, PartialEq)]
pub struct GeoTiff {
    /// Columns (image width).
    pub cols: u32,
    /// Rows (image length).
    pub rows: u32,
    /// Heights, row-major, as stored (NaN and no-data values included; the caller checks).
    pub heights: Vec<f32>,
    /// `ModelPixelScale`'s x and y, if the file has it.
    pub pixel_scale: Option<[f64; 2]>,
    /// `ModelTiepoint`'s model x and y of raster (0, 0), if the file has it.
    pub origin: Option<[f64; 2]>,
    /// GDAL's no-data value, if the file names one.
    pub nodata: Option<f64>,
}

/// Reads a baseline float32 single-band TIFF or GeoTIFF, uncompressed, in strips, either byte
/// order (what [`write_geotiff`] writes, and GDAL with `-co COMPRESS=NONE`). Anything else is
/// an error that says what the file has.
pub fn read_geotiff(bytes: &[u8]) -> Result<GeoTiff, String> {
    let truncated = || "the file is cut off (a TIFF offset points past its end)".to_string();
    let le = match bytes.get(..4) {
        Some(b"II\x2a\x00") => true,
        Some(b"MM\x00\x2a") => false,
        Some(b"II\x2b\x00") | Some(b"MM\x00\x2b") => {
            return Err("BigTIFF is not read; write a classic TIFF (gdal_translate -co BIGTIFF=NO)".into());
        }
        _ => return Err("not a TIFF file (no II*/MM* header)".into()),
    };
    let u16_at = |at: usize| -> Result<u16, String> {
        let b = bytes.get(at..at + 2).ok_or_else(truncated)?;
        Ok(if le {
            u16::from_le_bytes([b[0], b[1]])
        } else {
            u16::from_be_bytes([b[0], b[1]])
        })
    };
    let u32_at = |at: usize| -> Result<u32, String> {
        let b = bytes.get(at..at + 4).ok_or_else(truncated)?;
        let a = [b[0], b[1], b[2], b[3]];
        Ok(if le {
            u32::from_le_bytes(a)
        } else {
            u32::from_be_bytes(a)
        })
    };
    let ifd = u32_at(4)? as usize;
    let n = u16_at(ifd)? as usize;
    // Each entry's values as numbers (SHORT, LONG, DOUBLE, ASCII as text).
    let mut nums: Vec<(u16, Vec<f64>)> = Vec::with_capacity(n);
    let mut nodata = None;
    for e in 0..n {
        let at = ifd + 2 + e * 12;
        let id = u16_at(at)?;
        let kind = u16_at(at + 2)?;
        let count = u32_at(at + 4)? as usize;
        let size = match kind {
            1 | 2 | 6 | 7 => 1,
            3 | 8 => 2,
            4 | 9 | 11 => 4,
            5 | 10 | 12 => 8,
            _ => continue, // a type this reader does not know: skip the tag
        };
        let len = count.checked_mul(size).ok_or_else(truncated)?;
        let data = if len <= 4 { at + 8 } else { u32_at(at + 8)? as usize };
        let raw = bytes
            .get(data..data.checked_add(len).ok_or_else(truncated)?)
            .ok_or_else(truncated)?;
        if id == tag::GDAL_NODATA && kind == 2 {
            let text = String::from_utf8_lossy(raw);
            nodata = text.trim_matches(char::from(0)).trim().parse::<f64>().ok();
            continue;
        }
        let mut v = Vec::with_capacity(count);
        for i in 0..count {
            let o = data + i * size;
            v.push(match kind {
                3 => f64::from(u16_at(o)?),
                4 => f64::from(u32_at(o)?),
                12 => {
                    let hi_lo = (u64::from(u32_at(o)?), u64::from(u32_at(o + 4)?));
                    let bits = if le {
                        hi_lo.0 | (hi_lo.1 << 32)
                    } else {
                        (hi_lo.0 << 32) | hi_lo.1
                    };
                    f64::from_bits(bits)
                }
                _ => break,
            });
        }
        nums.push((id, v));
    }
    let get = |id: u16| nums.iter().find(|(t, _)| *t == id).map(|(_, v)| v.as_slice());
    let one = |id: u16, default: Option<f64>| -> Result<f64, String> {
        get(id)
            .and_then(|v| v.first().copied())
            .or(default)
            .ok_or_else(|| format!("the TIFF has no tag {id}"))
    };
    let cols = one(tag::WIDTH, None)? as u32;
    let rows = one(tag::LENGTH, None)? as u32;
    let bits = one(tag::BITS, Some(1.0))?;
    let format = one(tag::SAMPLE_FORMAT, Some(1.0))?;
    let samples = one(tag::SAMPLES, Some(1.0))?;
    let compression = one(tag::COMPRESSION, Some(1.0))?;
    if bits != 32.0 || format != 3.0 || samples != 1.0 {
        return Err(format!(
            "the TIFF holds {samples} sample(s) of {bits} bits in sample format {format}; a heightmap here is one \
             float32 band (sample format 3): convert it with gdal_translate -ot Float32 -b 1"
        ));
    }
    if compression != 1.0 {
        return Err(format!(
            "the TIFF is compressed (compression {compression}); write it uncompressed: gdal_translate -co COMPRESS=NONE"
        ));
    }
    if get(tag::TILE_WIDTH).is_some() {
        return Err("the TIFF is tiled; write it in strips: gdal_translate -co TILED=NO".into());
    }
    let offsets = get(tag::STRIP_OFFSETS).ok_or("the TIFF has no strip offsets")?;
    let counts = get(tag::STRIP_BYTES).ok_or("the TIFF has no strip byte counts")?;
    // The samples cannot be more than the file: checked before anything is allocated.
    let want = u128::from(cols) * u128::from(rows) * 4;
    if want > bytes.len() as u128 {
        return Err(format!(
            "the TIFF is cut off: its {cols} × {rows} float32 samples need {want} bytes, the file has {}",
            bytes.len()
        ));
    }
    let want = want as usize;
    let mut data = Vec::with_capacity(want);
    for (&o, &c) in offsets.iter().zip(counts) {
        // Never more than the samples need: strips may overlap, so their sum is not bounded by
        // the file's size.
        let (o, c) = (o as usize, (c as usize).min(want - data.len()));
        data.extend_from_slice(bytes.get(o..o.saturating_add(c)).ok_or_else(truncated)?);
        if data.len() == want {
            break;
        }
    }
    if data.len() < want {
        return Err(format!(
            "the TIFF's strips hold {} bytes, its {cols} × {rows} float32 samples need {want}",
            data.len()
        ));
    }
    let heights = data[..want]
        .chunks_exact(4)
        .map(|b| {
            let a = [b[0], b[1], b[2], b[3]];
            if le {
                f32::from_le_bytes(a)
            } else {
                f32::from_be_bytes(a)
            }
        })
        .collect();
    Ok(GeoTiff {
        cols,
        rows,
        heights,
        pixel_scale: get(tag::PIXEL_SCALE).filter(|v| v.len() >= 2).map(|v| [v[0], v[1]]),
        origin: get(tag::TIEPOINT).filter(|v| v.len() >= 6).map(|v| [v[3], v[4]]),
        nodata,
    })
}
