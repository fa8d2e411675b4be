//! Validation of a document, with errors that name the element and the reason.
//!
//! A document is valid when:
//! - its version is [`VERSION`], the grid has at least one cell, a
//!   positive finite cell size and at most [`MAX_CELLS`] cells;
//! - every number is finite and every point lies on the grid (`0 ≤ x < cols·s`, `0 ≤ y < rows·s`);
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
//! Errors stop at the first problem, in document order.

use glam::DVec2;
use thiserror::Error;

use crate::cells::{self, Cell, Mask};
use crate::document::{Document, Figure, FigureKind, Grid, Point, Region, VERSION};
use crate::geometry::{self, Side};

/// The most cells a grid may have: 4096 × 4096. The engine keeps about 12 bytes per cell per
/// figure of a region plus about 30 per cell, so a larger grid would not fit a workstation.
pub const MAX_CELLS: u64 = 1 << 24;

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
    pub fn new(path: impl Into<String>, defect: Defect) -> ValidationError {
        ValidationError {
            path: path.into(),
            defect,
        }
    }
}

/// What is wrong with an element.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Defect {
    /// The version is not one this build reads.
    #[error("unsupported document version {0} (this build reads version {VERSION})")]
    Version(String),
    /// The grid has no cells.
    #[error("the grid needs at least one column and one row")]
    EmptyGrid,
    /// The cell size is not a positive finite number.
    #[error("the cell size must be a positive finite number of metres, got {0}")]
    CellSize(f64),
    /// The grid has more cells than [`MAX_CELLS`].
    #[error("{cells} cells is more than the {max} this build can hold in memory")]
    GridTooLarge { cells: u64, max: u64 },
    /// A number is NaN or infinite.
    #[error("not a finite number")]
    NotFinite,
    /// A point lies off the grid.
    #[error("({x}, {y}) lies outside the grid [0, {width}) × [0, {height}) m")]
    OutsideGrid {
        x: f64,
        y: f64,
        /// The grid's extent along x.
        width: f64,
        /// The grid's extent along y.
        height: f64,
    },
    /// A point figure without exactly one point.
    #[error("a point figure has exactly one point, found {0}")]
    PointCount(usize),
    /// A polyline with fewer than two points.
    #[error("a polyline needs at least two points, found {0}")]
    PolylineTooShort(usize),
    /// A closed curve with fewer than three distinct vertices.
    #[error("a closed curve needs at least three distinct points, found {0}")]
    CurveTooShort(usize),
    /// A point equal to the one before it.
    #[error("repeats the previous point")]
    RepeatedPoint,
    /// A closed curve whose last point is not its first.
    #[error("the curve is open: its last point ({}, {}) is not its first ({}, {})", last[0], last[1], first[0], first[1])]
    OpenCurve { first: Point, last: Point },
    /// A closed curve that crosses or touches itself.
    #[error("the curve crosses itself: the segment from this point meets the segment from points[{0}]")]
    SelfIntersecting(usize),
    /// A figure point outside its region.
    #[error("lies outside its region {0}")]
    OutsideRegion(String),
    /// A figure point on its region's edge.
    #[error("lies on the edge of its region {0}")]
    OnRegionEdge(String),
    /// A figure segment that leaves its region.
    #[error("the segment from the previous point to this one touches the edge of its region {0}")]
    CrossesRegionEdge(String),
    /// Nested figures in a figure that is not closed.
    #[error("a {0} figure cannot hold nested figures; only a closed figure bounds a region")]
    NestedInOpenFigure(&'static str),
    /// Two regions share grid cells.
    #[error("overlaps {other} on the grid (both cover cell ({}, {}))", cell.0, cell.1)]
    Overlap {
        /// The element it overlaps.
        other: String,
        /// The first shared cell, row by row.
        cell: Cell,
    },
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
    Ok(())
}

/// Checks the grid.
pub fn grid(g: &Grid) -> Result<(), ValidationError> {
    if g.cols == 0 || g.rows == 0 {
        return Err(ValidationError::new("grid", Defect::EmptyGrid));
    }
    if !(g.cell_size.is_finite() && g.cell_size > 0.0 && g.width().is_finite() && g.height().is_finite()) {
        return Err(ValidationError::new("grid.cell_size", Defect::CellSize(g.cell_size)));
    }
    let cells = u64::from(g.cols) * u64::from(g.rows);
    if cells > MAX_CELLS {
        return Err(ValidationError::new(
            "grid",
            Defect::GridTooLarge { cells, max: MAX_CELLS },
        ));
    }
    Ok(())
}

/// Checks top-level region `index` on its own: its boundary and every figure in it, at any depth.
/// Overlap with the other top-level regions is [`region_overlap`]'s.
pub fn region(grid: &Grid, region: &Region, index: usize) -> Result<(), ValidationError> {
    let path = format!("regions[{index}]");
    ring(
        grid,
        &region.boundary,
        |i| format!("{path}.boundary[{i}]"),
        &format!("{path}.boundary"),
    )?;
    figures(
        grid,
        &region.figures,
        &region.boundary,
        &format!("{path}.boundary"),
        &path,
    )
}

/// Checks that region `index`'s cells `mask` share no cell with the `others` (index, cells).
pub fn region_overlap<'a>(
    index: usize,
    mask: &Mask,
    others: impl IntoIterator<Item = (usize, &'a Mask)>,
) -> Result<(), ValidationError> {
    for (j, other) in others {
        if j == index {
            continue;
        }
        if let Some(cell) = mask.first_common(other) {
            return Err(ValidationError::new(
                format!("regions[{index}]"),
                Defect::Overlap {
                    other: format!("regions[{j}]"),
                    cell,
                },
            ));
        }
    }
    Ok(())
}

