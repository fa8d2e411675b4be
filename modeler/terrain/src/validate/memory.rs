//! The terrain engine's memory: an estimate from the document alone, checked before anything
//! allocates it.

use super::{BYTES_PER_FIGURE_CELL, BYTES_PER_REGION_CELL, Defect, MAX_ENGINE_BYTES, ValidationError};
use crate::cells;
use crate::document::{Document, Figure, FigureKind, Grid, Point};

/// The terrain engine's memory for `doc`, in bytes, an upper bound on what it keeps and
/// allocates while building and updating: per region (top-level, and the nested region of each
/// closed figure) its bounding box's cells × ([`BYTES_PER_FIGURE_CELL`] × its figures +
/// [`BYTES_PER_REGION_CELL`]), plus 4 bytes per grid cell for the heightmap. Returns the
/// estimate, the number of figures and the summed box cells. Linear in the document's points.
pub fn engine_bytes(doc: &Document) -> (u64, u64, u64) {
    fn box_cells(grid: &Grid, pts: &[Point]) -> u64 {
        // A closed curve's cells span exactly the cells of its extreme points (each segment's
        // walk stays between its end cells), so the box needs no rasterising.
        let Some(&first) = pts.first() else { return 0 };
        let (mut lo, mut hi) = (cells::point_cell(grid, first), cells::point_cell(grid, first));
        for &p in pts {
            let (c, r) = cells::point_cell(grid, p);
            lo = (lo.0.min(c), lo.1.min(r));
            hi = (hi.0.max(c), hi.1.max(r));
        }
        u64::from(hi.0 - lo.0 + 1) * u64::from(hi.1 - lo.1 + 1)
    }
    fn region(grid: &Grid, edge: &[Point], figs: &[Figure], acc: &mut (u64, u64, u64)) {
        let cells = box_cells(grid, edge);
        let n = figs.len() as u64;
        acc.0 = acc
            .0
            .saturating_add(cells.saturating_mul(BYTES_PER_FIGURE_CELL * n + BYTES_PER_REGION_CELL));
        acc.1 += n;
        acc.2 = acc.2.saturating_add(cells);
        for f in figs.iter().filter(|f| f.kind == FigureKind::Closed) {
            region(grid, &f.points, &f.figures, acc);
        }
    }
    // The heightmap, and with detail its noise, gates and the terrain before it; with erosion
    // the terrain before it and two f64 windows as large as the grid (a full rebuild's); with
    // fluvial erosion its model and its output.
    let fluvial = doc.terrain.erosion.is_some_and(|e| e.fluvial.is_some());
    let per_cell = if doc.terrain.detail.is_some() { 16 } else { 4 }
        + if doc.terrain.erosion.is_some() { 20 } else { 0 }
        + if fluvial {
            crate::fluvial::BYTES_PER_CELL as u64 + 4
        } else {
            0
        };
    let mut acc = (per_cell * doc.grid.cells() as u64, 0, 0);
    for r in &doc.regions {
        region(&doc.grid, &r.boundary, &r.figures, &mut acc);
    }
    acc
}

/// Checks that the terrain engine's memory for `doc` ([`engine_bytes`]) is within
/// [`MAX_ENGINE_BYTES`], before anything allocates it.
pub fn memory(doc: &Document) -> Result<(), ValidationError> {
    let (bytes, figures, cells) = engine_bytes(doc);
    if bytes > MAX_ENGINE_BYTES {
        return Err(ValidationError::new(
            "regions",
            Defect::TooLarge {
                bytes,
                figures,
                cells,
                max: MAX_ENGINE_BYTES,
            },
        ));
    }
    Ok(())
}
