//! Reprojection: an eye's picture drawn from one pose moved, by its depth, to a newer pose
//! (issue 16's latency; VR runtimes call it timewarp).
//!
//! The tracked view takes most of a frame to draw (17–25 ms at 640 × 360 on two cores), while
//! a seated viewer's head moves a few millimetres in that time. So a frame latched to the head
//! draws its view from the pose predicted for the frame's end *before* it waits for the head's
//! newest pose, holding each eye's picture and depth ([`Held`]); once the pose comes, each
//! eye's picture is moved to where the new eye sees it ([`warp`]) — a pass over the pixels, not
//! a draw. What is shown is then from the newest pose; only the content (the pen's newest
//! edits) is from when the view was drawn.
//!
//! **The maths.** An eye's [`Projection`] is a 3 × 4 matrix `P = [M | t]` taking a world point
//! `p` to `(X, Y, w) = M·p + t`, its pixel `(X/w, Y/w)`. A pixel `(x, y)` with depth `1/w` is
//! the world point `p = M⁻¹·((x·w, y·w, w) − t)`, which the new eye's `P' = [M' | t']` sees at
//! `(X', Y', w') = K·(x, y, 1)·w + c` with `K = M'·M⁻¹` and `c = t' − K·t`. Divided by `w`:
//! `(X', Y', w')/w = K·(x, y, 1) + c·(1/w)` — three dot products per pixel, and the sky
//! (`1/w = 0`, a direction) moves by `K` alone, as a point at infinity does.
//!
//! **The warp is a gather.** Each output pixel looks for the source pixel that lands on it: it
//! starts from the pixel at its own place and steps by the difference between where that pixel
//! lands and where it should ([`ITERATIONS`] times at most; the motion is smooth but for depth
//! edges, and a few pixels at most). A gather leaves no holes; at a depth edge the pixels the
//! new pose uncovers take a neighbour's colour, as every reprojection must (the new pose sees
//! what the old one did not). The identity motion gives back the picture to the byte.

use rayon::prelude::*;

use crate::output::frame::Rgba;
use crate::raster::camera::Projection;
use crate::raster::rasterise::Bounds;

/// Steps an output pixel takes towards its source pixel. The source pixel's motion differs from
/// its neighbours' only at depth edges: one step lands within a pixel elsewhere, a second
/// settles the rounding, a third a pixel that crossed an edge.
pub(crate) const ITERATIONS: usize = 3;

/// One eye's picture as drawn, for [`warp`]: pixels and depth over the frame (only `bounds`,
/// the eye's viewport, is the eye's), and the projection it was drawn with.
#[derive(Debug, Clone)]
pub(crate) struct Held {
    /// The frame's pixels, row-major, `width` per row.
    pub pixels: Vec<Rgba>,
    /// `1/w` per pixel (0: nothing drawn, the sky or the table's backdrop).
    pub invw: Vec<f32>,
    /// Pixels per row.
    pub width: usize,
    /// The eye's viewport.
    pub bounds: Bounds,
    /// The projection the eye was drawn with.
    pub projection: Projection,
}

/// What the pixels that show no surface show, which decides how they move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Background {
    /// A picture fixed to the screen (the classic look's sky gradient): its pixels stay where
    /// they are. In a tracked view every point of the screen's plane does, and it is at depth
    /// `w` = the eye's distance from the screen: this is its `1/w`.
    Screen(f32),
    /// The land look's world ([`crate::shade::atmosphere`]): below the horizon a level plane at this
    /// world height (the table and the land beyond it), above it the sky, at infinity.
    Level(f32),
}

