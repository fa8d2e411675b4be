//! Which course sample each cell of a river's window belongs to: the nearest point of the centre
//! line (a polyline through the samples), its distance, and the side of the line the cell is on.

use glam::DVec2;

use super::Window;

/// No sample within reach.
pub const NONE: u32 = u32::MAX;

/// The nearest-sample field of a window.
#[derive(Debug, Clone, PartialEq)]
pub struct Near {
    /// The nearest sample's index, or [`NONE`].
    pub owner: Vec<u32>,
    /// Distance to the centre line in cells (∞ where no owner).
    pub dist: Vec<f32>,
    /// +1 left of the line (counter-clockwise of its direction, x right, y up), −1 right, 0 on it.
    pub side: Vec<i8>,
}

/// The field of the polyline `line` (cell coordinates of the grid: cell centres at integers) over
/// `win`, for cells within `reach` cells of it. Each segment visits the cells of its bounding
/// box grown by `reach`, so the cost is the line's length × (2·reach)².
pub fn nearest(win: &Window, line: &[DVec2], reach: f64) -> Near {
    let n = win.len();
    let mut near = Near {
        owner: vec![NONE; n],
        dist: vec![f32::INFINITY; n],
        side: vec![0; n],
    };
    let origin = win.origin();
    let pts: Vec<DVec2> = line.iter().map(|p| *p - origin).collect();
    if pts.len() == 1 {
        // One point: a disc.
        visit(win, pts[0], pts[0], reach, |i, p| {
            let d = p.distance(pts[0]);
            if (d as f32) < near.dist[i] {
                near.dist[i] = d as f32;
                near.owner[i] = 0;
            }
        });
        return near;
    }
    for k in 0..pts.len().saturating_sub(1) {
        let (a, b) = (pts[k], pts[k + 1]);
        let ab = b - a;
        let len2 = ab.length_squared();
        visit(win, a, b, reach, |i, p| {
            let t = if len2 > 0.0 {
                ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = p.distance(a + ab * t) as f32;
            if d < near.dist[i] {
                near.dist[i] = d;
                near.owner[i] = if t < 0.5 { k as u32 } else { k as u32 + 1 };
                let cross = ab.perp_dot(p - a);
                near.side[i] = if cross > 1e-9 {
                    1
                } else if cross < -1e-9 {
                    -1
                } else {
                    0
                };
            }
        });
    }
    near
}

/// Calls `f(index, local position)` for the window's cells in the box of `a`, `b` grown by `reach`.
fn visit(win: &Window, a: DVec2, b: DVec2, reach: f64, mut f: impl FnMut(usize, DVec2)) {
    let lo = a.min(b) - DVec2::splat(reach);
    let hi = a.max(b) + DVec2::splat(reach);
    let (w, h) = (win.width as f64, win.height as f64);
    if hi.x < 0.0 || hi.y < 0.0 || lo.x > w - 1.0 || lo.y > h - 1.0 {
        return;
    }
    let (c0, c1) = (lo.x.ceil().max(0.0) as usize, (hi.x.floor().min(w - 1.0)) as usize);
    let (r0, r1) = (lo.y.ceil().max(0.0) as usize, (hi.y.floor().min(h - 1.0)) as usize);
    for r in r0..=r1 {
        for c in c0..=c1 {
            f(r * win.width + c, DVec2::new(c as f64, r as f64));
        }
    }
}

/// Sets `mask` to 1 on the window's cells within `radius` cells of the segment `a`–`b` (grid
/// cell coordinates): the sweep of a disc along it.
pub fn sweep_segment(win: &Window, mask: &mut [u8], a: DVec2, b: DVec2, radius: f64) {
    let origin = win.origin();
    let (a, b) = (a - origin, b - origin);
    let ab = b - a;
    let len2 = ab.length_squared();
    visit(win, a, b, radius, |i, p| {
        let t = if len2 > 0.0 {
            ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        if p.distance(a + ab * t) <= radius {
            mask[i] = 1;
        }
    });
}
