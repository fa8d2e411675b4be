//! The `.json` sidecar written beside an exported heightmap: what a program that reads the
//! file needs and the file cannot say (RAW16 says nothing; a PNG's tEXt chunks and a GeoTIFF's
//! tags are not read by every engine).

use serde::Serialize;

use super::HeightRange;
use crate::heightmap::Heightmap;

/// A heightmap file's format, as the sidecar names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// 16-bit grayscale PNG (`--png`).
    Png16,
    /// Little-endian u16, no header (`--raw16`).
    Raw16,
    /// Float32 single-band GeoTIFF (`--geotiff`).
    Geotiff,
}

/// The sidecar of an exported heightmap, serialised as JSON (`docs/heightmaps.md`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sidecar {
    /// The file's format.
    pub format: Format,
    /// Rows (image height, cells along y).
    pub rows: u32,
    /// Columns (image width, cells along x).
    pub cols: u32,
    /// Side of a cell on the ground, metres.
    pub cell_size_m: f64,
    /// The lowest height, metres (the value 0 of a 16-bit file).
    pub height_min_m: f64,
    /// The highest height, metres (the value 65535 of a 16-bit file).
    pub height_max_m: f64,
    /// Metres per 16-bit step, `(max − min) / 65535` (16-bit formats only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertical_scale_m_per_step: Option<f64>,
    /// The byte order of the samples: `little-endian` (RAW16, GeoTIFF) or `big-endian` (PNG).
    pub byte_order: &'static str,
    /// The upper-left corner of the upper-left cell, metres (GeoTIFF only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub origin_m: Option<[f64; 2]>,
    /// The coordinate reference system's EPSG code, if one was given (GeoTIFF only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub epsg: Option<u32>,
    /// Unreal Engine's landscape Z scale that maps the 16-bit range onto `max − min` metres:
    /// `(max − min) · 100 / 512` (Unreal spans 512 m at Z scale 100); 16-bit PNG only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreal_z_scale: Option<f64>,
    /// Unreal Engine's landscape X and Y scale for the cell size: centimetres per cell.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreal_xy_scale: Option<f64>,
    /// The landscape actor's Z location that puts value 0 at `height_min_m`, centimetres:
    /// `50 · (min + max)` (Unreal's value 32768 is the actor's Z).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreal_location_z_cm: Option<f64>,
}

impl Sidecar {
    /// The sidecar of `map` written as `format` over `range`.
    pub fn new(format: Format, map: &Heightmap, range: HeightRange) -> Sidecar {
        let (min, max) = (f64::from(range.min), f64::from(range.max));
        let sixteen = format != Format::Geotiff;
        Sidecar {
            format,
            rows: map.rows(),
            cols: map.cols(),
            cell_size_m: map.cell_size(),
            height_min_m: min,
            height_max_m: max,
            vertical_scale_m_per_step: sixteen.then_some((max - min) / 65535.0),
            byte_order: if format == Format::Png16 {
                "big-endian"
            } else {
                "little-endian"
            },
            origin_m: None,
            epsg: None,
            unreal_z_scale: (format == Format::Png16).then_some((max - min) * 100.0 / 512.0),
            unreal_xy_scale: (format == Format::Png16).then_some(map.cell_size() * 100.0),
            unreal_location_z_cm: (format == Format::Png16).then_some(50.0 * (min + max)),
        }
    }

    /// The sidecar as pretty JSON text, ending in a newline.
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }
}

/// The sidecar's path for a heightmap at `path`: `path` with `.json` appended (`dem.r16.json`).
pub fn sidecar_path(path: &std::path::Path) -> std::path::PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".json");
    std::path::PathBuf::from(name)
}