/// The depth `1/w` of each pixel of an eye drawn with `projection` into a frame `width` wide:
/// the surface's where a sample has one (`samples`, row-major), else the background's.
pub(crate) fn depths(
    samples: impl Iterator<Item = f32>,
    projection: &Projection,
    background: Background,
    width: usize,
    out: &mut Vec<f32>,
) {
    out.clear();
    match background {
        Background::Screen(invw) => out.extend(samples.map(|s| if s > 0.0 { s } else { invw })),
        Background::Level(height) => {
            // The ray through pixel (x, y) is w·u + e with u = M⁻¹·(x, y, 1) and e = −M⁻¹·t
            // (the eye): it meets the level at w = (height − e_y) / u_y, ahead when positive.
            let (m, t) = projection.parts();
            let Some(inverse) = (m.determinant() != 0.0).then(|| m.inverse()) else {
                out.extend(samples.map(|s| s.max(0.0)));
                return;
            };
            let eye_y = -(inverse * t).y;
            // u_y is affine in the pixel: a step per column.
            let (uy0, uyx, uyy) = (inverse.row(1).z, inverse.row(1).x, inverse.row(1).y);
            let above = f64::from(height) - eye_y;
            out.extend(samples.enumerate().map(|(i, s)| {
                if s > 0.0 {
                    return s;
                }
                let (x, y) = ((i % width) as f64 + 0.5, (i / width) as f64 + 0.5);
                let uy = uy0 + uyx * x + uyy * y;
                // 1/w = u_y / (height − e_y): positive only when the plane is ahead.
                let invw = uy / above;
                if invw > 0.0 && invw.is_finite() {
                    invw as f32
                } else {
                    0.0
                }
            }));
        }
    }
}

/// The map from a held eye's pixels to another projection's: `(x', y')` from `(x, y, 1/w)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Motion {
    /// `K = M'·M⁻¹`, rows.
    k: [[f32; 3]; 3],
    /// `c = t' − K·t`.
    c: [f32; 3],
}

impl Motion {
    /// The motion from `from`'s pixels to `to`'s; `None` when `from` is degenerate (its 3 × 3
    /// part not invertible).
    pub(crate) fn between(from: &Projection, to: &Projection) -> Option<Motion> {
        let ((from_m, from_t), (to_m, to_t)) = (from.parts(), to.parts());
        if from_m.determinant() == 0.0 {
            return None;
        }
        let k = to_m * from_m.inverse();
        let c = to_t - k * from_t;
        if !(k.is_finite() && c.is_finite()) {
            return None;
        }
        // Rows of `k` (glam's matrices are stored by columns).
        let kt = k.transpose();
        let row = |v: glam::DVec3| [v.x as f32, v.y as f32, v.z as f32];
        Some(Motion {
            k: [row(kt.x_axis), row(kt.y_axis), row(kt.z_axis)],
            c: row(c),
        })
    }

    /// Where the pixel at `(x, y)` (its centre) with depth `invw` lands; `None` at or behind
    /// the new eye (the tests' reference).
    #[cfg(test)]
    pub fn apply(&self, x: f32, y: f32, invw: f32) -> Option<(f32, f32)> {
        let (lx, ly, ahead) = self.lands(x, y, invw);
        ahead.then_some((lx, ly))
    }

    /// Where the pixel lands, without a branch: the position, and whether it is ahead of the
    /// new eye (the position is meaningless where not).
    #[inline(always)]
    fn lands(&self, x: f32, y: f32, invw: f32) -> (f32, f32, bool) {
        let dot = |r: &[f32; 3], c: f32| r[0] * x + r[1] * y + r[2] + c * invw;
        let w = dot(&self.k[2], self.c[2]);
        let r = 1.0 / w;
        (dot(&self.k[0], self.c[0]) * r, dot(&self.k[1], self.c[1]) * r, w > 0.0)
    }
}

/// Writes `held`'s eye, moved by `motion`, over its viewport of `out` (a frame `held.width`
/// wide): each pixel the source pixel that lands on it (see the module's notes).
pub(crate) fn warp(held: &Held, motion: &Motion, out: &mut [Rgba]) {
    let Bounds { x0, x1, y0, y1 } = held.bounds;
    let width = held.width;
    if x1 <= x0 || y1 <= y0 || width == 0 {
        return;
    }
    out.par_chunks_mut(width)
        .enumerate()
        .skip(y0 as usize)
        .take((y1 - y0) as usize)
        .for_each(|(y, row)| crate::simd::dispatch!(warp_row, (held, motion, y, row)));
}

