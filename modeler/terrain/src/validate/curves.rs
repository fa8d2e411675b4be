//! Points and closed curves, shared by every element kind: finite points on the grid, none
//! repeating the one before; closed curves closed, with three or more vertices, not touching
//! themselves. `SegmentIndex` and `Bands` keep the checks linear for drawn curves.

use std::collections::HashMap;

use glam::DVec2;
use thiserror::Error;

use super::{Defect, Num, ValidationError};
use crate::document::{Grid, Point};
use crate::geometry::{self, Side};

/// What is wrong with a point or a closed curve.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CurveDefect {
    /// A point lies off the grid.
    #[error("({}, {}) lies outside the grid [0, {}) × [0, {}) m", Num(*x), Num(*y), Num(*width), Num(*height))]
    OutsideGrid {
        x: f64,
        y: f64,
        /// The grid's extent along x.
        width: f64,
        /// The grid's extent along y.
        height: f64,
    },
    /// A point equal to the one before it.
    #[error("repeats the previous point")]
    RepeatedPoint,
    /// A closed curve with fewer than three distinct vertices.
    #[error("a closed curve needs at least three distinct points, found {0}")]
    CurveTooShort(usize),
    /// A closed curve whose last point is not its first.
    #[error("the curve is open: its last point ({}, {}) is not its first ({}, {})", Num(last[0]), Num(last[1]), Num(first[0]), Num(first[1]))]
    OpenCurve { first: Point, last: Point },
    /// A closed curve that crosses or touches itself.
    #[error("the curve crosses itself: the segment from this point meets the segment from points[{0}]")]
    SelfIntersecting(usize),
}

/// Every point finite, on the grid, and different from the one before.
pub(super) fn points(grid: &Grid, pts: &[Point], path: &impl Fn(usize) -> String) -> Result<(), ValidationError> {
    for (i, p) in pts.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Err(ValidationError::new(path(i), Defect::NotFinite));
        }
        let (w, h) = (grid.width(), grid.height());
        if !(p[0] >= 0.0 && p[0] < w && p[1] >= 0.0 && p[1] < h) {
            let defect = CurveDefect::OutsideGrid {
                x: p[0],
                y: p[1],
                width: w,
                height: h,
            };
            return Err(ValidationError::new(path(i), defect));
        }
        if i > 0 && pts[i - 1] == *p {
            return Err(ValidationError::new(path(i), CurveDefect::RepeatedPoint));
        }
    }
    Ok(())
}

/// The segments `pts[i] pts[i + 1]` of a polyline in a grid of square buckets, for finding the
/// segments near another in time linear in the number of segments (for drawn curves, whose
/// segments are of similar length).
///
/// The bucket side `h` is the mean segment length. A segment is represented by sample points no
/// more than `h/3` apart, its ends included, each in the bucket holding it. A point common to two
/// segments lies within `h/6` of a sample of each, so those samples are at most `h/3` apart and
/// their buckets are equal or neighbours (also after rounding, which is far smaller than `h`):
/// looking up the 3 × 3 buckets around each sample of one segment finds every segment that can
/// touch it. A segment has at most `3·len/h + 2` samples, so the samples of a curve number at most
/// `5n`; a segment `k` times longer than the mean costs `k` times more, not `n`.
pub(super) struct SegmentIndex<'a> {
    pts: &'a [Point],
    origin: DVec2,
    h: f64,
    buckets: HashMap<(i64, i64), Vec<u32>>,
    /// The query a segment was last found by, to report each candidate once.
    seen: Vec<u32>,
    query: u32,
}

impl<'a> SegmentIndex<'a> {
    pub(super) fn new(pts: &'a [Point]) -> SegmentIndex<'a> {
        let n = pts.len().saturating_sub(1);
        let mut origin = DVec2::splat(f64::INFINITY);
        let mut total = 0.0;
        for (i, &p) in pts.iter().enumerate() {
            origin = origin.min(DVec2::from(p));
            if i > 0 {
                total += geometry::distance(pts[i - 1], p);
            }
        }
        let mean = total / n.max(1) as f64;
        // Points are on the grid, so finite; a curve of one repeated point has no length.
        let h = if mean.is_finite() && mean > 0.0 { mean } else { 1.0 };
        let mut index = SegmentIndex {
            pts,
            origin,
            h,
            buckets: HashMap::new(),
            seen: vec![0; n],
            query: 0,
        };
        let mut cells = Vec::new();
        for i in 0..n {
            cells.clear();
            index.samples(pts[i], pts[i + 1], &mut cells);
            for &cell in &cells {
                let list = index.buckets.entry(cell).or_default();
                if list.last() != Some(&(i as u32)) {
                    list.push(i as u32);
                }
            }
        }
        index
    }

    /// The buckets of the samples of segment `a b` (consecutive repeats removed).
    fn samples(&self, a: Point, b: Point, out: &mut Vec<(i64, i64)>) {
        let (a, b) = (DVec2::from(a), DVec2::from(b));
        let steps = (3.0 * a.distance(b) / self.h).ceil().clamp(1.0, 1e9) as u64;
        for k in 0..=steps {
            let p = a.lerp(b, k as f64 / steps as f64);
            let q = (p - self.origin) / self.h;
            // `as` saturates: a point far outside the curve's box lands in an edge bucket, which
            // only adds candidates.
            let cell = (q.x.floor() as i64, q.y.floor() as i64);
            if out.last() != Some(&cell) {
                out.push(cell);
            }
        }
    }

    /// Every indexed segment that may touch segment `a b`, in increasing order (a superset of
    /// those that do).
    pub(crate) fn near(&mut self, a: Point, b: Point, out: &mut Vec<usize>) {
        out.clear();
        self.query += 1;
        let mut cells = Vec::new();
        self.samples(a, b, &mut cells);
        for (x, y) in cells {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let key = (x.saturating_add(dx), y.saturating_add(dy));
                    let Some(list) = self.buckets.get(&key) else { continue };
                    for &i in list {
                        if self.seen[i as usize] != self.query {
                            self.seen[i as usize] = self.query;
                            out.push(i as usize);
                        }
                    }
                }
            }
        }
        out.sort_unstable();
    }

    /// Whether segment `a b` touches any indexed segment.
    pub(super) fn touches(&mut self, a: Point, b: Point, scratch: &mut Vec<usize>) -> bool {
        self.near(a, b, scratch);
        let pts = self.pts;
        scratch
            .iter()
            .any(|&i| geometry::segments_touch(a, b, pts[i], pts[i + 1]))
    }
}

