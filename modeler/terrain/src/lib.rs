//! The terrain model of seed 000: a document of regions and control figures, and the terrain as a
//! pure function of it, with nothing of the pen or the screen.
//!
//! - [`Document`] ([`document`]): the source of truth — a grid, generation regions, and control
//!   figures (points, polylines, closed curves) with heights and slopes, nested to any depth.
//!   Plain data; read and written as versioned JSON by [`persist`] (`docs/document.md`),
//!   validated ([`validate`]), addressed by [`FigurePath`] and [`CurvePath`] ([`address`]).
//! - [`generate`] and [`TerrainEngine`] ([`engine`]): the terrain by the thesis' equations 1–4
//!   ([`cells`], [`distance`], [`profile`]), updated from the document and a change [`change::Scope`]
//!   by regenerating only what changed ([`engine`] explains how).
//! - [`Editor`]: edits ([`Edit`], which turn into a document change and its scope) with undo and
//!   redo, and a journal that survives a crash ([`journal`], [`persist`]).
//! - [`export`]: 16-bit PNG heightmaps, raw float32, OBJ and binary glTF meshes.
//!
//! The seed's own repeat-until-stable distance maps are not here: they are the reference in
//! `tests/baseline.rs`, which the tests compare the engine with and the bench times.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod address;
pub mod cells;
pub mod change;
pub mod detail;
pub mod distance;
pub mod document;
pub mod edit;
pub mod editor;
pub mod edt;
pub mod engine;
pub mod erosion;
pub mod export;
pub mod fastmath;
pub mod fluvial;
// The fuzz targets' properties, shared with the stable test that replays their corpora.
#[doc(hidden)]
pub mod fuzzing;
pub mod geometry;
mod heightmap;
pub mod import;
pub mod input;
pub mod journal;
mod json;
pub mod lock;
pub mod persist;
mod pool;
pub mod profile;
pub mod rect;
pub mod revision;
pub mod ridge;
pub mod river;
pub mod rocks;
// Runtime dispatch of the hot loops to AVX2 and AVX-512; public only for the tests that compare
// the copies.
#[doc(hidden)]
pub mod simd;
pub mod trees;
pub mod validate;

pub use address::{CurvePath, FigurePath};
pub use document::{
    Detail, Document, Erosion, Figure, FigureKind, Fluvial, Grid, Metric, Point, Region, River, TerrainSettings,
};
pub use edit::{Edit, EditError};
pub use editor::{Editor, Outcome};
pub use engine::{Rect, TerrainEngine, generate};
pub use heightmap::Heightmap;
pub use persist::{LoadError, SaveError};
pub use validate::{Defect, ValidationError};