/// Pixels whose first step [`warp_row`] takes together.
const LANES: usize = 16;

/// Row `y` of [`warp`]. Every pixel's first step starts from its own place, whose depth is in a
/// row: those steps are taken [`LANES`] at a time, without branches (the compiler vectorises
/// them). A pixel that moves less than half a pixel stays where it is — most of them, for a
/// frame's residual motion — and the others go on one at a time.
#[inline(always)]
fn warp_row(held: &Held, motion: &Motion, y: usize, row: &mut [Rgba]) {
    let Bounds { x0, x1, y0, y1 } = held.bounds;
    let width = held.width;
    // The pixel a position falls in, within the viewport. A cast truncates towards zero, which
    // is the floor for the positions at or above 0 and clamps the same below (`x0`, `y0` ≥ 0),
    // in one instruction where `floor` is a call without SSE4.1 (a quarter of the warp's time).
    let clamp_x = |v: f32| (v as i32).clamp(x0, x1 - 1);
    let clamp_y = |v: f32| (v as i32).clamp(y0, y1 - 1);
    let ty = y as f32 + 0.5;
    let depths = &held.invw[y * width..y * width + width];
    let mut x = x0;
    while x < x1 {
        let n = ((x1 - x) as usize).min(LANES);
        let mut invw = [0.0f32; LANES];
        invw[..n].copy_from_slice(&depths[x as usize..x as usize + n]);
        let (mut vx, mut vy, mut stay) = ([0.0f32; LANES], [0.0f32; LANES], [false; LANES]);
        for k in 0..LANES {
            let tx = (x + k as i32) as f32 + 0.5;
            // Where the pixel at its own place lands; the source that would land here if the
            // motion were the same there (`v`). Behind the new eye, or `v` within the pixel
            // itself: the pixel stays. Tested on the floats, as `floor(v)` = the pixel: a cast
            // to an integer saturates, which keeps the loop from vectorising.
            let (lx, ly, ahead) = motion.lands(tx, ty, invw[k]);
            vx[k] = tx + tx - lx;
            vy[k] = ty + ty - ly;
            let (px, py) = (tx - 0.5, ty - 0.5);
            stay[k] = !ahead || (vx[k] >= px && vx[k] < px + 1.0 && vy[k] >= py && vy[k] < py + 1.0);
        }
        for k in 0..n {
            let own = (x + k as i32, y as i32);
            let (sx, sy) = if stay[k] {
                own
            } else {
                match (clamp_x(vx[k]), clamp_y(vy[k])) {
                    first if first == own => own,
                    first => settle(held, motion, first, (own.0 as f32 + 0.5, ty), (clamp_x, clamp_y)),
                }
            };
            row[own.0 as usize] = held.pixels[sy as usize * width + sx as usize];
        }
        x += n as i32;
    }
}

