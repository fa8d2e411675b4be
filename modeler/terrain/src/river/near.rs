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
    /// Per row of the window, the columns the last fill's segments visited (first > last: none);
    /// every other cell holds [`NONE`], ∞ and 0, so the next fill resets only these.
    spans: Vec<(u32, u32)>,
}

impl Near {
    /// A field of no cells (each fill sizes it to its window).
    pub fn empty() -> Near {
        Near::in_buffers(Vec::new(), Vec::new(), Vec::new())
    }

    /// A field that has not been filled, in these buffers (the first fill sets all their cells).
    pub(super) fn in_buffers(owner: Vec<u32>, dist: Vec<f32>, side: Vec<i8>) -> Near {
        Near {
            owner,
            dist,
            side,
            spans: Vec::new(),
        }
    }

    /// Its buffers.
    pub(super) fn into_buffers(self) -> (Vec<u32>, Vec<f32>, Vec<i8>) {
        (self.owner, self.dist, self.side)
    }
}

/// A row span of no cells.
const NO_SPAN: (u32, u32) = (u32::MAX, 0);

/// The field of the polyline `line` (cell coordinates of the grid: cell centres at integers) over
/// `win`, for cells within `reach` cells of it. Each segment visits the cells it may be nearest
/// (below): about the band's area × (1 + reach × the turn per sample / 2) cells in all.
pub fn nearest(win: &Window, line: &[DVec2], reach: f64) -> Near {
    let mut near = Near::empty();
    nearest_into(win, line, reach, &mut near);
    near
}

/// Windows of at least this many cells fill their field on two row bands at once.
const SPLIT_CELLS: usize = 16_384;

/// How far (cells) each row's cells of a region reach past its exact bounds, so that rounding in
/// the bounds never leaves out a cell on an edge; far below a cell, so it adds no visits.
const SLACK: f64 = 1e-6;

/// [`nearest`] into `near`'s buffers (reused from one iteration to the next: a field of the same
/// window is reset only where its segments reached, so its arrays must hold what the last fill
/// left there).
///
/// Each cell's owner is the nearest segment within `reach` (the first of equal squared distances
/// as `f32`), whichever segments visit it, so a large window is filled as two bands of rows on
/// the thread pool and the field is the same bit for bit (a test checks).
pub fn nearest_into(win: &Window, line: &[DVec2], reach: f64, near: &mut Near) {
    let n = win.len();
    // Another window's buffers (or none yet): every cell unset, no span.
    if near.owner.len() != n || near.dist.len() != n || near.side.len() != n || near.spans.len() != win.height {
        near.owner.clear();
        near.owner.resize(n, NONE);
        near.dist.clear();
        near.dist.resize(n, f32::INFINITY);
        near.side.clear();
        near.side.resize(n, 0);
        near.spans.clear();
        near.spans.resize(win.height, NO_SPAN);
    }
    let origin = win.origin();
    let pts: Vec<DVec2> = line.iter().map(|p| *p - origin).collect();
    let Near {
        owner,
        dist,
        side,
        spans,
    } = near;
    if n < SPLIT_CELLS || win.height < 2 {
        fill(
            win,
            &pts,
            reach,
            0..win.height,
            Band {
                owner,
                dist,
                side,
                spans,
            },
        );
        return;
    }
    let mid = win.height / 2;
    let at = mid * win.width;
    let (o0, o1) = owner.split_at_mut(at);
    let (d0, d1) = dist.split_at_mut(at);
    let (s0, s1) = side.split_at_mut(at);
    let (p0, p1) = spans.split_at_mut(mid);
    let pts = &pts;
    rayon::join(
        || {
            let band = Band {
                owner: o0,
                dist: d0,
                side: s0,
                spans: p0,
            };
            fill(win, pts, reach, 0..mid, band)
        },
        || {
            let band = Band {
                owner: o1,
                dist: d1,
                side: s1,
                spans: p1,
            };
            fill(win, pts, reach, mid..win.height, band)
        },
    );
}

/// A band of rows of a field's buffers.
struct Band<'a> {
    owner: &'a mut [u32],
    dist: &'a mut [f32],
    side: &'a mut [i8],
    spans: &'a mut [(u32, u32)],
}

