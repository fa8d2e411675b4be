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

use rayon::prelude::*;

use super::RidgeError;
use super::gradient::sobel;
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
pub fn horizons(field: Field<'_>, azimuth: f64, mut f: impl FnMut(usize, f64)) {
    let Field { z, cols, rows, cell } = field;
    let n = z.len();
    let (mut sum, mut weight) = (vec![0.0f32; n], vec![0.0f32; n]);
    let (dx, dy) = (azimuth.cos(), azimuth.sin());
    let x_major = dx.abs() >= dy.abs();
    let mut sink = |line: &Line, k: usize, t: Option<f32>| {
        if let Some(t) = t {
            line.spread(k, t, &mut sum, &mut weight);
        }
    };
    if x_major {
        sweep(z, cols, rows, cell, (dx, dy), false, &mut sink);
    } else {
        let zt = transpose(z, cols, rows);
        sweep(&zt, rows, cols, cell, (dy, dx), false, &mut sink);
    }
    if !x_major {
        // Back to the grid's layout: the transposed grid is rows wide.
        sum = transpose(&sum, rows, cols);
        weight = transpose(&weight, rows, cols);
    }
    for (i, (&s, &w)) in sum.iter().zip(&weight).enumerate() {
        f(i, if w > 0.0 { f64::from(s / w) } else { f64::NEG_INFINITY });
    }
}

/// One section's samples, in increasing u from `u0`: the lower cell's index, the interpolation
/// weight of the cell one row further, and the interpolated height; sample k lies `(u0 + k)·spacing`
/// along the line.
#[derive(Default)]
struct Line {
    i0: Vec<u32>,
    frac: Vec<f32>,
    h: Vec<f32>,
    u0: f32,
    spacing: f32,
    /// Grid columns (the row stride of `i0`).
    stride: usize,
}

impl Line {
    /// Adds `value` to sample k's two cells, weighted by nearness, and the weights.
    #[inline]
    fn spread(&self, k: usize, value: f32, sum: &mut [f32], weight: &mut [f32]) {
        let (i0, frac) = (self.i0[k] as usize, self.frac[k]);
        let w0 = 1.0 - frac;
        sum[i0] += w0 * value;
        weight[i0] += w0;
        if frac > 0.0 {
            sum[i0 + self.stride] += frac * value;
            weight[i0 + self.stride] += frac;
        }
    }
}

/// The upper hull of the samples passed so far, nearest vertex last.
///
/// The nearest vertex is kept in registers and the others in two `f32` stacks. Why: the pop
/// test reads the vertex pushed one sample earlier; stored as a `(f32, f32)` pair it was written
/// as two 4-byte stores and read back as one 8- or 16-byte load, which the CPU cannot forward
/// from the store buffer, a stall of a dozen cycles on every sample (`perf` put most of the
/// sweep there). Same-width stores and loads forward.
#[derive(Default)]
struct Hull {
    s: Vec<f32>,
    h: Vec<f32>,
}

/// The upper-hull pass over a line's samples in the order `order`, the first ones the farthest
/// ahead: calls `sink(line, k, tangent)` for each sample (`None` when nothing is ahead).
/// `sign` is 1 when ahead is increasing u, −1 when decreasing, so that positions grow ahead.
#[inline]
fn hull_pass(
    line: &Line,
    hull: &mut Hull,
    sign: f32,
    order: impl Iterator<Item = usize>,
    sink: &mut impl FnMut(&Line, usize, Option<f32>),
) {
    hull.s.clear();
    hull.h.clear();
    // The nearest hull vertex, once there is one.
    let mut near: Option<(f32, f32)> = None;
    for k in order {
        let (s, h) = (sign * (line.u0 + k as f32) * line.spacing, line.h[k]);
        let t = near.map(|(mut s1, mut h1)| {
            // Pop the nearest vertex while it lies on or under the line to the next one.
            while let (Some(&s2), Some(&h2)) = (hull.s.last(), hull.h.last()) {
                if (h1 - h) * (s2 - s) <= (h2 - h) * (s1 - s) {
                    (s1, h1) = (s2, h2);
                    hull.s.pop();
                    hull.h.pop();
                } else {
                    break;
                }
            }
            hull.s.push(s1);
            hull.h.push(h1);
            (h1 - h) / (s1 - s)
        });
        sink(line, k, t);
        near = Some((s, h));
    }
}

