//! Heightmaps read in: the file a document's `terrain.base` names, and `penmodel import`.
//!
//! Three kinds, told by the file name's extension: `.png` a 16-bit grayscale PNG (its height
//! range from the `tEXt` chunks `generate --png` writes, or given), `.tif`/`.tiff` a float32
//! GeoTIFF ([`crate::export::read_geotiff`]: its cell size from `ModelPixelScale`), anything
//! else raw float32 (`rows × cols` little-endian, row-major, no header, metres: the size given).
//! Every height must be finite; a file of the wrong size, cut off or unreadable is an error
//! that names the file and what is wrong, never a panic.

use std::fmt;
use std::io::{self, Cursor};
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::document::{Base, BaseHeights, Grid};
use crate::export::{self, HeightRange};

/// The largest heightmap file read, bytes: 256 MiB (the largest grid,
/// [`MAX_CELLS`](crate::validate::MAX_CELLS) cells, is 64 MiB as float32).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Refuses a heightmap of more cells than a document's grid may have, before anything is
/// allocated for it.
fn check_cells(cols: u32, rows: u32) -> Result<(), String> {
    let cells = u64::from(cols) * u64::from(rows);
    if cells > crate::validate::MAX_CELLS {
        return Err(format!(
            "it is {cols} × {rows} cells, more than a document's grid may have ({}); resample it smaller",
            crate::validate::MAX_CELLS
        ));
    }
    Ok(())
}

/// A heightmap file's kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// 16-bit grayscale PNG.
    Png16,
    /// Float32 single-band (Geo)TIFF.
    GeoTiff,
    /// Raw little-endian float32.
    RawF32,
}

impl Kind {
    /// The kind of the file at `path`, by its extension.
    pub fn of(path: &Path) -> Kind {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Kind::Png16,
            Some("tif" | "tiff") => Kind::GeoTiff,
            _ => Kind::RawF32,
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Kind::Png16 => "16-bit PNG",
            Kind::GeoTiff => "float32 GeoTIFF",
            Kind::RawF32 => "raw float32",
        })
    }
}

/// What a file may not say: a raw file's size, a PNG's height range.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Options {
    /// `(rows, cols)` of a raw float32 file.
    pub size: Option<(u32, u32)>,
    /// The heights of a 16-bit PNG's values 0 and 65535, metres (instead of its tEXt chunks).
    pub range: Option<(f64, f64)>,
}

/// A heightmap read in.
#[derive(Debug, Clone, PartialEq)]
pub struct Read {
    /// The file's kind.
    pub kind: Kind,
    /// Columns.
    pub cols: u32,
    /// Rows.
    pub rows: u32,
    /// Heights in metres, row-major, every one finite.
    pub heights: Vec<f32>,
    /// The cell size the file records, metres (a PNG's `cell_size_m`, a GeoTIFF's pixel scale).
    pub cell_size: Option<f64>,
}

/// Why a heightmap could not be read.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Error)]
pub enum ImportError {
    /// The file could not be read.
    #[error("cannot read {}: {cause}", path.display())]
    Io { path: PathBuf, cause: io::Error },
    /// The file is not a heightmap of its kind, or not of the size it must have.
    #[error("{}: {message}", path.display())]
    Bad { path: PathBuf, message: String },
}

