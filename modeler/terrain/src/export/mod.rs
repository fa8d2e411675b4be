//! Exports of a heightmap: 16-bit PNG, RAW16, float32 GeoTIFF, raw float32 (the heightmaps with a
//! JSON sidecar, [`Sidecar`]), and meshes (OBJ, binary glTF, PLY).
//!
//! Conventions shared by all formats:
//! - grid row r, column c is image row r (top to bottom), column c (left to right), and raw
//!   index `r·cols + c`;
//! - meshes have one vertex per cell at the cell's centre, `x = (c + ½)·s`, `y = (r + ½)·s`,
//!   and map the ground plane and height to the glTF (and de-facto OBJ) Y-up frame as
//!   `X = x, Y = height, Z = y`, which shows the terrain from above the same way round as the
//!   PNG; two triangles per square of four neighbouring centres, counter-clockwise seen from
//!   above (+Y), with per-vertex normals from central differences.

mod geotiff;
mod glb;
mod mesh;
mod obj;
mod ply;
mod png;
mod raw;
mod raw16;
mod sidecar;

use std::io;

use thiserror::Error;

pub use geotiff::{GeoRef, GeoTiff, read_geotiff, write_geotiff};
pub use glb::{
    Alpha, GlbScene, INSTANCING, Instance, Material, Part, write_glb, write_glb_meshes, write_glb_scene, write_glb_with,
};
pub use mesh::Mesh;
pub use obj::{write_meshes, write_obj, write_obj_with};
pub use ply::write_ply;
pub use png::{HeightRange, KEY_CELL_SIZE, KEY_HEIGHT_MAX, KEY_HEIGHT_MIN, read_png_range, write_png};
pub use raw::{read_raw, write_raw};
pub use raw16::write_raw16;
pub use sidecar::{Format, Sidecar, sidecar_path};

/// Checks that every height of `map` is finite, so no file gets NaN or infinity in it.
pub fn check_finite(map: &crate::Heightmap) -> Result<(), ExportError> {
    match map.heights().iter().position(|h| !h.is_finite()) {
        None => Ok(()),
        Some(i) => {
            let cols = map.cols().max(1) as usize;
            Err(ExportError::NotFinite {
                col: (i % cols) as u32,
                row: (i / cols) as u32,
                value: map.heights()[i],
            })
        }
    }
}

/// Why an export failed.
#[allow(missing_docs)] // fields named for what they hold.
#[derive(Debug, Error)]
pub enum ExportError {
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] io::Error),
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
    /// A mesh needs at least 2 × 2 cells.
    #[error("a mesh needs at least 2 × 2 cells, the grid is {cols} × {rows}")]
    TooSmallForMesh { cols: u32, rows: u32 },
    /// A height is NaN or infinite. A valid document never gives one (its heights, slopes and
    /// cell size are bounded for that); this guards the files against a heightmap built otherwise.
    #[error("the height of cell ({col}, {row}) is {value}, not a finite number; nothing was exported")]
    NotFinite { col: u32, row: u32, value: f32 },
    /// The mesh does not fit the format's 32-bit sizes.
    #[error("the mesh is too large for binary glTF ({0} bytes)")]
    TooLarge(u64),
    /// A glTF primitive names a material the scene does not have (a bug of the caller).
    #[error("a glTF primitive names material {0}, which the scene does not have")]
    NoMaterial(usize),
}