/// `z` (`cols × rows`, row-major) transposed: `rows × cols`. In tiles, so that both the reads
/// and the writes stay within a few cache lines and pages (a plain column walk misses the cache
/// on every cell of a large grid).
fn transpose(z: &[f32], cols: u32, rows: u32) -> Vec<f32> {
    const TILE: usize = 64;
    let (w, h) = (cols as usize, rows as usize);
    let mut t = vec![0.0f32; z.len()];
    // Each task writes TILE rows of the result (TILE columns of `z`).
    t.par_chunks_mut(h * TILE).enumerate().for_each(|(tc, out)| {
        let c0 = tc * TILE;
        let nc = out.len() / h;
        for r0 in (0..h).step_by(TILE) {
            for c in c0..c0 + nc {
                let dst = &mut out[(c - c0) * h..(c - c0 + 1) * h];
                for r in r0..(r0 + TILE).min(h) {
                    dst[r] = z[r * w + c];
                }
            }
        }
    });
    t
}

/// The horizon sweep for a direction `(du, dv)` with `|du| ≥ |dv|`, u along the columns of the
/// `cols × rows` grid `z`: every line's samples through `sink`, and with `both` again for the
/// opposite direction (the same lines swept the other way).
fn sweep(
    z: &[f32],
    cols: u32,
    rows: u32,
    cell: f64,
    (du, dv): (f64, f64),
    both: bool,
    sink: &mut impl FnMut(&Line, usize, Option<f32>),
) {
    let (nu, nv) = (cols, rows);
    // A step ahead (u += sign du) moves v by dv/|du|: line b is v = b + u·dv/du.
    let mut slope = dv / du;
    // cos 45° and sin 45° differ in the last bit: snap the diagonals and axes so that their
    // lines run exactly through the cell centres.
    for exact in [-1.0, 0.0, 1.0] {
        if (slope - exact).abs() < 1e-12 {
            slope = exact;
        }
    }
    let spacing = ((1.0 + slope * slope).sqrt() * cell) as f32;
    let w = cols as usize;
    let (lo, hi) = (f64::from(nu - 1) * slope.min(0.0), f64::from(nu - 1) * slope.max(0.0));
    let ahead_up = du > 0.0;
    let mut hull = Hull {
        s: Vec::with_capacity(nu as usize),
        h: Vec::with_capacity(nu as usize),
    };
    let mut line = Line {
        stride: w,
        spacing,
        ..Line::default()
    };
    let nvf = f64::from(nv);
    let last_u = i64::from(nu) - 1;
    for b in (-hi.ceil() as i64 - 1)..(i64::from(nv) - lo.floor() as i64 + 1) {
        // The columns where the line is on the grid (a column wider each way; checked below).
        let (ua, ub) = if slope == 0.0 {
            (0, last_u)
        } else {
            let (a, c) = ((-(b as f64)) / slope, (nvf - 1.0 - b as f64) / slope);
            let (a, c) = (a.min(c), a.max(c));
            ((a.floor() as i64 - 1).max(0), (c.ceil() as i64 + 1).min(last_u))
        };
        line.i0.clear();
        line.frac.clear();
        line.h.clear();
        // The samples on the grid are consecutive in u.
        let mut first = None;
        for u in ua..=ub {
            let v = b as f64 + u as f64 * slope;
            if v < 0.0 || v > nvf - 1.0 {
                if first.is_some() {
                    break;
                }
                continue;
            }
            first.get_or_insert(u);
            // v ≥ 0: truncation is the floor.
            let v0 = v as usize;
            let frac = (v - v0 as f64) as f32;
            let i0 = v0 * w + u as usize;
            let h = if frac > 0.0 {
                z[i0] * (1.0 - frac) + z[i0 + w] * frac
            } else {
                z[i0]
            };
            line.i0.push(i0 as u32);
            line.frac.push(frac);
            line.h.push(h);
        }
        line.u0 = first.unwrap_or(0) as f32;
        let n = line.h.len();
        if n == 0 {
            continue;
        }
        // From the far end back: the first samples swept are the farthest ahead.
        if ahead_up || both {
            hull_pass(&line, &mut hull, 1.0, (0..n).rev(), sink);
        }
        if !ahead_up || both {
            hull_pass(&line, &mut hull, -1.0, 0..n, sink);
        }
    }
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

/// A hillshade: Lambert's `max(0, n·s)` per cell with no shadows, the map that shows a
/// heightfield's shape (its creases, steps and cones) most plainly.
pub fn hillshade(field: Field<'_>, sun: Sun) -> Vec<f32> {
    let (ce, se) = (sun.elevation.cos(), sun.elevation.sin());
    let s = [ce * sun.azimuth.cos(), ce * sun.azimuth.sin(), se];
    let cols = field.cols as usize;
    (0..field.z.len())
        .map(|i| lambert(field, (i % cols) as u32, (i / cols) as u32, s) as f32)
        .collect()
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
    out.par_chunks_mut(field.cols as usize)
        .zip(lit.par_chunks(field.cols as usize))
        .enumerate()
        .for_each(|(r, (line, lit))| {
            for (c, (o, &l)) in line.iter_mut().zip(lit).enumerate() {
                if l {
                    *o = lambert(field, c as u32, r as u32, s) as f32;
                }
            }
        });
    out
}

/// Azimuth pairs summed together on one thread; fixed so that the sum's order, and so its bits,
/// do not depend on the number of threads.
const GROUP: usize = 8;

/// The sky-view fraction per cell from `k` azimuths (`2πi/k`): `1 − (1/k)·Σ sin² H_i`.
///
/// Each line sample's `sin² H` is spread over its two cells like a horizon (see [`horizons`]),
/// with the weights summed alongside: the mean over all directions is the weighted mean (every
/// cell gets weight 1 per azimuth but at the grid's edge). Opposite azimuths share their lines
/// and are swept together.
pub fn sky_view(field: Field<'_>, k: u32) -> Vec<f32> {
    let Field { z, cols, rows, cell } = field;
    let n = z.len();
    let k = k.max(1) as usize;
    let zt = transpose(z, cols, rows);
    // Azimuth d with its opposite d + k/2 when k is even.
    let pairs: Vec<(usize, Option<usize>)> = if k.is_multiple_of(2) {
        (0..k / 2).map(|d| (d, Some(d + k / 2))).collect()
    } else {
        (0..k).map(|d| (d, None)).collect()
    };
    // Per group: sums and weights in the grid's layout and in the transposed one.
    let groups: Vec<[Vec<f32>; 4]> = pairs
        .par_chunks(GROUP)
        .map(|chunk| {
            let [mut acc, mut wt, mut acc_t, mut wt_t] = [(); 4].map(|_| vec![0.0f32; n]);
            for &(d, opposite) in chunk {
                let az = TAU * d as f64 / k as f64;
                let (dx, dy) = (az.cos(), az.sin());
                let (grid, sum, weight) = if dx.abs() >= dy.abs() {
                    (z, &mut acc, &mut wt)
                } else {
                    (&zt[..], &mut acc_t, &mut wt_t)
                };
                let (c, r, dir) = if dx.abs() >= dy.abs() {
                    (cols, rows, (dx, dy))
                } else {
                    (rows, cols, (dy, dx))
                };
                let mut add = |line: &Line, j: usize, t: Option<f32>| {
                    let m = t.unwrap_or(0.0).max(0.0);
                    line.spread(j, m * m / (1.0 + m * m), sum, weight);
                };
                sweep(grid, c, r, cell, dir, opposite.is_some(), &mut add);
            }
            [acc, wt, acc_t, wt_t]
        })
        .collect();
    // The groups' sums in a fixed order, the transposed ones brought back to the grid's layout.
    let mut total = [(); 4].map(|_| vec![0.0f32; n]);
    for g in &groups {
        for (t, a) in total.iter_mut().zip(g) {
            t.par_iter_mut().zip(a.par_iter()).for_each(|(t, a)| *t += a);
        }
    }
    let [acc, wt, acc_t, wt_t] = total;
    let (acc_t, wt_t) = (transpose(&acc_t, rows, cols), transpose(&wt_t, rows, cols));
    acc.par_iter()
        .zip(wt.par_iter())
        .zip(acc_t.par_iter().zip(wt_t.par_iter()))
        .map(|((&a, &w), (&at, &wt))| {
            let (s, ws) = (a + at, w + wt);
            if ws > 0.0 { 1.0 - s / ws } else { 1.0 }
        })
        .collect()
}

/// `(1 − f)·direct + f·sky` with `f` = [`DIFFUSE`].
pub fn insolation(direct: &[f32], sky: &[f32]) -> Vec<f32> {
    let f = DIFFUSE as f32;
    direct.iter().zip(sky).map(|(&d, &s)| (1.0 - f) * d + f * s).collect()
}
