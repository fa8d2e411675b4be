//! Plane geometry on the document's points: orientation, segment intersection, point in polygon.
//!
//! The computations are on [`DVec2`]; every function takes anything that converts into one, so
//! the document's `[x, y]` points ([`Point`](crate::document::Point), which keep the file format and its parse
//! errors as they are) and glam vectors both go in as they are. The formulas are written out by
//! component where glam's own would round differently (a distance is `hypot`, not
//! `sqrt(x² + y²)`), so the results are the same bits as on plain arrays.
//!
//! Plain `f64` predicates. They decide validation (a curve crossing itself, a figure leaving its
//! region); inputs that sit within rounding of a tie are decided either way, consistently for the
//! same input.

use glam::DVec2;

/// Twice the signed area of the triangle `a b c`: positive when `c` is to the left of `a → b`.
pub fn orient(a: impl Into<DVec2>, b: impl Into<DVec2>, c: impl Into<DVec2>) -> f64 {
    let a = a.into();
    let (ab, ac) = (b.into() - a, c.into() - a);
    ab.x * ac.y - ab.y * ac.x
}

/// Whether `p`, known to be collinear with `a b`, lies within the segment's bounding box.
fn within(a: DVec2, b: DVec2, p: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Whether the closed segments `a b` and `c d` share at least one point (touching counts).
pub fn segments_touch(a: impl Into<DVec2>, b: impl Into<DVec2>, c: impl Into<DVec2>, d: impl Into<DVec2>) -> bool {
    let (a, b, c, d) = (a.into(), b.into(), c.into(), d.into());
    let o1 = orient(a, b, c);
    let o2 = orient(a, b, d);
    let o3 = orient(c, d, a);
    let o4 = orient(c, d, b);
    if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)) {
        return true;
    }
    (o1 == 0.0 && within(a, b, c))
        || (o2 == 0.0 && within(a, b, d))
        || (o3 == 0.0 && within(c, d, a))
        || (o4 == 0.0 && within(c, d, b))
}

/// Whether `p` lies on the closed segment `a b`.
pub fn on_segment(a: impl Into<DVec2>, b: impl Into<DVec2>, p: impl Into<DVec2>) -> bool {
    let (a, b, p) = (a.into(), b.into(), p.into());
    orient(a, b, p) == 0.0 && within(a, b, p)
}

/// Distance between two points.
pub fn distance(a: impl Into<DVec2>, b: impl Into<DVec2>) -> f64 {
    let d = a.into() - b.into();
    d.x.hypot(d.y)
}

/// Distance from `p` to the closed segment `a b`.
pub fn segment_distance(a: impl Into<DVec2>, b: impl Into<DVec2>, p: impl Into<DVec2>) -> f64 {
    let (a, b, p) = (a.into(), b.into(), p.into());
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return distance(a, p);
    }
    let t = ((p - a).dot(d) / len2).clamp(0.0, 1.0);
    distance(a + d * t, p)
}

/// Distance from `p` to the line through `a` and `b` (to `a` if they coincide).
pub fn line_offset(a: impl Into<DVec2>, b: impl Into<DVec2>, p: impl Into<DVec2>) -> f64 {
    let (a, b, p) = (a.into(), b.into(), p.into());
    let len = distance(a, b);
    if len == 0.0 {
        return distance(a, p);
    }
    orient(a, b, p).abs() / len
}

/// Where `p` is relative to the closed polygon `ring` (first point repeated at the end).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Strictly inside.
    Inside,
    /// On one of the polygon's edges.
    On,
    /// Strictly outside.
    Outside,
}

/// Locates `p` against the simple polygon `ring` (even-odd rule; its last point equals its first).
pub fn locate<P: Copy + Into<DVec2>>(ring: &[P], p: impl Into<DVec2>) -> Side {
    let p = p.into();
    let mut inside = false;
    for e in ring.windows(2) {
        let (a, b) = (e[0].into(), e[1].into());
        if on_segment(a, b, p) {
            return Side::On;
        }
        // Half-open in y so a vertex on the ray is counted once.
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    if inside { Side::Inside } else { Side::Outside }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::Point;

    const SQUARE: [Point; 5] = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0], [0.0, 0.0]];

    #[test]
    fn locate_square() {
        assert_eq!(locate(&SQUARE, [2.0, 2.0]), Side::Inside);
        assert_eq!(locate(&SQUARE, [4.0, 2.0]), Side::On);
        assert_eq!(locate(&SQUARE, [0.0, 0.0]), Side::On);
        assert_eq!(locate(&SQUARE, [5.0, 2.0]), Side::Outside);
        assert_eq!(locate(&SQUARE, [2.0, 4.5]), Side::Outside);
    }

    #[test]
    fn touching_segments() {
        assert!(segments_touch([0.0, 0.0], [2.0, 2.0], [0.0, 2.0], [2.0, 0.0]));
        assert!(segments_touch([0.0, 0.0], [2.0, 0.0], [2.0, 0.0], [3.0, 1.0]));
        assert!(segments_touch([0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [3.0, 0.0]));
        assert!(!segments_touch([0.0, 0.0], [2.0, 0.0], [2.5, 0.0], [3.0, 0.0]));
        assert!(!segments_touch([0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.4, 0.6]));
    }
}
