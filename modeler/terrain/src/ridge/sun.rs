//! Insolation (seed 002 §3.2): direct sunlight by a horizon test times Lambert's law, and the
//! sky's diffuse light by horizons in k azimuths, each found by a sweep along parallel sections
//! of the grid in O(cells) (Alg. 3.1) instead of rendering the terrain from m points of the sky
//! dome (O(m·n²)).
//!
//! **Sections.** For an azimuth φ (from +x towards +y), the grid is cut into parallel straight
//! lines in direction φ, one cell apart across the dominant axis of (cos φ, sin φ); each line is
//! sampled once per cell along that axis, the height interpolated linearly between the two cells
//! it passes between. [`horizons`] sweeps each line from its far end back, keeping the upper
//! convex hull of the samples passed (those *ahead*); the hull's first vertex gives the current
//! sample's horizon — the largest tangent `(z_q − z_p)/|q − p|` over the samples q ahead — and
//! samples under the hull are popped for good: O(1) amortised per sample. A cell's horizon is
//! the mean of its two neighbouring lines' horizons there, weighted by nearness (along the axes
//! and diagonals the lines run through the cell centres, and it is exactly the walk from cell to
//! cell). [`ray_march`] is the brute force along the exact ray from the cell, for comparison.
//!
//! - **Direct** ([`direct`]): a cell is lit when the sun's elevation is above its horizon in the
//!   sun's azimuth; lit, it gets `max(0, n·s)` (n the Sobel surface normal, s the unit vector to
//!   the sun); in shadow exactly 0.
//! - **Sky** ([`sky_view`]): the fraction of an isotropic sky's light a horizontal surface receives
//!   with the horizons `H_i` in k evenly spaced azimuths: `1 − (1/k)·Σ sin² H_i` (the cosine-
//!   weighted view factor; a horizon below 0 counts as 0). 1 on open ground.
//! - **Insolation** ([`insolation`]): `(1 − f)·direct + f·sky` with the diffuse fraction f
//!   ([`DIFFUSE`], 0.2: a clear sky's share).

use std::f64::consts::TAU;
use std::ops::Range;

use rayon::prelude::*;

use super::RidgeError;
use super::gradient::sobel;
use super::packed::Packed;
use super::scratch;
use super::sections::{Sections, transpose};
use super::walk::{LANES, OFF_GRID, Walk};
use crate::Heightmap;

/// The diffuse share of clear-sky light used by [`insolation`].
pub const DIFFUSE: f64 = 0.2;

/// A sun position: azimuth from +x towards +y and elevation above the horizon, radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    /// Azimuth, radians.
    pub azimuth: f64,
    /// Elevation, radians, in (0, π/2].
    pub elevation: f64,
}

impl Sun {
    /// A sun from degrees, refused below (or on) the horizon; `what` names it in the message.
    pub fn degrees(azimuth: f64, elevation: f64, what: &str) -> Result<Sun, RidgeError> {
        if !azimuth.is_finite() {
            return Err(RidgeError::NotFinite {
                what: format!("{what} azimuth"),
            });
        }
        if !(elevation.is_finite() && elevation > 0.0 && elevation <= 90.0) {
            return Err(RidgeError::SunBelowHorizon {
                what: what.to_string(),
                degrees: elevation,
            });
        }
        Ok(Sun {
            azimuth: azimuth.to_radians(),
            elevation: elevation.to_radians(),
        })
    }
}

/// A heightfield to light: `cols × rows` row-major heights of `cell` metres.
#[derive(Debug, Clone, Copy)]
pub struct Field<'a> {
    /// Heights, metres.
    pub z: &'a [f32],
    /// Columns.
    pub cols: u32,
    /// Rows.
    pub rows: u32,
    /// Cell size, metres.
    pub cell: f64,
}

