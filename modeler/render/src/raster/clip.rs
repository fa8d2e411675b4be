//! Clipping: triangles and line segments against the near plane and the guard band.
//!
//! Clipping happens in the projection's homogeneous coordinates `(X, Y, w)` (pixel = `X/w`,
//! `Y/w`), where every plane is linear: the near plane `w ≥ near`, and the guard band
//! `X ≥ G₀·w`, `X ≤ G₁·w`, `Y ≥ G₀·w`, `Y ≤ G₁·w` ([`GUARD_MIN`], [`GUARD_MAX`] pixels). A
//! triangle crossing a plane is cut, not dropped (Sutherland–Hodgman), and the polygon left is
//! drawn as a fan.
//!
//! **Why a guard band rather than the viewport**: the rasteriser already limits itself to the
//! pixels of its tile, so the only job of side clipping is to keep coordinates inside its
//! fixed-point range. Clipping to a band far outside the frame touches only triangles that are
//! enormous on screen (a camera inside the terrain), so the fast path never clips, and the cut
//! edges lie off screen where their rounding cannot show.
//!
//! **Watertight cuts**: an edge shared by two triangles is cut by both at the same point,
//! because the cut is always computed from the inside end to the outside end, with the same
//! operations on the same inputs (both triangles get their vertices from
//! [`super::transform::Affine::clip_vertex`]).

/// Pixels left of (above) the frame that fixed-point coordinates still hold.
pub(crate) const GUARD_MIN: f32 = -8192.0;
/// Pixels right of (below) the frame's origin that fixed-point coordinates still hold.
pub(crate) const GUARD_MAX: f32 = crate::output::frame::MAX_SIDE as f32 + 8192.0;

/// A vertex before the perspective division, with its attributes: height (metres) and light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipVertex {
    /// `X = pixel x · w`.
    pub x: f32,
    /// `Y = pixel y · w`.
    pub y: f32,
    /// Depth in front of the eye.
    pub w: f32,
    /// Height, metres.
    pub h: f32,
    /// Light, 0 to 1.
    pub l: f32,
}

impl ClipVertex {
    fn lerp(self, to: ClipVertex, t: f32) -> ClipVertex {
        ClipVertex {
            x: self.x + t * (to.x - self.x),
            y: self.y + t * (to.y - self.y),
            w: self.w + t * (to.w - self.w),
            h: self.h + t * (to.h - self.h),
            l: self.l + t * (to.l - self.l),
        }
    }

    /// Whether the vertex is inside every plane (then it needs no clipping).
    pub fn inside(&self, near: f32) -> bool {
        planes(near).iter().all(|p| p.distance(self) >= 0.0)
    }
}

/// A plane `a·X + b·Y + c·w + d ≥ 0`.
#[derive(Debug, Clone, Copy)]
struct Plane([f32; 4]);

impl Plane {
    fn distance(&self, v: &ClipVertex) -> f32 {
        let [a, b, c, d] = self.0;
        a * v.x + b * v.y + c * v.w + d
    }
}

fn planes(near: f32) -> [Plane; 5] {
    [
        Plane([0.0, 0.0, 1.0, -near]),
        Plane([1.0, 0.0, -GUARD_MIN, 0.0]),
        Plane([-1.0, 0.0, GUARD_MAX, 0.0]),
        Plane([0.0, 1.0, -GUARD_MIN, 0.0]),
        Plane([0.0, -1.0, GUARD_MAX, 0.0]),
    ]
}

/// The most vertices a triangle clipped by five planes can have.
pub(crate) const MAX_POLYGON: usize = 8;

/// A convex polygon of up to [`MAX_POLYGON`] vertices.
#[allow(missing_docs)] // `len` counts the vertices used.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Polygon {
    /// The vertices; the first `len` are used.
    pub vertices: [ClipVertex; MAX_POLYGON],
    pub len: usize,
}

/// The cut of edge `(a, b)` with the plane, computed from the inside end.
fn cut(a: ClipVertex, da: f32, b: ClipVertex, db: f32) -> ClipVertex {
    if da >= 0.0 {
        a.lerp(b, da / (da - db))
    } else {
        b.lerp(a, db / (db - da))
    }
}

/// The part of triangle `tri` inside the near plane and the guard band, in the same winding.
pub(crate) fn triangle(tri: [ClipVertex; 3], near: f32) -> Polygon {
    let mut poly = Polygon {
        vertices: [tri[0]; MAX_POLYGON],
        len: 3,
    };
    poly.vertices[..3].copy_from_slice(&tri);
    for plane in planes(near) {
        let mut out = [tri[0]; MAX_POLYGON];
        let mut n = 0;
        for i in 0..poly.len {
            let a = poly.vertices[i];
            let b = poly.vertices[(i + 1) % poly.len];
            let (da, db) = (plane.distance(&a), plane.distance(&b));
            if da >= 0.0 {
                out[n] = a;
                n += 1;
            }
            if (da >= 0.0) != (db >= 0.0) && n < MAX_POLYGON {
                out[n] = cut(a, da, b, db);
                n += 1;
            }
        }
        poly.vertices = out;
        poly.len = n;
        if n < 3 {
            poly.len = 0;
            break;
        }
    }
    poly
}

/// The part of segment `(a, b)` inside the near plane and the guard band, if any.
pub(crate) fn segment(mut a: ClipVertex, mut b: ClipVertex, near: f32) -> Option<(ClipVertex, ClipVertex)> {
    for plane in planes(near) {
        let (da, db) = (plane.distance(&a), plane.distance(&b));
        match (da >= 0.0, db >= 0.0) {
            (true, true) => {}
            (false, false) => return None,
            (true, false) => b = cut(a, da, b, db),
            (false, true) => a = cut(a, da, b, db),
        }
    }
    Some((a, b))
}
