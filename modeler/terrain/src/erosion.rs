//! Thermal erosion (issue 20): a short pass that lets material slide down where the ground is
//! steeper than its talus angle, applied to the regions' terrain after the fractal detail
//! ([`crate::detail`]) and before the ridges join it and the rivers carve it.
//!
//! Each of `iterations` steps moves, between every cell `i` and each of its 8 neighbours `j`,
//!
//! `flow_ij = k · sign(d) · max(0, |d| − T_ij)`, `d = h_j − h_i`, `k = amount / 8`,
//!
//! into `i` (out of `j`), where `T_ij = tan(talus) · distance(i, j)` (a cell or √2 cells): the
//! height difference the talus allows. All cells move at once from the last step's heights
//! (Jacobi, not one cell after the other), so a step is a pure function of each cell's 3 × 3
//! neighbourhood and the result depends on no order of visits. What one cell gives, its neighbour
//! takes: the pass conserves material (cells beyond the grid take no part). With `k ≤ 1/8` a step
//! is monotone — a higher neighbour never lowers a cell — so it never overshoots into
//! oscillation, and differences between two terrains never grow.
//!
//! **Incremental.** A step reads a cell's neighbours, so `n` steps make a cell's height a
//! function of the terrain before erosion within `n` cells of it (Chebyshev distance): after a
//! change of the terrain before erosion in a rectangle, only that rectangle grown by `n` cells
//! changes, and it is recomputed from the rectangle grown by `2n` ([`Layer::apply`]): the margin's
//! cells miss neighbours outside the window and go wrong, one ring a step, never reaching the
//! cells written. A full rebuild is the same computation over the whole grid, so an update equals
//! it to the bit. The steps run in `f64` and the result is rounded to `f32` once.
//!
//! A figure's cells erode like any other: a peak steeper than the talus is lowered, so a pulled
//! figure stands a little below the pen where its ground is steep. Non-finite heights neither
//! give nor take.

use rayon::prelude::*;

use crate::document::{Erosion, Grid};
use crate::heightmap::Heightmap;
use crate::rect::Rect;

/// The 8 neighbours, in the fixed order every cell sums them in: `(dc, dr, diagonal)`.
const NEIGHBOURS: [(i64, i64, bool); 8] = [
    (-1, -1, true),
    (0, -1, false),
    (1, -1, true),
    (-1, 0, false),
    (1, 0, false),
    (-1, 1, true),
    (0, 1, false),
    (1, 1, true),
];

/// The erosion of a document's terrain: its settings and the terrain before erosion.
pub struct Layer {
    settings: Erosion,
    /// The regions' terrain (with detail) before erosion.
    pub(crate) before: Heightmap,
}

impl Layer {
    /// The layer for `settings` on `grid`, with no terrain yet.
    pub fn new(grid: &Grid, settings: Erosion) -> Layer {
        Layer {
            settings,
            before: Heightmap::new(grid),
        }
    }

    /// The settings this layer was made for.
    pub fn settings(&self) -> &Erosion {
        &self.settings
    }

    /// Writes the eroded terrain into `out` over `rect` grown by the iterations (clamped to the
    /// grid), from the terrain before erosion; returns the rectangle written.
    pub fn apply(&self, rect: Rect, out: &mut Heightmap) -> Rect {
        let (cols, rows) = (self.before.cols(), self.before.rows());
        if rect.width == 0 || rect.height == 0 || cols == 0 || rows == 0 {
            return Rect::EMPTY;
        }
        let n = self.settings.iterations;
        let write = grown(rect, n, cols, rows);
        let read = grown(rect, n.saturating_mul(2), cols, rows);
        let eroded = erode(&self.settings, &self.before, read);
        let w = cols as usize;
        let dst = out.heights_mut();
        for r in write.r0..write.r0 + write.height {
            let from = (r - read.r0) as usize * read.width as usize + (write.c0 - read.c0) as usize;
            let to = r as usize * w + write.c0 as usize;
            dst[to..to + write.width as usize].copy_from_slice(&eroded[from..from + write.width as usize]);
        }
        write
    }
}

/// `rect` grown by `n` cells on every side, clamped to the `cols × rows` grid.
fn grown(rect: Rect, n: u32, cols: u32, rows: u32) -> Rect {
    let c0 = rect.c0.saturating_sub(n);
    let r0 = rect.r0.saturating_sub(n);
    let c1 = (rect.c0 + rect.width).saturating_add(n).min(cols);
    let r1 = (rect.r0 + rect.height).saturating_add(n).min(rows);
    Rect {
        c0,
        r0,
        width: c1 - c0,
        height: r1 - r0,
    }
}

/// The heights of `map` in `window` after the erosion's steps, computed inside the window alone
/// (row-major over the window): exact in the window shrunk by the steps, except along the grid's
/// edges, where it is exact up to the edge.
pub fn erode(settings: &Erosion, map: &Heightmap, window: Rect) -> Vec<f32> {
    let (cols, rows) = (i64::from(map.cols()), i64::from(map.rows()));
    let (ww, wh) = (window.width as usize, window.height as usize);
    let h = map.heights();
    let mut a: Vec<f64> = Vec::with_capacity(ww * wh);
    for r in window.r0..window.r0 + window.height {
        let start = r as usize * cols as usize + window.c0 as usize;
        a.extend(h[start..start + ww].iter().map(|&v| f64::from(v)));
    }
    let mut b = a.clone();
    let slope = settings.talus.to_radians().tan();
    let (orth, diag) = (
        slope * map.cell_size(),
        slope * map.cell_size() * std::f64::consts::SQRT_2,
    );
    let k = settings.amount / 8.0;
    let (wc0, wr0) = (i64::from(window.c0), i64::from(window.r0));
    for _ in 0..settings.iterations {
        b.par_chunks_mut(ww.max(1)).enumerate().for_each(|(y, line)| {
            let r = wr0 + y as i64;
            for (x, o) in line.iter_mut().enumerate() {
                let c = wc0 + x as i64;
                let here = a[y * ww + x];
                if !here.is_finite() {
                    *o = here;
                    continue;
                }
                let mut flow = 0.0;
                for &(dc, dr, diagonal) in &NEIGHBOURS {
                    let (nc, nr) = (c + dc, r + dr);
                    // Beyond the grid: no neighbour. Beyond the window: the margin, whose cells
                    // are not written.
                    if nc < 0 || nr < 0 || nc >= cols || nr >= rows {
                        continue;
                    }
                    let (xi, yi) = (nc - wc0, nr - wr0);
                    if xi < 0 || yi < 0 || xi >= ww as i64 || yi >= wh as i64 {
                        continue;
                    }
                    let there = a[yi as usize * ww + xi as usize];
                    if !there.is_finite() {
                        continue;
                    }
                    let d = there - here;
                    let t = if diagonal { diag } else { orth };
                    if d > t {
                        flow += d - t;
                    } else if d < -t {
                        flow += d + t;
                    }
                }
                *o = here + k * flow;
            }
        });
        std::mem::swap(&mut a, &mut b);
    }
    a.into_iter().map(|v| v as f32).collect()
}