impl<'a> Field<'a> {
    /// The terrain of `map`.
    pub fn of(map: &'a Heightmap) -> Field<'a> {
        Field {
            z: map.heights(),
            cols: map.cols(),
            rows: map.rows(),
            cell: map.cell_size(),
        }
    }
}

/// Calls `f(cell index, horizon tangent)` for every cell, for azimuth `azimuth` (radians); the
/// tangent is `-∞` where nothing lies ahead.
///
/// On all cores like [`sky_view`]'s sweeps: blocks of lines walked into their own parts of a
/// buffer, then the columns spread from the blocks in block order. A cell gets two terms (its
/// two lines), so the sums do not depend on the order either way.
pub fn horizons(field: Field<'_>, azimuth: f64, mut f: impl FnMut(usize, f64)) {
    let Field { z, cols, rows, cell } = field;
    let (cols, rows) = (cols as usize, rows as usize);
    if z.is_empty() {
        return;
    }
    let (dx, dy) = (azimuth.cos(), azimuth.sin());
    let x_major = dx.abs() >= dy.abs();
    // The layout (u along its w rows, v across its h) with u's columns contiguous, an element
    // more (see `Sections::block_heights`): the grid transposed when u runs along the grid's
    // rows.
    let (zc, w, h, du, dv) = if x_major {
        (transpose(z, cols, rows, 1), cols, rows, dx, dy)
    } else {
        let mut zp = scratch::zeros(z.len() + 1);
        zp[..z.len()].copy_from_slice(z);
        (zp, rows, cols, dy, dx)
    };
    let lines = Sections::new(w, h, slope(du, dv), cell);
    let packed = Packed::new(&lines, BLOCK);
    let mut values = scratch::zeros(0);
    // Per cell the sum of its lines' tangents and of their weights, columns contiguous.
    let (mut sum, mut weight) = (scratch::zeros(w * h), scratch::zeros(w * h));
    for pass in packed.passes(pass_budget(w * h)) {
        packed
            .split(pass.clone(), &mut values)
            .into_par_iter()
            .for_each_init(Scratch::default, |buf, (k, block)| {
                let (b0, cols) = packed.block(k);
                horizon_block(&zc, &lines, du > 0.0, (b0, cols), block, buf);
            });
        let span = packed.columns(pass.clone());
        let values = &values[..];
        sum[span.start * h..span.end * h]
            .par_chunks_mut(h * SPREAD_COLUMNS)
            .zip(weight[span.start * h..span.end * h].par_chunks_mut(h * SPREAD_COLUMNS))
            .enumerate()
            .for_each(|(piece, (sums, weights))| {
                for (i, (col, wcol)) in sums.chunks_exact_mut(h).zip(weights.chunks_exact_mut(h)).enumerate() {
                    let u = span.start + piece * SPREAD_COLUMNS + i;
                    packed.at_column(&lines, pass.clone(), values, u, |b0, src| {
                        lines.column_spread_weighted(u, b0, src, col, wcol)
                    });
                }
            });
    }
    if x_major {
        // Back to the grid's layout: u ran along the grid's rows.
        let (s, w) = (transpose(&sum, rows, cols, 0), transpose(&weight, rows, cols, 0));
        scratch::give([std::mem::replace(&mut sum, s), std::mem::replace(&mut weight, w)]);
    }
    for (i, (&s, &w)) in sum.iter().zip(&weight).enumerate() {
        f(i, if w > 0.0 { f64::from(s / w) } else { f64::NEG_INFINITY });
    }
    scratch::give([zc, values, sum, weight]);
}

/// The lines `b0..b0 + BLOCK` of `lines` as one block (`block`, laid out like
/// [`Sections::block_heights`]'s): their heights, then in their place each sample's horizon
/// tangent towards u's sign `up` (NaN with nothing ahead), walked side by side ([`Walk`]).
fn horizon_block(
    zc: &[f32],
    lines: &Sections,
    up: bool,
    (b0, cols): (isize, Range<usize>),
    block: &mut [f32],
    buf: &mut Scratch,
) {
    let Scratch { heights, walk } = buf;
    let Some((z, out)) = block_samples(zc, lines, (b0, cols), block, heights) else {
        return;
    };
    if up {
        walk.horizons::<true>(z, lines.spacing, out);
    } else {
        walk.horizons::<false>(z, lines.spacing, out);
    }
}

/// The slope `dv/du` of a direction with `|du| ≥ |dv|`, the axes and diagonals exact: cos 45°
/// and sin 45° differ in the last bit, and their lines should run through the cell centres.
fn slope(du: f64, dv: f64) -> f64 {
    let t = dv / du;
    [-1.0, 0.0, 1.0]
        .into_iter()
        .find(|e: &f64| (t - e).abs() < 1e-12)
        .unwrap_or(t)
}

/// The brute-force horizon of cell `(c, r)` in azimuth `azimuth`: the largest tangent to the
/// terrain (bilinearly interpolated) sampled every cell along the exact ray to the grid's edge.
/// O(n) per cell; the reference [`horizons`] is compared with.
pub fn ray_march(field: Field<'_>, azimuth: f64, c: u32, r: u32) -> f64 {
    let Field { z, cols, rows, cell } = field;
    let (dx, dy) = (azimuth.cos(), azimuth.sin());
    let h0 = f64::from(z[r as usize * cols as usize + c as usize]);
    let mut best = f64::NEG_INFINITY;
    let mut t = 1.0;
    loop {
        let (x, y) = (f64::from(c) + t * dx, f64::from(r) + t * dy);
        if x < 0.0 || y < 0.0 || x > f64::from(cols - 1) || y > f64::from(rows - 1) {
            return best;
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as usize, y0 as usize);
        let (x1, y1) = ((x0 + 1).min(cols as usize - 1), (y0 + 1).min(rows as usize - 1));
        let at = |xx: usize, yy: usize| f64::from(z[yy * cols as usize + xx]);
        let h =
            (at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx) * (1.0 - fy) + (at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx) * fy;
        best = best.max((h - h0) / (t * cell));
        t += 1.0;
    }
}

/// Lambert's `max(0, n·s)` at cell `(c, r)` for the unit vector `s` to the sun.
fn lambert(field: Field<'_>, c: u32, r: u32, s: [f64; 3]) -> f64 {
    let [gx, gy] = sobel(field.z, field.cols, field.rows, field.cell, c, r);
    let n = 1.0 / (gx * gx + gy * gy + 1.0).sqrt();
    ((-gx * s[0] - gy * s[1] + s[2]) * n).max(0.0)
}

/// Lambert's `max(0, n·s)` of row r into `out`, where `lit` (when given) says so, 0 elsewhere:
/// [`lambert`] cell by cell, its operations in the same order, the inner columns as one loop over
/// three rows (vectorised) and the two edge columns (clamped neighbours) as single cells.
fn lambert_row(field: Field<'_>, r: u32, s: [f64; 3], lit: Option<&[bool]>, out: &mut [f32]) {
    let (cols, rows) = (field.cols as usize, field.rows);
    let at = |r: u32| &field.z[r as usize * cols..(r as usize + 1) * cols];
    let (above, row, below) = (at(r.saturating_sub(1)), at(r), at((r + 1).min(rows - 1)));
    let k = 1.0 / (8.0 * field.cell);
    let shade = |gx: f64, gy: f64| {
        let n = 1.0 / (gx * gx + gy * gy + 1.0).sqrt();
        ((-gx * s[0] - gy * s[1] + s[2]) * n).max(0.0)
    };
    if cols >= 3 {
        let m = cols - 2;
        for (i, o) in out[1..=m].iter_mut().enumerate() {
            let (cm, c, cp) = (i, i + 1, i + 2);
            let f = |v: &[f32], j: usize| f64::from(v[j]);
            let gx =
                (f(above, cp) + 2.0 * f(row, cp) + f(below, cp)) - (f(above, cm) + 2.0 * f(row, cm) + f(below, cm));
            let gy =
                (f(below, cm) + 2.0 * f(below, c) + f(below, cp)) - (f(above, cm) + 2.0 * f(above, c) + f(above, cp));
            let v = shade(gx * k, gy * k) as f32;
            *o = if lit.is_none_or(|l| l[c]) { v } else { 0.0 };
        }
    }
    for c in [0, cols - 1] {
        let v = lambert(field, c as u32, r, s) as f32;
        out[c] = if lit.is_none_or(|l| l[c]) { v } else { 0.0 };
    }
}

/// A hillshade: Lambert's `max(0, n·s)` per cell with no shadows, the map that shows a
/// heightfield's shape (its creases, steps and cones) most plainly.
pub fn hillshade(field: Field<'_>, sun: Sun) -> Vec<f32> {
    let (ce, se) = (sun.elevation.cos(), sun.elevation.sin());
    let s = [ce * sun.azimuth.cos(), ce * sun.azimuth.sin(), se];
    let mut out = vec![0.0f32; field.z.len()];
    out.par_chunks_mut(field.cols.max(1) as usize)
        .enumerate()
        .for_each(|(r, line)| lambert_row(field, r as u32, s, None, line));
    out
}

/// Direct sunlight per cell: Lambert where the sun is above the cell's horizon, exactly 0 in
/// shadow.
pub fn direct(field: Field<'_>, sun: Sun) -> Vec<f32> {
    let mut lit = vec![false; field.z.len()];
    let tan = sun.elevation.tan();
    horizons(field, sun.azimuth, |i, t| lit[i] = tan > t);
    let (ce, se) = (sun.elevation.cos(), sun.elevation.sin());
    let s = [ce * sun.azimuth.cos(), ce * sun.azimuth.sin(), se];
    let mut out = vec![0.0f32; field.z.len()];
    let cols = field.cols.max(1) as usize;
    out.par_chunks_mut(cols)
        .zip(lit.par_chunks(cols))
        .enumerate()
        .for_each(|(r, (line, lit))| lambert_row(field, r as u32, s, Some(lit), line));
    out
}

/// One layout's share of the sky view (u along its `w` rows, v across its `h`): per cell the sum
/// of the spread `sin² H`, stored `sum[u·h + v]` (columns contiguous), and the weights of the
/// first and last v and of every other (see `Sections::weight`).
struct Layout {
    /// The layout's row length and rows.
    w: usize,
    h: usize,
    sum: Vec<f32>,
    first: Vec<f32>,
    last: Vec<f32>,
    inner: f32,
}

impl Layout {
    fn new(w: usize, h: usize) -> Layout {
        Layout {
            w,
            h,
            sum: scratch::zeros(w * h),
            first: vec![0.0; w],
            last: vec![0.0; w],
            inner: 0.0,
        }
    }

