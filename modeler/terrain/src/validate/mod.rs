//! Validation of a document, with errors that name the element and the reason.
//!
//! A document is valid when:
//! - its version is [`VERSION`], the grid has at least one cell, a cell size within
//!   [[`MIN_CELL_SIZE`], [`MAX_CELL_SIZE`]] m and at most [`MAX_CELLS`] cells;
//! - every number is finite, every point lies on the grid (`0 ≤ x < cols·s`, `0 ≤ y < rows·s`),
//!   heights are within ±[`MAX_HEIGHT`] m and slopes within ±[`MAX_SLOPE`] — the ranges that make
//!   every intermediate term of eq. 1–4 and every `f32` height finite;
//! - figures are nested at most [`MAX_DEPTH`] deep (a figure path has at most that many figure
//!   indices), so that every document and journal line the editor writes parses back;
//! - the terrain engine's caches ([`engine_bytes`]) fit in [`MAX_ENGINE_BYTES`];
//! - a point figure has one point, a polyline at least two, and no point repeats the one before;
//! - region boundaries and closed figures are closed (last point equal to the first), have at
//!   least three distinct vertices and do not cross or touch themselves (polylines may cross
//!   themselves: a ridge that loops is still a ridge);
//! - every figure lies strictly inside its region (the region's boundary, or the closed figure it
//!   is nested in): its points are inside and its segments do not touch the region's edge;
//! - only closed figures hold nested figures;
//! - top-level regions do not overlap on the grid, and neither do the closed figures of one
//!   region (each is the region of its nested figures). Overlap is tested on the rasterised cells,
//!   so two curves closer than a cell that share a cell overlap.
//!
//! Errors stop at the first problem, in document order (the memory check comes last).
//!
//! The curve checks are linear in the number of vertices for drawn curves: a curve's segments go
//! into a grid of buckets about one segment long (`SegmentIndex`) and each segment is tested only
//! against those in its neighbouring buckets; points are located against their region's edge
//! through bands of rows (`Bands`).

mod curves;
mod figures;
mod grid;
mod memory;
mod ridges;
mod rivers;
mod rocks;
mod terrain;
mod trees;

use std::fmt;

use thiserror::Error;

use crate::cells::{self, Mask};
use crate::document::{Document, OLDEST_VERSION, VERSION};
pub use crate::ridge::RidgeError;

pub use curves::CurveDefect;
pub use figures::{FigureDefect, height, region, region_overlap, slope};
pub use grid::{GridDefect, grid};
pub use memory::{engine_bytes, memory};
pub use ridges::ridges;
pub use rivers::{RiverDefect, rivers};
pub use rocks::{RockDefect, rock_fields};
pub use terrain::{
    MAX_DETAIL_OCTAVES, MAX_EROSION_ITERATIONS, MAX_FLUVIAL_STEPS, TerrainDefect, base, base_loaded, erosion, terrain,
};
pub use trees::{TreeDefect, groves, species, trees};

/// The most cells a grid may have: 4096 × 4096. The engine keeps about 16 bytes per cell per
/// figure of a region plus about 30 per cell, so a larger grid would not fit a workstation.
pub const MAX_CELLS: u64 = 1 << 24;

/// The smallest cell size, in metres. Below it mesh vertices `(c + ½)·s` would round together in
/// `f32` and their normals become undefined.
pub const MIN_CELL_SIZE: f64 = 1e-3;

/// The largest cell size, in metres: 100 km, so the grid's extent (≤ 4096 cells) stays far within
/// `f32` range with room for squared distances.
pub const MAX_CELL_SIZE: f64 = 1e5;

/// The largest absolute height, in metres (1000 km). A cell's height is the base plus a weighted
/// mean of reliefs (height − base, at most twice this), so every term stays a finite `f32`.
pub const MAX_HEIGHT: f64 = 1e6;

/// The largest absolute slope coefficient. Eq. 4 adds two slopes and multiplies by a weight;
/// eq. 2 raises a number in [0, 1] to `1 ± s`: within this range nothing overflows, and beyond a
/// few units the profile is already a step.
pub const MAX_SLOPE: f64 = 1e3;

/// The deepest a figure may be nested: a top-level figure is at depth 1, a figure in it at 2. The
/// JSON reader stops at 128 nested arrays and objects; a figure at depth d is 2d + 5 deep in the
/// document and 2d + 7 in a journal's `history` line, so 32 leaves room, and the editor refuses
/// the figure that would go deeper.
pub const MAX_DEPTH: usize = 32;

/// Bytes the terrain engine keeps per figure per cell of its region's bounding box: distances,
/// eq. 2 shape terms, their logarithms (a slope change is one `exp` per cell) and coefficients
/// (`f32` each).
pub const BYTES_PER_FIGURE_CELL: u64 = 16;

/// Bytes the terrain engine keeps, or allocates for a moment, per cell of a region's bounding
/// box whatever its figures: the mask, edge distances, eq. 3's normaliser (`f64`), a search
/// queue, a distance map being rebuilt and the cells it changed.
pub const BYTES_PER_REGION_CELL: u64 = 32;

