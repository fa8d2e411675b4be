//! The document: the modeler's source of truth, saved and loaded as versioned JSON.
//!
//! The format is specified in `docs/document.md`. A [`Document`] read with [`Document::from_json`]
//! or [`Document::load`] has been validated ([`crate::validate`]); a document built in code is
//! checked when it is handed to the [`TerrainEngine`](crate::TerrainEngine) or saved.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::json;
use crate::persist::write_atomic;
use crate::validate::{self, ValidationError};

/// The format version this build reads and writes.
pub const VERSION: u32 = 1;

/// A point in the ground plane, `[x, y]` in metres: x along columns, y along rows.
pub type Point = [f64; 2];

/// A terrain model: a grid and the generation regions drawn on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Document {
    /// Format version; [`VERSION`].
    pub version: u32,
    /// Free text about the document; generation ignores it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The heightfield's grid.
    pub grid: Grid,
    /// The top-level generation regions, which never overlap.
    pub regions: Vec<Region>,
}

/// The heightfield's grid. Cell `(c, r)` covers `[c·s, (c+1)·s) × [r·s, (r+1)·s)`, `s` the cell size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// Number of columns (cells along x).
    pub cols: u32,
    /// Number of rows (cells along y).
    pub rows: u32,
    /// Side of a cell in metres.
    pub cell_size: f64,
}

impl Grid {
    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.cols as usize * self.rows as usize
    }

    /// Extent along x in metres.
    pub fn width(&self) -> f64 {
        f64::from(self.cols) * self.cell_size
    }

    /// Extent along y in metres.
    pub fn height(&self) -> f64 {
        f64::from(self.rows) * self.cell_size
    }
}

/// A generation region: a closed curve bounding the terrain its figures raise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// The closed boundary; its last point repeats its first.
    pub boundary: Vec<Point>,
    /// The control figures inside it.
    #[serde(default)]
    pub figures: Vec<Figure>,
}

/// What a figure is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FigureKind {
    /// One point.
    Point,
    /// An open polyline of two or more points.
    Polyline,
    /// A closed curve (last point repeats the first); also the region of its nested figures.
    Closed,
}

impl FigureKind {
    /// The name the document uses.
    pub fn name(self) -> &'static str {
        match self {
            FigureKind::Point => "point",
            FigureKind::Polyline => "polyline",
            FigureKind::Closed => "closed",
        }
    }
}

/// A control figure: pulled to `height` with the slope coefficient `slope`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Figure {
    /// Point, polyline or closed curve.
    pub kind: FigureKind,
    /// The figure's points; a closed curve repeats its first point at the end.
    pub points: Vec<Point>,
    /// Absolute height in metres (negative for a depression).
    pub height: f64,
    /// Slope coefficient of eq. 2: 0 linear, < 0 sharp, > 0 bell-shaped.
    #[serde(default)]
    pub slope: f64,
    /// For a closed figure, the figures of the nested region it bounds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub figures: Vec<Figure>,
}

impl Figure {
    /// Moves the figure and everything nested in it by `by`.
    pub fn translate(&mut self, by: Point) {
        for p in &mut self.points {
            *p = [p[0] + by[0], p[1] + by[1]];
        }
        for f in &mut self.figures {
            f.translate(by);
        }
    }
}

impl Region {
    /// Moves the boundary and every figure by `by`.
    pub fn translate(&mut self, by: Point) {
        for p in &mut self.boundary {
            *p = [p[0] + by[0], p[1] + by[1]];
        }
        for f in &mut self.figures {
            f.translate(by);
        }
    }
}

/// Why a document could not be read.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The reason.
        source: io::Error,
    },
    /// The text is not JSON of the document's shape.
    #[error("{}: {message} (line {line}, column {column})", if path.is_empty() { "document" } else { path })]
    Parse {
        /// The element that failed, e.g. `regions[0].figures[1].height` (empty for the top level).
        path: String,
        /// What was wrong.
        message: String,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
    },
    /// The document is well formed but not valid.
    #[error(transparent)]
    Invalid(#[from] ValidationError),
}

/// Why a document could not be saved.
#[derive(Debug, Error)]
pub enum SaveError {
    /// The document is not valid; nothing was written.
    #[error(transparent)]
    Invalid(#[from] ValidationError),
    /// Writing failed; the previous file, if any, is intact.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The reason.
        source: io::Error,
    },
}

#[derive(Deserialize)]
struct VersionOnly {
    version: serde_json::Value,
}

impl Document {
    /// An empty document on `grid`.
    pub fn new(grid: Grid) -> Document {
        Document {
            version: VERSION,
            note: None,
            grid,
            regions: Vec::new(),
        }
    }

    /// Parses and validates a document.
    pub fn from_json(text: &str) -> Result<Document, LoadError> {
        // The version decides how to read the rest, so it is checked before the shape.
        let version: VersionOnly = parse(text)?;
        match version.version.as_u64() {
            Some(v) if v == u64::from(VERSION) => {}
            _ => {
                return Err(
                    ValidationError::new("version", validate::Defect::Version(version.version.to_string())).into(),
                );
            }
        }
        let doc: Document = parse(text)?;
        validate::document(&doc)?;
        Ok(doc)
    }

    /// The document as JSON text, in the layout of `docs/document.md` (short arrays on one line).
    pub fn to_json(&self) -> String {
        json::pretty(self)
    }

    /// Reads and validates the document at `path`.
    pub fn load(path: &Path) -> Result<Document, LoadError> {
        let text = fs::read_to_string(path).map_err(|source| LoadError::Io {
            path: path.to_owned(),
            source,
        })?;
        Document::from_json(&text)
    }

    /// Validates the document and writes it to `path` atomically: a temporary file in the same
    /// directory is written and flushed to disk, renamed over `path`, and the directory flushed.
    /// Returns the bytes written.
    pub fn save(&self, path: &Path) -> Result<Vec<u8>, SaveError> {
        validate::document(self)?;
        let bytes = self.to_json().into_bytes();
        write_atomic(path, &bytes).map_err(|source| SaveError::Io {
            path: path.to_owned(),
            source,
        })?;
        Ok(bytes)
    }
}

fn parse<'de, T: Deserialize<'de>>(text: &'de str) -> Result<T, LoadError> {
    let de = &mut serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        LoadError::Parse {
            path: if path == "." { String::new() } else { path },
            message: strip_position(&inner.to_string()),
            line: inner.line(),
            column: inner.column(),
        }
    })?;
    Ok(value)
}

/// serde_json's message without its " at line L column C" suffix (reported separately).
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}