    /// The weights of the cells of row v, or `None` for `inner`.
    fn weights(&self, r: usize, h: usize) -> Option<&[f32]> {
        if r == 0 {
            Some(&self.first)
        } else if r + 1 == h {
            Some(&self.last)
        } else {
            None
        }
    }
}

/// Lines swept as one block: their heights and values laid out column by column, so that
/// building and spreading them are shifted interpolations of contiguous cells and their walks
/// run side by side ([`Walk`]). A block is also the unit of work the cores share.
const BLOCK: usize = LANES;

/// Columns of a layout spread as one piece of work.
const SPREAD_COLUMNS: usize = 16;

/// Adds the sky view's `sin² H` of the direction `(du, dv)` (`|du| ≥ |dv|`, u along the rows of
/// `layout`), and with `both` of the opposite direction, to `layout`. `zc` is the grid with u's
/// columns contiguous (the layout transposed), an element more. `values` is scratch.
///
/// On all cores in two passes: the blocks of lines, each swept into its own part of `values`,
/// then the columns of `layout`, each adding the blocks' values in block order — so that every
/// cell's sum is added in the same order however the work is shared.
fn sky_sweep(zc: &[f32], cell: f64, (du, dv): (f64, f64), both: bool, layout: &mut Layout, values: &mut Vec<f32>) {
    let (w, h) = (layout.w, layout.h);
    let lines = Sections::new(w, h, slope(du, dv), cell);
    let packed = Packed::new(&lines, BLOCK);
    for pass in packed.passes(pass_budget(w * h)) {
        packed
            .split(pass.clone(), values)
            .into_par_iter()
            .for_each_init(Scratch::default, |buf, (k, block)| {
                let (b0, cols) = packed.block(k);
                sweep_block(zc, &lines, (du, both), (b0, cols), block, buf);
            });
        let span = packed.columns(pass.clone());
        let values = &values[..];
        layout.sum[span.start * h..span.end * h]
            .par_chunks_mut(h * SPREAD_COLUMNS)
            .enumerate()
            .for_each(|(piece, cols)| {
                for (i, col) in cols.chunks_exact_mut(h).enumerate() {
                    let u = span.start + piece * SPREAD_COLUMNS + i;
                    packed.at_column(&lines, pass.clone(), values, u, |b0, src| {
                        lines.column_spread(u, b0, src, col)
                    });
                }
            });
    }
    let passes = if both { 2.0 } else { 1.0 };
    for u in 0..w {
        layout.first[u] += passes * lines.weight(u, 0);
        layout.last[u] += passes * lines.weight(u, h - 1);
    }
    layout.inner += passes;
}

/// The lines `b0..b0 + BLOCK` of `lines` as one block (`block`, laid out like
/// [`Sections::block_heights`]'s, [`OFF_GRID`] where a line is off the grid): their heights,
/// then in their place the `sin² H` of each sample (towards `du`'s sign, and with `both` the
/// opposite way added).
fn sweep_block(
    zc: &[f32],
    lines: &Sections,
    (du, both): (f64, bool),
    (b0, cols): (isize, Range<usize>),
    block: &mut [f32],
    buf: &mut Scratch,
) {
    let sp2 = lines.spacing * lines.spacing;
    let Scratch { heights, walk } = buf;
    let Some((z, out)) = block_samples(zc, lines, (b0, cols), block, heights) else {
        return;
    };
    match (du > 0.0 || both, du < 0.0 || both) {
        (true, true) => {
            walk.sky::<true, false>(z, sp2, out);
            walk.sky::<false, true>(z, sp2, out);
        }
        (true, false) => walk.sky::<true, false>(z, sp2, out),
        _ => walk.sky::<false, false>(z, sp2, out),
    }
}

/// The heights of the lines `b0..b0 + BLOCK` into `heights` ([`OFF_GRID`] where a line is
/// off the grid) over `cols`, the columns where any of them is on it ([`Packed`]'s block, laid
/// out like `block`): the heights and `block`, or `None` when the lines miss the grid.
fn block_samples<'a>(
    zc: &[f32],
    lines: &Sections,
    (b0, cols): (isize, Range<usize>),
    block: &'a mut [f32],
    heights: &'a mut Vec<f32>,
) -> Option<(&'a [f32], &'a mut [f32])> {
    if cols.is_empty() {
        return None;
    }
    heights.clear();
    heights.resize(block.len(), OFF_GRID);
    lines.block_heights(zc, b0, BLOCK, cols.start, heights);
    Some((&heights[..], block))
}