/// The steps after the first of a pixel whose centre is `(tx, ty)`, from the source pixel
/// `(sx, sy)` the first step found.
#[inline(always)]
fn settle(
    held: &Held,
    motion: &Motion,
    (mut sx, mut sy): (i32, i32),
    (tx, ty): (f32, f32),
    (clamp_x, clamp_y): (impl Fn(f32) -> i32, impl Fn(f32) -> i32),
) -> (i32, i32) {
    for _ in 1..ITERATIONS {
        let (cx, cy) = (sx as f32 + 0.5, sy as f32 + 0.5);
        let (lx, ly, ahead) = motion.lands(cx, cy, held.invw[sy as usize * held.width + sx as usize]);
        if !ahead {
            break;
        }
        let (nx, ny) = (clamp_x(cx + tx - lx), clamp_y(cy + ty - ly));
        if (nx, ny) == (sx, sy) {
            break;
        }
        (sx, sy) = (nx, ny);
    }
    (sx, sy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raster::camera::{Camera, Eye, Tracked, View, Viewport};

    fn projection(head: [f64; 3]) -> Projection {
        let camera = Camera {
            view: View::Tracked(Tracked {
                head,
                ..Tracked::fit([0.6, 0.34], [100.0, 60.0], 0.45)
            }),
            tilt: 0.2,
        };
        let vp = camera.viewpoint(Eye::Left, 16.0 / 9.0);
        Projection::new(
            &vp,
            camera.tilt,
            Viewport {
                x: 0.0,
                y: 0.0,
                width: 64.0,
                height: 36.0,
            },
        )
    }

    #[test]
    fn a_motion_moves_world_points_as_the_projections_do() {
        let (a, b) = (projection([0.0, -0.25, 0.45]), projection([0.012, -0.241, 0.437]));
        let motion = Motion::between(&a, &b).expect("invertible");
        for p in [
            glam::DVec3::new(3.0, 1.5, -7.0),
            glam::DVec3::new(-20.0, 0.0, 12.0),
            glam::DVec3::new(40.0, 9.0, 25.0),
        ] {
            let [x, y, w] = a.pixel(p).expect("in front");
            let [x2, y2, _] = b.pixel(p).expect("in front");
            let (mx, my) = motion.apply(x as f32, y as f32, (1.0 / w) as f32).expect("in front");
            assert!(
                (f64::from(mx) - x2).abs() < 1e-3 && (f64::from(my) - y2).abs() < 1e-3,
                "{p}: {mx},{my} vs {x2},{y2}"
            );
        }
        // The sky: a direction moves by K alone, as a point far along it does.
        let far = a.eye + (glam::DVec3::new(3.0, 1.5, -7.0) - a.eye) * 1e7;
        let [x, y, _] = a.pixel(far).expect("in front");
        let [x2, y2, _] = b.pixel(far).expect("in front");
        let (mx, my) = motion.apply(x as f32, y as f32, 0.0).expect("in front");
        assert!((f64::from(mx) - x2).abs() < 1e-2 && (f64::from(my) - y2).abs() < 1e-2);
    }

    #[test]
    fn the_identity_gives_the_picture_back() {
        let a = projection([0.0, -0.25, 0.45]);
        let motion = Motion::between(&a, &a).expect("invertible");
        let (width, height) = (64usize, 36usize);
        let held = Held {
            pixels: (0..width * height).map(|i| (i as u32).to_le_bytes()).collect(),
            invw: (0..width * height)
                .map(|i| if i % 7 == 0 { 0.0 } else { 0.01 + (i % 13) as f32 * 1e-3 })
                .collect(),
            width,
            bounds: Bounds {
                x0: 0,
                x1: width as i32,
                y0: 0,
                y1: height as i32,
            },
            projection: a,
        };
        let mut out = vec![[0; 4]; width * height];
        warp(&held, &motion, &mut out);
        assert_eq!(out, held.pixels);
    }

    #[test]
    fn a_flat_picture_shifts_by_its_motion() {
        // Every pixel at one depth: the picture moves by whole pixels where the motion does.
        let a = projection([0.0, -0.25, 0.45]);
        let (width, height) = (64usize, 36usize);
        let bounds = Bounds {
            x0: 0,
            x1: width as i32,
            y0: 0,
            y1: height as i32,
        };
        let held = Held {
            pixels: (0..width * height).map(|i| (i as u32).to_le_bytes()).collect(),
            invw: vec![0.02; width * height],
            width,
            bounds,
            projection: a,
        };
        // A motion that moves every pixel by (+3, −2).
        let shift = Motion {
            k: [[1.0, 0.0, 3.0], [0.0, 1.0, -2.0], [0.0, 0.0, 1.0]],
            c: [0.0; 3],
        };
        let mut out = vec![[0; 4]; width * height];
        warp(&held, &shift, &mut out);
        for y in 0..height {
            for x in 0..width {
                // The source pixel (x − 3, y + 2), clamped at the edges the shift uncovers.
                let sx = (x as i32 - 3).clamp(0, width as i32 - 1) as usize;
                let sy = (y as i32 + 2).clamp(0, height as i32 - 1) as usize;
                assert_eq!(out[y * width + x], held.pixels[sy * width + sx], "({x}, {y})");
            }
        }
    }
}