/// The most memory the terrain engine may need for a document, in bytes (2 GiB): see
/// [`engine_bytes`]. 100 figures over 1024² cells need about 1.6 GB; 300 over 2048² would need
/// 20 GB, which aborted the process before this limit.
pub const MAX_ENGINE_BYTES: u64 = 2 << 30;

/// A number written compactly for a message: the shortest form that reads back, in exponent
/// notation when it is very large or very small (`1e308`, not 309 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if v == 0.0 || !v.is_finite() || (1e-4..1e15).contains(&a) {
            write!(f, "{v}")
        } else {
            write!(f, "{v:e}")
        }
    }
}

/// A byte count for a message, in the largest unit that keeps it ≥ 1 (`1.3 GB`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = self.0 as f64;
        match self.0 {
            0..1_000_000 => write!(f, "{:.1} kB", b / 1e3),
            1_000_000..1_000_000_000 => write!(f, "{:.1} MB", b / 1e6),
            _ => write!(f, "{:.1} GB", b / 1e9),
        }
    }
}

/// A document element that is not valid, and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{path}: {defect}")]
pub struct ValidationError {
    /// The element, e.g. `regions[1].figures[0].points[3]`.
    pub path: String,
    /// What is wrong with it.
    pub defect: Defect,
}

impl ValidationError {
    /// An error at `path`.
    pub fn new(path: impl Into<String>, defect: impl Into<Defect>) -> ValidationError {
        ValidationError {
            path: path.into(),
            defect: defect.into(),
        }
    }
}

/// What is wrong with an element: a defect of the document itself or of a number, or one element
/// kind's own defect (each kind's module defines and checks it). The message is the kind's.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Defect {
    /// The version is not one this build reads.
    #[error("unsupported document version {0} (this build reads versions {OLDEST_VERSION} to {VERSION})")]
    Version(String),
    /// An element the document's version does not have.
    #[error("needs document version {0}")]
    NeedsVersion(u32),
    /// The terrain engine would need more than [`MAX_ENGINE_BYTES`].
    #[error(
        "the terrain would need about {} of memory ({figures} figures over {cells} cells of region bounding boxes), \
         more than the limit of {}: use fewer figures or a coarser grid",
        Bytes(*bytes),
        Bytes(*max)
    )]
    TooLarge {
        /// The estimate, [`engine_bytes`].
        bytes: u64,
        /// Figures in the document, at every depth.
        figures: u64,
        /// Cells of every region's and nested region's bounding box, summed.
        cells: u64,
        /// [`MAX_ENGINE_BYTES`].
        max: u64,
    },
    /// A number is NaN or infinite.
    #[error("not a finite number")]
    NotFinite,
    /// A width, depth, water amount, hardness, density, weight or scale that is not above 0.
    #[error("{} must be above 0", Num(*_0))]
    NotPositive(f64),
    /// A coefficient out of its range.
    #[error("{} must be from {} to {}", Num(*value), Num(*min), Num(*max))]
    Coefficient {
        #[allow(missing_docs)]
        value: f64,
        #[allow(missing_docs)]
        min: f64,
        #[allow(missing_docs)]
        max: f64,
    },
    /// The grid's.
    #[error(transparent)]
    Grid(#[from] GridDefect),
    /// A point's or a closed curve's (a region's boundary, a closed figure, a field's outline).
    #[error(transparent)]
    Curve(#[from] CurveDefect),
    /// A region's or a figure's.
    #[error(transparent)]
    Figure(#[from] FigureDefect),
    /// A rock field's.
    #[error(transparent)]
    Rocks(#[from] RockDefect),
    /// A river's.
    #[error(transparent)]
    River(#[from] RiverDefect),
    /// The ridgelines' and ridgeline trees' (the error names the element:
    /// `ridges.lines[2].points[1]`).
    #[error(transparent)]
    Ridge(#[from] RidgeError),
    /// A tree's or a grove's.
    #[error(transparent)]
    Tree(#[from] TreeDefect),
    /// The terrain settings' (`terrain.detail`, `terrain.erosion`).
    #[error(transparent)]
    Terrain(#[from] TerrainDefect),
}

/// Checks the whole document.
pub fn document(doc: &Document) -> Result<(), ValidationError> {
    if doc.version != VERSION {
        return Err(ValidationError::new(
            "version",
            Defect::Version(doc.version.to_string()),
        ));
    }
    grid(&doc.grid)?;
    for (i, r) in doc.regions.iter().enumerate() {
        region(&doc.grid, r, i)?;
    }
    let masks: Vec<Mask> = doc
        .regions
        .iter()
        .map(|r| cells::closed_mask(&doc.grid, &r.boundary))
        .collect();
    for (i, m) in masks.iter().enumerate() {
        region_overlap(i, m, masks.iter().enumerate().take(i))?;
    }
    rock_fields(doc)?;
    rivers(doc)?;
    ridges(doc)?;
    trees(doc)?;
    groves(doc)?;
    terrain(doc)?;
    memory(doc)
}

fn finite(v: f64, path: impl FnOnce() -> String) -> Result<(), ValidationError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ValidationError::new(path(), Defect::NotFinite))
    }
}