/// Reads the heightmap at `path`.
pub fn read(path: &Path, options: &Options) -> Result<Read, ImportError> {
    let bad = |message: String| ImportError::Bad {
        path: path.to_owned(),
        message,
    };
    let bytes = crate::input::read_input(path, MAX_FILE_BYTES).map_err(|cause| ImportError::Io {
        path: path.to_owned(),
        cause,
    })?;
    let kind = Kind::of(path);
    let (cols, rows, heights, cell_size) = match kind {
        Kind::Png16 => read_png(&bytes, options).map_err(bad)?,
        Kind::GeoTiff => {
            let t = export::read_geotiff(&bytes).map_err(bad)?;
            check_cells(t.cols, t.rows).map_err(bad)?;
            let cell = match t.pixel_scale {
                Some([x, y]) if (x.abs() - y.abs()).abs() > 1e-9 * x.abs().max(y.abs()) => {
                    return Err(bad(format!(
                        "its cells are not square ({x} × {y}); resample it to square cells"
                    )));
                }
                Some([x, _]) => Some(x.abs()),
                None => None,
            };
            if let Some(nodata) = t.nodata
                && let Some(i) = t.heights.iter().position(|&h| f64::from(h) == nodata)
            {
                let c = i % t.cols.max(1) as usize;
                return Err(bad(format!(
                    "cell ({c}, {}) holds the no-data value {nodata}: fill the holes first (gdal_fillnodata)",
                    i / t.cols.max(1) as usize
                )));
            }
            (t.cols, t.rows, t.heights, cell)
        }
        Kind::RawF32 => {
            let Some((rows, cols)) = options.size else {
                return Err(bad(
                    "a raw float32 heightmap needs its size: give --size ROWSxCOLS".into()
                ));
            };
            check_cells(cols, rows).map_err(bad)?;
            let want = u64::from(rows) * u64::from(cols) * 4;
            if bytes.len() as u64 != want {
                return Err(bad(format!(
                    "holds {} bytes, but {rows} × {cols} float32 heights are {want} bytes",
                    bytes.len()
                )));
            }
            let heights = export::read_raw(&bytes[..], cols, rows).map_err(|cause| ImportError::Io {
                path: path.to_owned(),
                cause,
            })?;
            (cols, rows, heights, None)
        }
    };
    if cols == 0 || rows == 0 {
        return Err(bad(format!("it has no cells ({cols} × {rows})")));
    }
    if let Some(i) = heights.iter().position(|h| !h.is_finite()) {
        let c = i % cols as usize;
        return Err(bad(format!(
            "the height of cell ({c}, {}) is {}, not a finite number",
            i / cols as usize,
            heights[i]
        )));
    }
    Ok(Read {
        kind,
        cols,
        rows,
        heights,
        cell_size,
    })
}

type Decoded = (u32, u32, Vec<f32>, Option<f64>);

fn read_png(bytes: &[u8], options: &Options) -> Result<Decoded, String> {
    let mut reader = png::Decoder::new(Cursor::new(bytes))
        .read_info()
        .map_err(|e| format!("not a PNG heightmap: {e}"))?;
    let info = reader.info();
    let (cols, rows) = (info.width, info.height);
    check_cells(cols, rows)?;
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(format!(
            "the PNG is {:?} at {} bits; a heightmap here is 16-bit grayscale",
            info.color_type, info.bit_depth as u8
        ));
    }
    let text = &info.uncompressed_latin1_text;
    let get = |key: &str| {
        text.iter()
            .find(|t| t.keyword == key)
            .and_then(|t| t.text.trim().parse::<f64>().ok())
    };
    let cell = get(export::KEY_CELL_SIZE);
    let range = options
        .range
        .or(get(export::KEY_HEIGHT_MIN).zip(get(export::KEY_HEIGHT_MAX)))
        .ok_or(
            "the PNG does not record its height range (tEXt height_min_m and height_max_m): give it (--min M --max M)",
        )?;
    let size = reader
        .output_buffer_size()
        .ok_or("the PNG is too large to decode here")?;
    let mut buf = vec![0u8; size];
    reader
        .next_frame(&mut buf)
        .map_err(|e| format!("the PNG is damaged: {e}"))?;
    let n = cols as usize * rows as usize;
    let range = HeightRange {
        min: range.0 as f32,
        max: range.1 as f32,
    };
    let heights: Vec<f32> = buf
        .chunks_exact(2)
        .take(n)
        .map(|b| range.height(u16::from_be_bytes([b[0], b[1]])))
        .collect();
    if heights.len() != n {
        return Err("the PNG's image data is short".into());
    }
    Ok((cols, rows, heights, cell))
}

/// Loads the heights of a document's base: `base.path` read relative to `dir` (the document's
/// folder), checked against `grid`'s size.
pub fn load_base(base: &mut Base, dir: &Path, grid: &Grid) -> Result<(), ImportError> {
    let path = dir.join(&base.path);
    let read = read(
        &path,
        &Options {
            size: Some((grid.rows, grid.cols)),
            range: base.min.zip(base.max),
        },
    )?;
    if (read.cols, read.rows) != (grid.cols, grid.rows) {
        return Err(ImportError::Bad {
            path,
            message: format!(
                "it is {} × {} cells, the document's grid {} × {} (cols × rows)",
                read.cols, read.rows, grid.cols, grid.rows
            ),
        });
    }
    base.heights = BaseHeights::new(read.heights);
    Ok(())
}