/// A segment of the line in its own frame (from `a` along the unit `u` for `len` cells; `s` along
/// it from `a`, `n` across it, positive on its left) and the cells it may be nearest: the
/// rectangle `s` in `along`, `|n|` ≤ reach, and the wedge past its end on the outer side of the
/// bend, if any.
struct Segment {
    a: DVec2,
    u: DVec2,
    len: f64,
    along: (f64, f64),
    /// The outer side (±1) and how far past the end the wedge reaches at `|n|` = reach.
    wedge: Option<(f64, f64)>,
}

/// The line's segments: one per pair of points, one of length 0 for a single point.
fn segment_count(pts: &[DVec2]) -> usize {
    pts.len().saturating_sub(1).max(pts.len().min(1))
}

/// The unit direction from `a` to `b`, if they differ.
fn direction(a: DVec2, b: DVec2) -> Option<DVec2> {
    let len = a.distance(b);
    (len > 0.0).then(|| (b - a) / len)
}

/// Segment `k` of the line `pts` (below [`segment_count`]). A cell's nearest point of the line is
/// inside a segment (then the cell projects onto it, within `reach` across) or at a joint, on
/// the outer side of the bend, in the wedge between the two segments' normals; the segment before
/// the joint covers that wedge (a cell at `|n|` across it lies at most `|n| · tan(turn)` past its
/// end), or, for a turn of 45° or more, a rectangle `reach` long past its end. The course's ends
/// and segments of length 0 reach `reach` each way (a disc, which also covers the joints next to
/// a segment of length 0). So the region lies within `√2 · reach` of the segment.
fn segment(pts: &[DVec2], k: usize, reach: f64) -> Segment {
    let (a, b) = match pts {
        [p] => (*p, *p),
        _ => (pts[k], pts[k + 1]),
    };
    let Some(u) = direction(a, b) else {
        return Segment {
            a,
            u: DVec2::X,
            len: 0.0,
            along: (-reach, reach),
            wedge: None,
        };
    };
    let len = a.distance(b);
    let start = if k == 0 { -reach } else { 0.0 };
    let (mut end, mut wedge) = (len, None);
    let last = segment_count(pts) - 1;
    match (k < last).then(|| direction(pts[k + 1], pts[k + 2])).flatten() {
        _ if k == last => end = len + reach,
        // A turn of 45° or more: the wedge's cells within reach lie at most `reach` past.
        Some(q) if u.dot(q) <= u.perp_dot(q).abs() => end = len + reach,
        Some(q) => {
            // Turning left, the outer side is the right (n < 0).
            let turn = u.perp_dot(q);
            if turn != 0.0 {
                wedge = Some((-turn.signum(), reach * turn.abs() / u.dot(q)));
            }
        }
        None => {}
    }
    Segment {
        a,
        u,
        len,
        along: (start, end),
        wedge,
    }
}

/// The field of the line `pts` (window-local) over the window's rows `rows`, into a band of
/// buffers that holds those rows only (unset but for the last fill's spans).
fn fill(win: &Window, pts: &[DVec2], reach: f64, rows: std::ops::Range<usize>, band: Band) {
    let Band {
        owner,
        dist,
        side,
        spans,
    } = band;
    let w = win.width;
    // The last fill's cells back to unset.
    for (r, span) in spans.iter_mut().enumerate() {
        let (c0, c1) = (span.0 as usize, span.1 as usize);
        if c0 <= c1 {
            owner[r * w + c0..=r * w + c1].fill(NONE);
            dist[r * w + c0..=r * w + c1].fill(f32::INFINITY);
            side[r * w + c0..=r * w + c1].fill(0);
        }
        *span = NO_SPAN;
    }
    // While searching, `dist` holds squared distances, compared by their bits (the same order for
    // positive floats, ∞ above them all).
    let mut band = Band {
        owner,
        dist,
        side,
        spans,
    };
    // A segment's region lies within √2 · reach of it (see `segment`): those of segments further
    // from the band's rows have none of its cells.
    let (top, bottom) = (rows.start as f64 - 2.0 * reach - 1.0, rows.end as f64 + 2.0 * reach);
    for k in 0..segment_count(pts) {
        let (a, b) = (pts[k], pts[(k + 1).min(pts.len() - 1)]);
        if a.y.max(b.y) < top || a.y.min(b.y) > bottom {
            continue;
        }
        let seg = &segment(pts, k, reach);
        let Some(region) = Region::of(win, seg, reach) else {
            continue;
        };
        // Most regions are rectangles, with two edges each side.
        if region.edges <= 2 {
            visit_segment::<2>(&region, seg, k as u32, reach, &rows, w, &mut band);
        } else {
            visit_segment::<4>(&region, seg, k as u32, reach, &rows, w, &mut band);
        }
    }
    let Band { dist, spans, .. } = band;
    // The roots once at the end (∞ stays ∞).
    for (r, span) in spans.iter().enumerate() {
        let (c0, c1) = (span.0 as usize, span.1 as usize);
        if c0 <= c1 {
            for d in &mut dist[r * w + c0..=r * w + c1] {
                *d = d.sqrt();
            }
        }
    }
}