/// The values a pass of blocks may hold for a grid of `cells`: twice the grid (an ordinary
/// grid's lines fit in one pass, as before), and never so little that a pass is a few blocks.
fn pass_budget(cells: usize) -> usize {
    (2 * cells).max(1 << 20)
}

/// Buffers reused from block to block: the block's heights and its walks.
#[derive(Default)]
struct Scratch {
    heights: Vec<f32>,
    walk: Walk,
}

/// The sky-view fraction per cell from `k` azimuths (`2πi/k`): `1 − (1/k)·Σ sin² H_i`.
///
/// Each line sample's `sin² H` is spread over its two cells like a horizon (see [`horizons`]):
/// the mean over all directions is the weighted mean, every cell getting weight 1 per azimuth
/// but on the grid's edge rows across a direction's lines, where the weights are known in closed
/// form (`Sections::weight`). Opposite azimuths share their lines and are swept together. The
/// azimuths are swept one after another, each on all cores (`sky_sweep`); the result does not
/// depend on the number of threads.
pub fn sky_view(field: Field<'_>, k: u32) -> Vec<f32> {
    let Field { z, cols, rows, cell } = field;
    let (cols, rows) = (cols as usize, rows as usize);
    if z.is_empty() {
        return Vec::new();
    }
    let k = k.max(1) as usize;
    // The grid and its transpose, each an element more (see `Sections::block_heights`).
    let mut zp = scratch::zeros(z.len() + 1);
    zp[..z.len()].copy_from_slice(z);
    let zt = transpose(z, cols, rows, 1);
    // Azimuth d with its opposite d + k/2 when k is even.
    let pairs: Vec<(usize, bool)> = if k.is_multiple_of(2) {
        (0..k / 2).map(|d| (d, true)).collect()
    } else {
        (0..k).map(|d| (d, false)).collect()
    };
    // The row-major azimuths' layout (u along the grid's rows, sums transposed) and the
    // column-major ones' (u down the columns, sums in the grid's layout).
    let (mut x, mut y) = (Layout::new(cols, rows), Layout::new(rows, cols));
    let mut values = scratch::zeros(0);
    for (d, both) in pairs {
        let az = TAU * d as f64 / k as f64;
        let (dx, dy) = (az.cos(), az.sin());
        if dx.abs() >= dy.abs() {
            sky_sweep(&zt, cell, (dx, dy), both, &mut x, &mut values);
        } else {
            sky_sweep(&zp, cell, (dy, dx), both, &mut y, &mut values);
        }
    }
    let along = transpose(&x.sum, rows, cols, 0);
    let mut out = vec![0.0f32; z.len()];
    out.par_chunks_mut(cols).enumerate().for_each(|(r, line)| {
        let (a, at) = (&along[r * cols..(r + 1) * cols], &y.sum[r * cols..(r + 1) * cols]);
        let wx = x.weights(r, rows);
        for (c, o) in line.iter_mut().enumerate() {
            // Cell (c, r) is (u, v) = (r, c) for the column-major azimuths.
            let wy = y.weights(c, cols).map_or(y.inner, |w| w[r]);
            let ws = wx.map_or(x.inner, |w| w[c]) + wy;
            *o = if ws > 0.0 { 1.0 - (a[c] + at[c]) / ws } else { 1.0 };
        }
    });
    scratch::give([zp, zt, x.sum, y.sum, values, along]);
    out
}

/// `(1 − f)·direct + f·sky` with `f` = [`DIFFUSE`].
pub fn insolation(direct: &[f32], sky: &[f32]) -> Vec<f32> {
    let f = DIFFUSE as f32;
    direct.iter().zip(sky).map(|(&d, &s)| (1.0 - f) * d + f * s).collect()
}
