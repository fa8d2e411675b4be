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
/// `win`, for cells within `reach` cells of it. Each segment visits its slab of cells (below),
/// so the cost is about the band's area × (1 + 2·reach × the bend per sample).
pub fn nearest(win: &Window, line: &[DVec2], reach: f64) -> Near {
    let mut near = Near {
        owner: Vec::new(),
        dist: Vec::new(),
        side: Vec::new(),
    };
    nearest_into(win, line, reach, &mut near);
    near
}

/// Windows of at least this many cells fill their field on two row bands at once.
const SPLIT_CELLS: usize = 16_384;

/// [`nearest`] into `near`'s buffers (reused from one iteration to the next).
///
/// A large window is filled as two bands of rows on the thread pool: each band runs every
/// segment over its own rows, in the same order, so each cell sees the same candidates in the
/// same order as a single pass and the field is the same bit for bit (a test checks).
pub fn nearest_into(win: &Window, line: &[DVec2], reach: f64, near: &mut Near) {
    let n = win.len();
    near.owner.clear();
    near.owner.resize(n, NONE);
    near.dist.clear();
    near.dist.resize(n, f32::INFINITY);
    near.side.clear();
    near.side.resize(n, 0);
    let origin = win.origin();
    let pts: Vec<DVec2> = line.iter().map(|p| *p - origin).collect();
    if n < SPLIT_CELLS || win.height < 2 {
        fill(
            win,
            &pts,
            reach,
            0..win.height,
            &mut near.owner,
            &mut near.dist,
            &mut near.side,
        );
        return;
    }
    let mid = win.height / 2;
    let at = mid * win.width;
    let (o0, o1) = near.owner.split_at_mut(at);
    let (d0, d1) = near.dist.split_at_mut(at);
    let (s0, s1) = near.side.split_at_mut(at);
    let pts = &pts;
    rayon::join(
        || fill(win, pts, reach, 0..mid, o0, d0, s0),
        || fill(win, pts, reach, mid..win.height, o1, d1, s1),
    );
}

/// The field of the polyline `pts` (window-local) over the window's rows `rows`, into buffers
/// that hold those rows only (reset to [`NONE`], ∞, 0).
fn fill(
    win: &Window,
    pts: &[DVec2],
    reach: f64,
    rows: std::ops::Range<usize>,
    owner: &mut [u32],
    dist: &mut [f32],
    side: &mut [i8],
) {
    let base = rows.start * win.width;
    if pts.len() == 1 {
        // One point: a disc.
        visit(win, rows.clone(), pts[0], pts[0], reach, |i, p| {
            let d = p.distance(pts[0]);
            if (d as f32) < dist[i - base] {
                dist[i - base] = d as f32;
                owner[i - base] = 0;
            }
        });
        return;
    }
    let segs = pts.len().saturating_sub(1);
    let dir: Vec<DVec2> = (0..segs).map(|k| (pts[k + 1] - pts[k]).normalize_or_zero()).collect();
    // The turn at each joint, once (the angle's size does not depend on the order).
    let bend: Vec<f64> = (1..segs).map(|k| dir[k - 1].angle_to(dir[k]).abs()).collect();
    for k in 0..segs {
        let (a, b) = (pts[k], pts[k + 1]);
        let ab = b - a;
        // Each segment visits its slab (the cells whose projection falls on it) widened over
        // the wedge its joints leave on the outer side of a bend: `reach × angle` past each end,
        // and 0.6 cell more so that neighbouring slabs overlap whatever the rounding; the
        // course's ends get a cap of `reach`.
        let widen = |other: Option<usize>| -> f64 {
            match other {
                None => reach,
                Some(j) => reach * bend[j] + 0.6,
            }
        };
        let before = widen(k.checked_sub(1));
        let after = widen((k + 1 < segs).then_some(k));
        let len2 = ab.length_squared();
        slab(win, rows.clone(), a, b, before, after, reach, |i, p| {
            // `clamp(0, 1)` by hand: the same for a number, without `clamp`'s check of its bounds
            // (a sixth of the field's instructions).
            #[allow(clippy::manual_clamp)]
            let t = if len2 > 0.0 {
                let t = (p - a).dot(ab) / len2;
                if t < 0.0 {
                    0.0
                } else if t > 1.0 {
                    1.0
                } else {
                    t
                }
            } else {
                0.0
            };
            // Squared distances while searching; the roots once at the end.
            let d = p.distance_squared(a + ab * t) as f32;
            let j = i - base;
            // Without a branch: which segment is nearest changes from cell to cell in no
            // pattern a predictor learns.
            let better = d < dist[j];
            let cross = ab.perp_dot(p - a);
            let s = i8::from(cross > 1e-9) - i8::from(cross < -1e-9);
            let o = if t < 0.5 { k as u32 } else { k as u32 + 1 };
            dist[j] = if better { d } else { dist[j] };
            owner[j] = if better { o } else { owner[j] };
            side[j] = if better { s } else { side[j] };
        });
    }
    for d in dist.iter_mut() {
        *d = d.sqrt();
    }
}