/// Segment `k`'s visits of the cells of its region in the band of rows `rows` (the window `w`
/// cells wide): where it is nearer than the cell's nearest so far, it becomes the cell's owner.
/// `N`: the region's edges each side that bound its rows (at least [`Region::edges`]).
#[inline(always)]
fn visit_segment<const N: usize>(
    region: &Region,
    seg: &Segment,
    k: u32,
    reach: f64,
    rows: &std::ops::Range<usize>,
    w: usize,
    band: &mut Band,
) {
    let Segment { a, u, len, .. } = *seg;
    let r2 = reach * reach;
    let base = rows.start * w;
    // Its nearer end: `k` before the middle (and for a segment of length 0), `k + 1` from it.
    let half = if len > 0.0 { 0.5 * len } else { f64::INFINITY };
    // The side: none for a segment of length 0 (a point has none).
    let on = if len > 0.0 { 1e-9 } else { f64::INFINITY };
    for r in region.r0.max(rows.start)..(region.r1 + 1).min(rows.end) {
        let Some((c0, c1)) = region.cols::<N>(r) else {
            continue;
        };
        let span = &mut band.spans[r - rows.start];
        *span = (span.0.min(c0 as u32), span.1.max(c1 as u32));
        let j0 = r * w + c0 - base;
        let n = c1 - c0 + 1;
        // Along the segment s = c·u.x + s0, across it (positive on its left) n0 − c·u.y.
        let dy = r as u32 as f64 - a.y;
        let (s0, n0) = (dy * u.y - a.x * u.x, dy * u.x + a.x * u.y);
        let (dist, owner, side) = (
            &mut band.dist[j0..j0 + n],
            &mut band.owner[j0..j0 + n],
            &mut band.side[j0..j0 + n],
        );
        let mut x = c0 as u32 as f64;
        for j in 0..n {
            let s = x * u.x + s0;
            let across = n0 - x * u.y;
            x += 1.0;
            // The nearest point is the projection clamped to the segment (by hand: no NaN
            // here, and `clamp` checks its bounds).
            #[allow(clippy::manual_clamp)]
            let sc = if s < 0.0 {
                0.0
            } else if s > len {
                len
            } else {
                s
            };
            let d = (s - sc) * (s - sc) + across * across;
            let (df, best) = ((d as f32).to_bits(), dist[j].to_bits());
            // Without a branch: which segment is nearest changes from cell to cell in no pattern
            // a predictor learns (the distance chosen as bits: a float's choice is a branch).
            let better = (d <= r2) & (df < best);
            let o = k + u32::from(s >= half);
            let sd = i8::from(across > on) - i8::from(across < -on);
            dist[j] = f32::from_bits(std::hint::select_unpredictable(better, df, best));
            owner[j] = std::hint::select_unpredictable(better, o, owner[j]);
            side[j] = std::hint::select_unpredictable(better, sd, side[j]);
        }
    }
}

