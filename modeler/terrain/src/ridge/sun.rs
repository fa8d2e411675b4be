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

/// Calls `f(cell index, horizon tangent)` for every cell, for azimuth `azimuth` (radians); the
/// tangent is `-∞` where nothing lies ahead.
pub fn horizons(field: Field<'_>, azimuth: f64, mut f: impl FnMut(usize, f64)) {
    let Field { z, cols, rows, cell } = field;
    let (dx, dy) = (azimuth.cos(), azimuth.sin());
    // Swap axes so that the sweep's dominant axis is "u" (cells along it: nu), the other "v".
    let x_major = dx.abs() >= dy.abs();
    let (nu, nv, du, dv) = if x_major {
        (cols, rows, dx, dy)
    } else {
        (rows, cols, dy, dx)
    };
    // A step ahead (u += sign du) moves v by dv/|du|: line b is v = b + u·dv/du.
    let mut slope = dv / du;
    // cos 45° and sin 45° differ in the last bit: snap the diagonals and axes so that their
    // lines run exactly through the cell centres.
    for exact in [-1.0, 0.0, 1.0] {
        if (slope - exact).abs() < 1e-12 {
            slope = exact;
        }
    }
    let spacing = (1.0 + slope * slope).sqrt() * cell * du.signum();
    let index = |u: u32, v: u32| {
        if x_major {
            v as usize * cols as usize + u as usize
        } else {
            u as usize * cols as usize + v as usize
        }
    };
    let (lo, hi) = (f64::from(nu - 1) * slope.min(0.0), f64::from(nu - 1) * slope.max(0.0));
    let ahead_up = du > 0.0;
    // Per cell, the weighted sum of its two neighbouring lines' horizons, and the weights.
    let mut sum = vec![0.0f32; z.len()];
    let mut weight = vec![0.0f32; z.len()];
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(nu as usize);
    let nvf = f64::from(nv);
    for b in (-hi.ceil() as i64 - 1)..(nv as i64 - lo.floor() as i64 + 1) {
        hull.clear();
        // From the far end back: the sweep's first samples are the farthest ahead.
        for k in 0..nu {
            let u = if ahead_up { nu - 1 - k } else { k };
            let v = b as f64 + f64::from(u) * slope;
            if v < 0.0 || v > nvf - 1.0 {
                continue;
            }
            let v0 = v.floor();
            let frac = v - v0;
            let v0 = v0 as u32;
            let v1 = (v0 + 1).min(nv - 1);
            let (i0, i1) = (index(u, v0), index(u, v1));
            let h = f64::from(z[i0]) * (1.0 - frac) + f64::from(z[i1]) * frac;
            let s = f64::from(u) * spacing;
            // Pop the nearest hull point while it lies on or under the line to the next one.
            while hull.len() >= 2 {
                let (s1, h1) = hull[hull.len() - 1];
                let (s2, h2) = hull[hull.len() - 2];
                if (h1 - h) * (s2 - s) <= (h2 - h) * (s1 - s) {
                    hull.pop();
                } else {
                    break;
                }
            }
            if let Some(&(s1, h1)) = hull.last() {
                let t = ((h1 - h) / (s1 - s)) as f32;
                let w0 = (1.0 - frac) as f32;
                sum[i0] += w0 * t;
                weight[i0] += w0;
                if frac > 0.0 {
                    sum[i1] += frac as f32 * t;
                    weight[i1] += frac as f32;
                }
            }
            hull.push((s, h));
        }
    }
    for (i, (&s, &w)) in sum.iter().zip(&weight).enumerate() {
        f(i, if w > 0.0 { f64::from(s / w) } else { f64::NEG_INFINITY });
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

/// Azimuths summed together on one thread; fixed so that the sum's order, and so its bits, do
/// not depend on the number of threads.
const GROUP: usize = 8;

/// The sky-view fraction per cell from `k` azimuths (`2πi/k`): `1 − (1/k)·Σ sin² H_i`.
pub fn sky_view(field: Field<'_>, k: u32) -> Vec<f32> {
    let n = field.z.len();
    let k = k.max(1) as usize;
    let groups: Vec<Vec<f32>> = (0..k.div_ceil(GROUP))
        .into_par_iter()
        .map(|g| {
            let mut acc = vec![0.0f32; n];
            for d in g * GROUP..((g + 1) * GROUP).min(k) {
                let az = TAU * d as f64 / k as f64;
                horizons(field, az, |i, t| {
                    let m = t.max(0.0);
                    acc[i] += (m * m / (1.0 + m * m)) as f32;
                });
            }
            acc
        })
        .collect();
    let inv = 1.0 / k as f32;
    let mut out = vec![0.0f32; n];
    out.par_chunks_mut(4096).enumerate().for_each(|(j, chunk)| {
        for (o, i) in chunk.iter_mut().zip(j * 4096..) {
            let mut s = 0.0f32;
            for g in &groups {
                s += g[i];
            }
            *o = 1.0 - s * inv;
        }
    });
    out
}

/// `(1 − f)·direct + f·sky` with `f` = [`DIFFUSE`].
pub fn insolation(direct: &[f32], sky: &[f32]) -> Vec<f32> {
    let f = DIFFUSE as f32;
    direct.iter().zip(sky).map(|(&d, &s)| (1.0 - f) * d + f * s).collect()
}