/// Calls `f(index, local position)` for the window's cells of rows `rows` in the box of `a`, `b`
/// grown by `reach`.
fn visit(win: &Window, rows: std::ops::Range<usize>, a: DVec2, b: DVec2, reach: f64, mut f: impl FnMut(usize, DVec2)) {
    let lo = a.min(b) - DVec2::splat(reach);
    let hi = a.max(b) + DVec2::splat(reach);
    let (w, h) = (win.width as f64, win.height as f64);
    if hi.x < 0.0 || hi.y < 0.0 || lo.x > w - 1.0 || lo.y > h - 1.0 {
        return;
    }
    let (c0, c1) = (lo.x.ceil().max(0.0) as usize, (hi.x.floor().min(w - 1.0)) as usize);
    let (r0, r1) = (lo.y.ceil().max(0.0) as usize, (hi.y.floor().min(h - 1.0)) as usize);
    for r in r0.max(rows.start)..(r1 + 1).min(rows.end) {
        for c in c0..=c1 {
            f(r * win.width + c, DVec2::new(c as f64, r as f64));
        }
    }
}

/// Calls `f(index, local position)` for the window's cells within `reach` of the line through
/// `a`, `b` whose projection on it lies from `before` before `a` to `after` past `b` (distances
/// along the line), row by row (of `rows` only): each row's cells form one interval.
#[allow(clippy::too_many_arguments)]
fn slab(
    win: &Window,
    rows: std::ops::Range<usize>,
    a: DVec2,
    b: DVec2,
    before: f64,
    after: f64,
    reach: f64,
    mut f: impl FnMut(usize, DVec2),
) {
    let ab = b - a;
    let len = ab.length();
    if len == 0.0 {
        return visit(win, rows, a, b, reach, f);
    }
    let u = ab / len;
    let (lo_t, hi_t) = (-before, len + after);
    let corners = [a + u * lo_t, a + u * hi_t];
    let lo = corners[0].min(corners[1]) - DVec2::splat(reach);
    let hi = corners[0].max(corners[1]) + DVec2::splat(reach);
    let (w, h) = (win.width as f64, win.height as f64);
    if hi.x < 0.0 || hi.y < 0.0 || lo.x > w - 1.0 || lo.y > h - 1.0 {
        return;
    }
    let (r0, r1) = (lo.y.ceil().max(0.0) as usize, hi.y.floor().min(h - 1.0) as usize);
    // The rows the slab's own corners span (the box above is grown by `reach` both ways: for a
    // segment along a column, 2·reach rows more than the slab's), and one more each side, so that
    // the rows left out have no cell whatever the rounding of the bounds below.
    let v = u.perp();
    let ys = [lo_t, hi_t].map(|t| a.y + u.y * t);
    let across = (v.y * reach).abs();
    let (y0, y1) = (ys[0].min(ys[1]) - across - 1.0, ys[0].max(ys[1]) + across + 1.0);
    let (r0, r1) = (r0.max(y0.max(0.0) as usize), r1.min(y1.max(0.0) as usize));
    let (cmin, cmax) = (lo.x.ceil().max(0.0), hi.x.floor().min(w - 1.0));
    for r in r0.max(rows.start)..(r1 + 1).min(rows.end) {
        let dy = r as f64 - a.y;
        // Along: s(c) = (c − a.x)·u.x + dy·u.y in [lo_t, hi_t]; across: n(c) = (c − a.x)·u.y − dy·u.x
        // (up to sign) in [−reach, reach]. Both are linear in c. The cells are the integers from
        // the greatest lower bound to the least upper one: the ceiling of a maximum is the
        // maximum of the ceilings, so one ceiling and one floor per row, of values held within
        // a cell of `[cmin, cmax]` (integers), where they are small integers.
        let (mut low, mut high) = (cmin, cmax);
        for (k, off, range) in [(u.x, dy * u.y, (lo_t, hi_t)), (u.y, -dy * u.x, (-reach, reach))] {
            if k.abs() < 1e-12 {
                if off < range.0 || off > range.1 {
                    high = low - 1.0;
                }
            } else {
                let (x0, x1) = ((range.0 - off) / k + a.x, (range.1 - off) / k + a.x);
                low = low.max(x0.min(x1));
                high = high.min(x0.max(x1));
            }
        }
        let (c0, c1) = (ceil_small(low.min(cmax + 1.0)), floor_small(high.max(cmin - 1.0)));
        if c1 < c0 {
            continue;
        }
        for c in c0 as usize..=c1 as usize {
            f(r * win.width + c, DVec2::new(c as f64, r as f64));
        }
    }
}

/// `x.ceil()` for `x` within `i32`'s range, as an integer: a truncation and a compare.
fn ceil_small(x: f64) -> i32 {
    let t = x as i32;
    if f64::from(t) < x { t + 1 } else { t }
}

/// `x.floor()` for `x` within `i32`'s range, as an integer (see [`ceil_small`]).
fn floor_small(x: f64) -> i32 {
    let t = x as i32;
    if f64::from(t) > x { t - 1 } else { t }
}

/// `x.round()` (half away from zero) up to the sign of a zero, inline (without SSE4.1
/// `f64::round` is a call into libm; the river's recentring paid one per step): the fraction `x − trunc(x)` is exact.
pub(super) fn round(x: f64) -> f64 {
    let t = trunc(x);
    let f = x - t;
    if f >= 0.5 {
        t + 1.0
    } else if f <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

/// `x` rounded towards zero; values of 2⁵² and more (and NaN, ∞) are already whole.
fn trunc(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        x as i64 as f64
    } else {
        x
    }
}

/// Sets `mask` to 1 on the window's cells within `radius` cells of the segment `a`–`b` (grid
/// cell coordinates): the sweep of a disc along it.
pub fn sweep_segment(win: &Window, mask: &mut [u8], a: DVec2, b: DVec2, radius: f64) {
    let origin = win.origin();
    let (a, b) = (a - origin, b - origin);
    let ab = b - a;
    let len2 = ab.length_squared();
    visit(win, 0..win.height, a, b, radius, |i, p| {
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
