//! Rasterisation of figures and regions onto the grid.
//!
//! - A **point** is the cell containing it: `(⌊x/s⌋, ⌊y/s⌋)` in double precision, clamped to the grid.
//! - A **segment** is every cell it passes through, 4-connected (a supercover walk that steps
//!   along x or y one cell at a time). Cells are half-open, so a point on a grid line belongs to
//!   the cell on its right (below). Where a segment passes exactly through a grid corner with x
//!   and y both increasing (or both decreasing), the cells before and after the corner touch only
//!   diagonally; the walk then adds the corner's column, row below: moving right it steps along x
//!   first, moving left along y first. With x increasing and y decreasing (or the reverse) the
//!   half-open rule already gives the corner cell. Either way the cells of a segment do not
//!   depend on the direction it is drawn in.
//! - A **polyline** is the union of its segments.
//! - A **closed curve** (and a region's boundary) is its boundary cells plus every cell whose
//!   centre lies inside the polygon (even-odd rule, scanned row by row at the centres' y).
//!
//! The result of a closed curve is a [`Mask`] bounded by its cells' bounding box; every
//! per-region array in the engine is laid out over that box.

use crate::document::{Figure, FigureKind, Grid, Point};

/// A grid cell `(column, row)`.
pub type Cell = (u32, u32);

/// A set of cells stored as flags over its bounding box.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mask {
    /// First column of the box.
    pub c0: u32,
    /// First row of the box.
    pub r0: u32,
    /// Columns in the box.
    pub width: u32,
    /// Rows in the box.
    pub height: u32,
    bits: Vec<bool>,
}

impl Mask {
    /// An empty box-sized mask.
    pub fn empty(c0: u32, r0: u32, width: u32, height: u32) -> Mask {
        Mask {
            c0,
            r0,
            width,
            height,
            bits: vec![false; width as usize * height as usize],
        }
    }

    /// The smallest mask holding `cells` (none: an empty 0 × 0 mask).
    pub fn from_cells(cells: &[Cell]) -> Mask {
        let Some(&(c, r)) = cells.first() else {
            return Mask::empty(0, 0, 0, 0);
        };
        let (mut cmin, mut cmax, mut rmin, mut rmax) = (c, c, r, r);
        for &(c, r) in cells {
            cmin = cmin.min(c);
            cmax = cmax.max(c);
            rmin = rmin.min(r);
            rmax = rmax.max(r);
        }
        let mut m = Mask::empty(cmin, rmin, cmax - cmin + 1, rmax - rmin + 1);
        for &cell in cells {
            m.insert(cell);
        }
        m
    }

    /// Number of cells in the box (set or not).
    pub fn box_len(&self) -> usize {
        self.bits.len()
    }

    /// The flags over the box, row-major.
    pub fn bits(&self) -> &[bool] {
        &self.bits
    }

    /// The box index of `cell`, if it lies in the box.
    pub fn index(&self, (c, r): Cell) -> Option<usize> {
        let (lc, lr) = (c.checked_sub(self.c0)?, r.checked_sub(self.r0)?);
        (lc < self.width && lr < self.height).then(|| lr as usize * self.width as usize + lc as usize)
    }

    /// The cell at box index `i`.
    pub fn cell(&self, i: usize) -> Cell {
        let w = self.width as usize;
        (self.c0 + (i % w) as u32, self.r0 + (i / w) as u32)
    }

    /// Whether `cell` is in the set.
    pub fn contains(&self, cell: Cell) -> bool {
        self.index(cell).is_some_and(|i| self.bits[i])
    }

    /// Adds `cell`, which must lie in the box.
    fn insert(&mut self, cell: Cell) {
        if let Some(i) = self.index(cell) {
            self.bits[i] = true;
        }
    }

    /// Number of cells in the set.
    pub fn len(&self) -> usize {
        self.bits.iter().filter(|&&b| b).count()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        !self.bits.iter().any(|&b| b)
    }

    /// The cells in the set, row by row.
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        self.bits
            .iter()
            .enumerate()
            .filter(|(_, b)| **b)
            .map(|(i, _)| self.cell(i))
    }

    /// This set without the cells that are not in `other` (same box).
    pub fn intersect(mut self, other: &Mask) -> Mask {
        for i in 0..self.bits.len() {
            if self.bits[i] && !other.contains(self.cell(i)) {
                self.bits[i] = false;
            }
        }
        self
    }

    /// The first cell (row by row) in both sets.
    pub fn first_common(&self, other: &Mask) -> Option<Cell> {
        let c0 = self.c0.max(other.c0);
        let r0 = self.r0.max(other.r0);
        let c1 = (self.c0 + self.width).min(other.c0 + other.width);
        let r1 = (self.r0 + self.height).min(other.r0 + other.height);
        (r0..r1)
            .flat_map(|r| (c0..c1).map(move |c| (c, r)))
            .find(|&cell| self.contains(cell) && other.contains(cell))
    }
}