fn finite(v: f64, path: impl FnOnce() -> String) -> Result<(), ValidationError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ValidationError::new(path(), Defect::NotFinite))
    }
}

/// Every point finite, on the grid, and different from the one before.
fn points(grid: &Grid, pts: &[Point], path: &impl Fn(usize) -> String) -> Result<(), ValidationError> {
    for (i, p) in pts.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ValidationError::new(path(i), Defect::NotFinite));
        }
        let (w, h) = (grid.width(), grid.height());
        if !(p[0] >= 0.0 && p[0] < w && p[1] >= 0.0 && p[1] < h) {
            let defect = Defect::OutsideGrid {
                x: p[0],
                y: p[1],
                width: w,
                height: h,
            };
            return Err(ValidationError::new(path(i), defect));
        }
        if i > 0 && pts[i - 1] == *p {
            return Err(ValidationError::new(path(i), Defect::RepeatedPoint));
        }
    }
    Ok(())
}

/// A closed curve: valid points, closed, three or more vertices, not touching itself.
fn ring(grid: &Grid, pts: &[Point], path: impl Fn(usize) -> String, whole: &str) -> Result<(), ValidationError> {
    points(grid, pts, &path)?;
    let (Some(&first), Some(&last)) = (pts.first(), pts.last()) else {
        return Err(ValidationError::new(whole, Defect::CurveTooShort(0)));
    };
    if first != last {
        return Err(ValidationError::new(whole, Defect::OpenCurve { first, last }));
    }
    let n = pts.len() - 1; // segments, = distinct vertices
    if n < 3 {
        return Err(ValidationError::new(whole, Defect::CurveTooShort(n)));
    }
    let seg = |i: usize| (pts[i], pts[i + 1]);
    for j in 1..n {
        for i in 0..j {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let meets = if adjacent {
                // Adjacent segments share a vertex; they meet elsewhere only by doubling back.
                let (p, q, r) = if j == i + 1 {
                    (pts[i], pts[j], pts[j + 1])
                } else {
                    (pts[j], pts[0], pts[1])
                };
                let (p, q, r) = (DVec2::from(p), DVec2::from(q), DVec2::from(r));
                geometry::orient(p, q, r) == 0.0 && (p - q).dot(r - q) > 0.0
            } else {
                let ((a, b), (c, d)) = (seg(i), seg(j));
                geometry::segments_touch(a, b, c, d)
            };
            if meets {
                return Err(ValidationError::new(path(j), Defect::SelfIntersecting(i)));
            }
        }
    }
    Ok(())
}

/// The figures of one region, bounded by `edge` (named `edge_path`), with paths under `parent`.
fn figures(grid: &Grid, figs: &[Figure], edge: &[Point], edge_path: &str, parent: &str) -> Result<(), ValidationError> {
    for (k, f) in figs.iter().enumerate() {
        figure(grid, f, edge, edge_path, &format!("{parent}.figures[{k}]"))?;
    }
    // Sibling closed figures bound nested regions, which must not share cells.
    let closed: Vec<(usize, Mask)> = figs
        .iter()
        .enumerate()
        .filter(|(_, f)| f.kind == FigureKind::Closed)
        .map(|(k, f)| (k, cells::closed_mask(grid, &f.points)))
        .collect();
    for (a, (ka, ma)) in closed.iter().enumerate() {
        for (kb, mb) in &closed[..a] {
            if let Some(cell) = ma.first_common(mb) {
                return Err(ValidationError::new(
                    format!("{parent}.figures[{ka}]"),
                    Defect::Overlap {
                        other: format!("{parent}.figures[{kb}]"),
                        cell,
                    },
                ));
            }
        }
    }
    Ok(())
}

fn figure(grid: &Grid, f: &Figure, edge: &[Point], edge_path: &str, path: &str) -> Result<(), ValidationError> {
    finite(f.height, || format!("{path}.height"))?;
    finite(f.slope, || format!("{path}.slope"))?;
    let point_path = |i: usize| format!("{path}.points[{i}]");
    match f.kind {
        FigureKind::Point => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() != 1 {
                return Err(ValidationError::new(
                    format!("{path}.points"),
                    Defect::PointCount(f.points.len()),
                ));
            }
        }
        FigureKind::Polyline => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() < 2 {
                let defect = Defect::PolylineTooShort(f.points.len());
                return Err(ValidationError::new(format!("{path}.points"), defect));
            }
        }
        FigureKind::Closed => ring(grid, &f.points, point_path, &format!("{path}.points"))?,
    }
    for (i, &p) in f.points.iter().enumerate() {
        match geometry::locate(edge, p) {
            Side::Inside => {}
            Side::On => {
                return Err(ValidationError::new(
                    point_path(i),
                    Defect::OnRegionEdge(edge_path.into()),
                ));
            }
            Side::Outside => {
                return Err(ValidationError::new(
                    point_path(i),
                    Defect::OutsideRegion(edge_path.into()),
                ));
            }
        }
        if i > 0 {
            let (a, b) = (f.points[i - 1], p);
            if edge.windows(2).any(|e| geometry::segments_touch(a, b, e[0], e[1])) {
                return Err(ValidationError::new(
                    point_path(i),
                    Defect::CrossesRegionEdge(edge_path.into()),
                ));
            }
        }
    }
    if !f.figures.is_empty() {
        if f.kind != FigureKind::Closed {
            return Err(ValidationError::new(
                format!("{path}.figures"),
                Defect::NestedInOpenFigure(f.kind.name()),
            ));
        }
        figures(grid, &f.figures, &f.points, &format!("{path}.points"), path)?;
    }
    Ok(())
}