/// A closed curve's edges in horizontal bands, to locate points against it in time proportional
/// to the edges in the point's band rather than all of them. Each edge is in every band its
/// `y` range meets, so every edge that can hold the point or cross its horizontal ray is in the
/// point's band; [`Bands::locate`] gives exactly [`geometry::locate`]'s answer.
pub(super) struct Bands<'a> {
    ring: &'a [Point],
    y0: f64,
    height: f64,
    bands: Vec<Vec<u32>>,
}

impl<'a> Bands<'a> {
    pub(super) fn new(ring: &'a [Point]) -> Bands<'a> {
        let n = ring.len().saturating_sub(1);
        let (mut y0, mut y1, mut rise) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for (i, p) in ring.iter().enumerate() {
            y0 = y0.min(p[1]);
            y1 = y1.max(p[1]);
            if i > 0 {
                rise += (p[1] - ring[i - 1][1]).abs();
            }
        }
        // Bands at least as tall as an edge's mean rise, so the edges' band entries number at
        // most about 3n; and at most n + 1 bands.
        let span = (y1 - y0).max(0.0);
        let height = (rise / n.max(1) as f64).max(span / n.max(1) as f64);
        let height = if height.is_finite() && height > 0.0 {
            height
        } else {
            1.0
        };
        let count = ((span / height).floor() as usize).saturating_add(1).min(n + 1);
        let mut bands = Bands {
            ring,
            y0,
            height,
            bands: vec![Vec::new(); count.max(1)],
        };
        for i in 0..n {
            let (a, b) = (ring[i][1], ring[i + 1][1]);
            for band in bands.band(a.min(b))..=bands.band(a.max(b)) {
                bands.bands[band].push(i as u32);
            }
        }
        bands
    }

    /// The band of height `y` (monotonic in `y`, clamped to the bands).
    fn band(&self, y: f64) -> usize {
        let k = ((y - self.y0) / self.height).floor();
        // `as` saturates (NaN to 0), then the clamp keeps it in range.
        (k.max(0.0) as usize).min(self.bands.len() - 1)
    }

    /// [`geometry::locate`] of `p`, through the edges of its band only.
    pub(super) fn locate(&self, p: Point) -> Side {
        let edges = &self.bands[self.band(p[1])];
        let mut inside = false;
        for &i in edges {
            let (a, b) = (self.ring[i as usize], self.ring[i as usize + 1]);
            if geometry::on_segment(a, b, p) {
                return Side::On;
            }
            // The same half-open test and crossing as geometry::locate, so the same bits.
            let (a, b, q) = (DVec2::from(a), DVec2::from(b), DVec2::from(p));
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
        if inside { Side::Inside } else { Side::Outside }
    }
}

/// A closed curve: valid points, closed, three or more vertices, not touching itself.
pub(super) fn ring(
    grid: &Grid,
    pts: &[Point],
    path: impl Fn(usize) -> String,
    whole: &str,
) -> Result<(), ValidationError> {
    points(grid, pts, &path)?;
    let (Some(&first), Some(&last)) = (pts.first(), pts.last()) else {
        return Err(ValidationError::new(whole, CurveDefect::CurveTooShort(0)));
    };
    if first != last {
        return Err(ValidationError::new(whole, CurveDefect::OpenCurve { first, last }));
    }
    let n = pts.len() - 1; // segments, = distinct vertices
    if n < 3 {
        return Err(ValidationError::new(whole, CurveDefect::CurveTooShort(n)));
    }
    let seg = |i: usize| (pts[i], pts[i + 1]);
    let mut index = SegmentIndex::new(pts);
    let mut near = Vec::new();
    // The first segment j meeting an earlier one, and the first such i: the order of checking
    // every pair, with only the pairs that can meet looked at.
    for j in 1..n {
        index.near(pts[j], pts[j + 1], &mut near);
        for &i in near.iter().take_while(|&&i| i < j) {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let meets = if adjacent {
                // Adjacent segments share a vertex; they meet elsewhere only by doubling back.
                let (p, q, r) = if j == i + 1 {
                    (pts[i], pts[j], pts[j + 1])
                } else {
                    (pts[j], pts[0], pts[1])
                };
                let (p, q, r) = (DVec2::from(p), DVec2::from(q), DVec2::from(r));
                geometry::orient(p, q, r) == 0.0 && (p - q).dot(r - q) > 0.0
            } else {
                let ((a, b), (c, d)) = (seg(i), seg(j));
                geometry::segments_touch(a, b, c, d)
            };
            if meets {
                return Err(ValidationError::new(path(j), CurveDefect::SelfIntersecting(i)));
            }
        }
    }
    Ok(())
}
