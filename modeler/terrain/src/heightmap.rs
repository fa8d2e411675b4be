//! The generated heightfield.

use crate::document::Grid;

/// Heights in metres over the document's grid, row-major: the height of cell `(c, r)` is at
/// index `r·cols + c`.
#[derive(Debug, Clone, PartialEq)]
pub struct Heightmap {
    cols: u32,
    rows: u32,
    cell_size: f64,
    heights: Vec<f32>,
}

impl Heightmap {
    /// A flat heightmap (all 0) over `grid`.
    pub fn new(grid: &Grid) -> Heightmap {
        Heightmap {
            cols: grid.cols,
            rows: grid.rows,
            cell_size: grid.cell_size,
            heights: vec![0.0; grid.cells()],
        }
    }

    /// A heightmap from its heights (`cols × rows` of them, row-major), or `None` if the count is wrong.
    pub fn from_heights(cols: u32, rows: u32, cell_size: f64, heights: Vec<f32>) -> Option<Heightmap> {
        (heights.len() == cols as usize * rows as usize).then_some(Heightmap {
            cols,
            rows,
            cell_size,
            heights,
        })
    }

    /// Columns: cells along x.
    pub fn cols(&self) -> u32 {
        self.cols
    }

    /// Rows: cells along y.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// Cell size in metres.
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// The ground a change of cells `(c0, r0, width, height)` covers, metres `[x0, y0, x1, y1]`:
    /// the cells' extent, without end where it reaches the grid's edge (the terrain's surface is
    /// held at the outer cells' heights beyond it, so a change there reaches out without end).
    /// What reads the heights around a point still has to widen it by a cell.
    pub fn extent_of(&self, (c0, r0, w, h): (u32, u32, u32, u32)) -> [f64; 4] {
        let s = self.cell_size;
        let end = |first: u32, n: u32, all: u32, lower: bool| match (lower, first, first + n >= all) {
            (true, 0, _) => f64::NEG_INFINITY,
            (true, f, _) => f64::from(f) * s,
            (false, _, true) => f64::INFINITY,
            (false, f, false) => f64::from(f + n) * s,
        };
        [
            end(c0, w, self.cols, true),
            end(r0, h, self.rows, true),
            end(c0, w, self.cols, false),
            end(r0, h, self.rows, false),
        ]
    }

    /// The height of cell `(c, r)`.
    ///
    /// # Panics
    /// If the cell is off the grid.
    pub fn get(&self, c: u32, r: u32) -> f32 {
        assert!(
            c < self.cols && r < self.rows,
            "cell ({c}, {r}) is off the {}×{} grid",
            self.cols,
            self.rows
        );
        self.heights[r as usize * self.cols as usize + c as usize]
    }

    /// All heights, row-major.
    pub fn heights(&self) -> &[f32] {
        &self.heights
    }

    pub(crate) fn heights_mut(&mut self) -> &mut [f32] {
        &mut self.heights
    }

    /// The lowest and highest height.
    pub fn range(&self) -> (f32, f32) {
        self.heights
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }
}
