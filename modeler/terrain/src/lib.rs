//! The terrain model of seed 000: a document of regions and control figures, and the terrain as a
//! pure function of it, with nothing of the pen or the screen.
//!
//! - [`Document`]: the source of truth — a grid, generation regions, and control figures (points,
//!   polylines, closed curves) with heights and slopes, nested to any depth. Saved as versioned
//!   JSON (`docs/document.md`), validated on load ([`validate`]).
//! - [`generate`] and [`TerrainEngine`]: the terrain by the thesis' equations 1–4 ([`raster`],
//!   [`distance`], [`profile`]), regenerated incrementally as the document is edited ([`terrain`]
//!   explains how).
//! - [`Editor`]: edits ([`Edit`]) with undo and redo, and a journal that survives a crash
//!   ([`journal`], [`persist`]).
//! - [`export`]: 16-bit PNG heightmaps, raw float32, OBJ and binary glTF meshes.
//! - [`baseline`]: the seed's own repeat-until-stable distance maps, the reference for tests and
//!   benchmarks.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod address;
pub mod cells;
pub mod change;
pub mod distance;
pub mod document;
pub mod edit;
pub mod editor;
pub mod engine;
pub mod export;
pub mod geometry;
mod heightmap;
pub mod journal;
mod json;
pub mod persist;
pub mod profile;
pub mod validate;

pub use address::{CurvePath, FigurePath};
pub use document::{Document, Figure, FigureKind, Grid, Point, Region};
pub use edit::{Edit, EditError};
pub use editor::{Editor, Outcome};
pub use engine::{Rect, TerrainEngine, generate};
pub use heightmap::Heightmap;
pub use persist::{LoadError, SaveError};
pub use validate::{Defect, ValidationError};
