//! The document: the modeler's source of truth, plain data that serialises as versioned JSON.
//!
//! The format is specified in `docs/document.md`. This module only holds the types; reading and
//! writing them is [`crate::persist`]'s ([`Document::from_json`], [`Document::load`],
//! [`Document::save`]), which validates ([`crate::validate`]). A document built in code is
//! checked when it is handed to the [`TerrainEngine`](crate::TerrainEngine) or saved.

use serde::{Deserialize, Serialize};

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
}