/// The position of `p` in cell units (x/s, y/s).
fn to_cells(grid: &Grid, p: Point) -> [f64; 2] {
    [p[0] / grid.cell_size, p[1] / grid.cell_size]
}

fn clamp_cell(v: f64, n: u32) -> u32 {
    // `as` saturates (NaN to 0), so out-of-grid input clamps instead of wrapping.
    (v.floor().max(0.0) as u32).min(n.saturating_sub(1))
}

/// The cell containing `p`.
pub fn point_cell(grid: &Grid, p: Point) -> Cell {
    let [u, v] = to_cells(grid, p);
    (clamp_cell(u, grid.cols), clamp_cell(v, grid.rows))
}

/// Appends the cells of the segment `a b` to `out`, in walking order from `a`'s cell to `b`'s.
pub fn segment_cells(grid: &Grid, a: Point, b: Point, out: &mut Vec<Cell>) {
    let [ua, va] = to_cells(grid, a);
    let [ub, vb] = to_cells(grid, b);
    let (mut c, mut r) = point_cell(grid, a);
    let (ce, re) = point_cell(grid, b);
    let sx: i64 = if ce > c { 1 } else { -1 };
    let sy: i64 = if re > r { 1 } else { -1 };
    let (du, dv) = ((ub - ua).abs(), (vb - va).abs());
    out.push((c, r));
    // Exactly |Δc| + |Δr| steps, each toward the end cell, so the walk always ends there.
    while (c, r) != (ce, re) {
        let step_x = if c == ce {
            false
        } else if r == re {
            true
        } else {
            // Distance to the next vertical and horizontal grid lines, compared as the segment
            // parameters ax/du and ay/dv without dividing.
            let ax = if sx > 0 {
                f64::from(c + 1) - ua
            } else {
                ua - f64::from(c)
            };
            let ay = if sy > 0 {
                f64::from(r + 1) - va
            } else {
                va - f64::from(r)
            };
            let (tx, ty) = (ax * dv, ay * du);
            if tx != ty { tx < ty } else { sx > 0 }
        };
        if step_x {
            c = (i64::from(c) + sx) as u32;
        } else {
            r = (i64::from(r) + sy) as u32;
        }
        out.push((c, r));
    }
}

/// The cells of the polyline through `points` (consecutive repeats removed).
pub fn polyline_cells(grid: &Grid, points: &[Point]) -> Vec<Cell> {
    let mut out = Vec::new();
    match points {
        [] => {}
        [p] => out.push(point_cell(grid, *p)),
        _ => {
            for s in points.windows(2) {
                segment_cells(grid, s[0], s[1], &mut out);
            }
        }
    }
    out.dedup();
    out
}

/// The cells of the closed curve `ring` (last point equal to the first): its boundary cells and
/// every cell whose centre lies inside.
pub fn closed_mask(grid: &Grid, ring: &[Point]) -> Mask {
    let boundary = polyline_cells(grid, ring);
    let mut mask = Mask::from_cells(&boundary);
    let pts: Vec<[f64; 2]> = ring.iter().map(|&p| to_cells(grid, p)).collect();
    let mut xs = Vec::new();
    for lr in 0..mask.height {
        let yc = f64::from(mask.r0 + lr) + 0.5;
        xs.clear();
        for e in pts.windows(2) {
            let (a, b) = (e[0], e[1]);
            if (a[1] <= yc) != (b[1] <= yc) {
                xs.push(a[0] + (yc - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
            }
        }
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            // Centres c + 0.5 within [x_in, x_out]; a centre exactly on the curve is a boundary
            // cell anyway.
            let first = (pair[0] - 0.5).ceil().max(f64::from(mask.c0));
            let last = (pair[1] - 0.5).floor().min(f64::from(mask.c0 + mask.width) - 1.0);
            // The columns first..=last, all in the box: one fill of the row's flags.
            if first <= last {
                let row = lr as usize * mask.width as usize;
                let (a, b) = ((first as u32 - mask.c0) as usize, (last as u32 - mask.c0) as usize);
                mask.bits[row + a..=row + b].fill(true);
            }
        }
    }
    mask
}

/// The cells a figure stands on: its cell, its polyline's cells, or its closed curve's cells.
pub fn figure_cells(grid: &Grid, figure: &Figure) -> Vec<Cell> {
    match figure.kind {
        FigureKind::Point | FigureKind::Polyline => polyline_cells(grid, &figure.points),
        FigureKind::Closed => closed_mask(grid, &figure.points).cells().collect(),
    }
}
