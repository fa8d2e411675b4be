//! Regions and their figures (seed 000): a region's boundary is a closed curve; its figures lie
//! strictly inside it, have a height and slope within range and the points their kind needs;
//! only closed figures hold nested figures, at most [`MAX_DEPTH`] deep; top-level regions, and
//! the closed figures of one region, share no grid cell.

use thiserror::Error;

use super::curves::{Bands, SegmentIndex, points, ring};
use super::{MAX_DEPTH, MAX_HEIGHT, MAX_SLOPE, Num, ValidationError, finite};
use crate::cells::{self, Cell, Mask};
use crate::document::{Figure, FigureKind, Grid, Point, Region};
use crate::geometry::Side;

/// What is wrong with a region or a figure.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FigureDefect {
    /// A height beyond ±[`MAX_HEIGHT`] metres.
    #[error("a height must be within ±{} m, got {}", Num(MAX_HEIGHT), Num(*.0))]
    HeightRange(f64),
    /// A slope beyond ±[`MAX_SLOPE`].
    #[error("a slope must be within ±{}, got {}", Num(MAX_SLOPE), Num(*.0))]
    SlopeRange(f64),
    /// A figure nested deeper than [`MAX_DEPTH`].
    #[error("figures may be nested at most {MAX_DEPTH} deep; this one is at depth {0}")]
    TooDeep(usize),
    /// A point figure without exactly one point.
    #[error("a point figure has exactly one point, found {0}")]
    PointCount(usize),
    /// A polyline with fewer than two points.
    #[error("a polyline needs at least two points, found {0}")]
    PolylineTooShort(usize),
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
    /// Two regions, or two closed figures of one region, share grid cells.
    #[error("overlaps {other} on the grid (both cover cell ({}, {}))", cell.0, cell.1)]
    Overlap {
        /// The element it overlaps.
        other: String,
        /// The first shared cell, row by row.
        cell: Cell,
    },
}

/// Checks a figure's height: finite and within ±[`MAX_HEIGHT`] metres.
pub fn height(v: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(v, &path)?;
    if v.abs() > MAX_HEIGHT {
        return Err(ValidationError::new(path(), FigureDefect::HeightRange(v)));
    }
    Ok(())
}

/// Checks a figure's slope: finite and within ±[`MAX_SLOPE`].
pub fn slope(v: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(v, &path)?;
    if v.abs() > MAX_SLOPE {
        return Err(ValidationError::new(path(), FigureDefect::SlopeRange(v)));
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
        1,
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
                FigureDefect::Overlap {
                    other: format!("regions[{j}]"),
                    cell,
                },
            ));
        }
    }
    Ok(())
}

/// A region's edge, indexed for the figures inside it.
struct Edge<'a> {
    path: &'a str,
    segments: SegmentIndex<'a>,
    bands: Bands<'a>,
}

/// The figures of one region, bounded by `edge` (named `edge_path`), with paths under `parent`,
/// at nesting `depth` (1 for a top-level region's figures).
fn figures(
    grid: &Grid,
    figs: &[Figure],
    edge: &[Point],
    edge_path: &str,
    parent: &str,
    depth: usize,
) -> Result<(), ValidationError> {
    if !figs.is_empty() && depth > MAX_DEPTH {
        return Err(ValidationError::new(
            format!("{parent}.figures[0]"),
            FigureDefect::TooDeep(depth),
        ));
    }
    let mut edge = Edge {
        path: edge_path,
        segments: SegmentIndex::new(edge),
        bands: Bands::new(edge),
    };
    for (k, f) in figs.iter().enumerate() {
        figure(grid, f, &mut edge, &format!("{parent}.figures[{k}]"), depth)?;
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
                    FigureDefect::Overlap {
                        other: format!("{parent}.figures[{kb}]"),
                        cell,
                    },
                ));
            }
        }
    }
    Ok(())
}

fn figure(grid: &Grid, f: &Figure, edge: &mut Edge<'_>, path: &str, depth: usize) -> Result<(), ValidationError> {
    height(f.height, || format!("{path}.height"))?;
    slope(f.slope, || format!("{path}.slope"))?;
    let point_path = |i: usize| format!("{path}.points[{i}]");
    match f.kind {
        FigureKind::Point => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() != 1 {
                return Err(ValidationError::new(
                    format!("{path}.points"),
                    FigureDefect::PointCount(f.points.len()),
                ));
            }
        }
        FigureKind::Polyline => {
            points(grid, &f.points, &point_path)?;
            if f.points.len() < 2 {
                let defect = FigureDefect::PolylineTooShort(f.points.len());
                return Err(ValidationError::new(format!("{path}.points"), defect));
            }
        }
        FigureKind::Closed => ring(grid, &f.points, point_path, &format!("{path}.points"))?,
    }
    let mut scratch = Vec::new();
    for (i, &p) in f.points.iter().enumerate() {
        match edge.bands.locate(p) {
            Side::Inside => {}
            Side::On => {
                return Err(ValidationError::new(
                    point_path(i),
                    FigureDefect::OnRegionEdge(edge.path.into()),
                ));
            }
            Side::Outside => {
                return Err(ValidationError::new(
                    point_path(i),
                    FigureDefect::OutsideRegion(edge.path.into()),
                ));
            }
        }
        if i > 0 && edge.segments.touches(f.points[i - 1], p, &mut scratch) {
            return Err(ValidationError::new(
                point_path(i),
                FigureDefect::CrossesRegionEdge(edge.path.into()),
            ));
        }
    }
    if !f.figures.is_empty() {
        if f.kind != FigureKind::Closed {
            return Err(ValidationError::new(
                format!("{path}.figures"),
                FigureDefect::NestedInOpenFigure(f.kind.name()),
            ));
        }
        figures(grid, &f.figures, &f.points, &format!("{path}.points"), path, depth + 1)?;
    }
    Ok(())
}