/// The cells a segment visits, row by row: its rectangle with its wedge, as one convex polygon
/// (the wedge's triangle and the rectangle's hull; a cell of the hull outside both only costs a
/// visit). Each row's cells form one interval, between the greatest of the left edges' bounds
/// and the least of the right edges' (each edge's line bounds every row), widened by [`SLACK`].
struct Region {
    /// The rows that may have cells, `r0..=r1`.
    r0: usize,
    r1: usize,
    /// The columns' bounds, within the window and widened by [`SLACK`].
    cmin: f64,
    cmax: f64,
    /// Each edge's x at row y: x0 + y·slope. Rising edges bound on the right (the inside is on an
    /// edge's left), falling ones on the left; the arrays are filled up with lines at −∞ (left)
    /// and +∞ (right), which bound nothing, so each row takes the same steps.
    left: [(f64, f64); 4],
    right: [(f64, f64); 4],
    /// The edges of the side with more of them.
    edges: usize,
}

impl Region {
    /// `seg`'s region in the window (window-local), or `None` if it has no cells there.
    fn of(win: &Window, seg: &Segment, reach: f64) -> Option<Region> {
        let at = |s: f64, n: f64| seg.a + seg.u * s + seg.u.perp() * n;
        let (s0, s1) = seg.along;
        // Counter-clockwise in (s, n), and so in the window (a rotation keeps the turn).
        let verts = match seg.wedge {
            None => [at(s0, -reach), at(s1, -reach), at(s1, reach), at(s0, reach)],
            Some((side, past)) if side > 0.0 => [at(s0, -reach), at(s1, -reach), at(s1 + past, reach), at(s0, reach)],
            Some((_, past)) => [at(s0, -reach), at(s1 + past, -reach), at(s1, reach), at(s0, reach)],
        };
        Region::convex(win, &verts)
    }

    /// The convex polygon `verts` (counter-clockwise, x right and y up; window-local).
    fn convex(win: &Window, verts: &[DVec2; 4]) -> Option<Region> {
        let (lo, hi) = verts
            .iter()
            .fold((DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let (w, h) = (win.width as f64, win.height as f64);
        if hi.x < -SLACK || hi.y < -SLACK || lo.x > w - 1.0 + SLACK || lo.y > h - 1.0 + SLACK {
            return None;
        }
        let mut left = [(f64::NEG_INFINITY, 0.0); 4];
        let mut right = [(f64::INFINITY, 0.0); 4];
        let (mut nl, mut nr) = (0, 0);
        for (i, p) in verts.iter().enumerate() {
            let q = verts[(i + 1) % verts.len()];
            let dy = q.y - p.y;
            // Edges along a row are bounded by the rows.
            if dy.abs() < 1e-12 {
                continue;
            }
            let slope = (q.x - p.x) / dy;
            let edge = (p.x - p.y * slope, slope);
            if dy > 0.0 {
                right[nr] = edge;
                nr += 1;
            } else {
                left[nl] = edge;
                nl += 1;
            }
        }
        Some(Region {
            r0: ceil_small((lo.y - SLACK).max(0.0)) as usize,
            r1: floor_small((hi.y + SLACK).min(h - 1.0)) as usize,
            cmin: (lo.x - SLACK).max(0.0),
            cmax: (hi.x + SLACK).min(w - 1.0),
            left,
            right,
            edges: nl.max(nr),
        })
    }

    /// The first and last column of row `r`'s cells, if any, from the first `N` edges of each
    /// side (at least [`Region::edges`]).
    #[inline(always)]
    fn cols<const N: usize>(&self, r: usize) -> Option<(usize, usize)> {
        let y = r as u32 as f64;
        // Plain compares: no NaN here, and `max`/`min` handle one. The lines at ±∞ give ±∞
        // (`y · 0` is 0), never beyond the bound.
        let (mut low, mut high) = (self.cmin + SLACK, self.cmax - SLACK);
        for &(x0, slope) in &self.left[..N] {
            let x = x0 + y * slope;
            if x > low {
                low = x;
            }
        }
        for &(x0, slope) in &self.right[..N] {
            let x = x0 + y * slope;
            if x < high {
                high = x;
            }
        }
        let (low, high) = (low - SLACK, high + SLACK);
        // The ceiling of a maximum is the maximum of the ceilings: one ceiling and one floor per
        // row, of values held within a cell of `[cmin, cmax]`, where they are small integers.
        let (last, first) = (self.cmax + 1.0, self.cmin - 1.0);
        let c0 = ceil_small(if low < last { low } else { last });
        let c1 = floor_small(if high > first { high } else { first });
        (c1 >= c0).then_some((c0 as usize, c1 as usize))
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
