//! The terrain modeler driven by the 3D pen: seed 000's modeling engine and its pen interaction.
//!
//! - [`Document`]: the source of truth — a grid, generation regions, and control figures (points,
//!   polylines, closed curves) with heights and slopes, nested to any depth. Saved as versioned
//!   JSON (`docs/document.md`), validated on load ([`validate`]).
//! - [`generate`] and [`Engine`]: the terrain as a pure function of the document by the thesis'
//!   equations 1–4 ([`raster`], [`distance`], [`profile`]), regenerated incrementally as the
//!   document is edited ([`terrain`] explains how).
//! - [`Editor`]: edits ([`Edit`]) with undo and redo, and a journal that survives a crash
//!   ([`journal`]).
//! - [`export`]: 16-bit PNG heightmaps, raw float32, OBJ and binary glTF meshes.
//! - [`interaction`]: the seed's pen operations (section 3.2) as a state machine over pen
//!   events — draw, end with SW3, highlight, grab, pull, slope, move, delete, undo, pan and zoom
//!   (`docs/modeler.md`).
//! - [`feed`] and [`session`]: pen events from the built-in demo, `pend` or a device, on a thread
//!   of their own, into an editor; [`picture`]: what a frame of the session shows.
//! - [`render`]: the CPU rasteriser — camera, clipping, depth-buffered triangles, elevation
//!   ramp with lighting, overlays, slope bar and mode text, stereo; [`output`]: PNG frames, their
//!   animation, a window.
//! - [`baseline`]: the seed's own repeat-until-stable distance maps, the reference for tests and
//!   benchmarks.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod baseline;
pub mod distance;
pub mod document;
pub mod edit;
pub mod editor;
pub mod export;
pub mod feed;
// Atomic, durable writes live in the host crate, below the modeler in the dependency order.
use pen_host::fsutil;
pub mod geometry;
mod heightmap;
pub mod interaction;
pub mod journal;
mod json;
pub mod output;
pub mod path;
pub mod picture;
pub mod profile;
pub mod raster;
pub mod render;
pub mod session;
pub mod terrain;
pub mod validate;

pub use document::{Document, Figure, FigureKind, Grid, LoadError, Point, Region, SaveError};
pub use edit::{Edit, EditError};
pub use editor::Editor;
pub use heightmap::Heightmap;
pub use path::{CurvePath, FigurePath};
pub use terrain::{Engine, Outcome, Rect, generate};
pub use validate::{Problem, ValidationError};
