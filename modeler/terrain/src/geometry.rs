//! Plane geometry on the document's points: orientation, segment intersection, point in polygon.
//!
//! Plain `f64` predicates. They decide validation (a curve crossing itself, a figure leaving its
//! region); inputs that sit within rounding of a tie are decided either way, consistently for the
//! same input.

use crate::document::Point;

/// Twice the signed area of the triangle `a b c`: positive when `c` is to the left of `a → b`.
pub fn orient(a: Point, b: Point, c: Point) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether `p`, known to be collinear with `a b`, lies within the segment's bounding box.
fn within(a: Point, b: Point, p: Point) -> bool {
    p[0] >= a[0].min(b[0]) && p[0] <= a[0].max(b[0]) && p[1] >= a[1].min(b[1]) && p[1] <= a[1].max(b[1])
}

/// Whether the closed segments `a b` and `c d` share at least one point (touching counts).
pub fn segments_touch(a: Point, b: Point, c: Point, d: Point) -> bool {
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
pub fn on_segment(a: Point, b: Point, p: Point) -> bool {
    orient(a, b, p) == 0.0 && within(a, b, p)
}

/// Distance between two points.
pub fn distance(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance from `p` to the closed segment `a b`.
pub fn segment_distance(a: Point, b: Point, p: Point) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    if len2 == 0.0 {
        return distance(a, p);
    }
    let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0);
    distance([a[0] + t * d[0], a[1] + t * d[1]], p)
}

/// Distance from `p` to the line through `a` and `b` (to `a` if they coincide).
pub fn line_offset(a: Point, b: Point, p: Point) -> f64 {
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
pub fn locate(ring: &[Point], p: Point) -> Side {
    let mut inside = false;
    for e in ring.windows(2) {
        let (a, b) = (e[0], e[1]);
        if on_segment(a, b, p) {
            return Side::On;
        }
        // Half-open in y so a vertex on the ray is counted once.
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    if inside { Side::Inside } else { Side::Outside }
}

#[cfg(test)]
mod tests {
    use super::*;

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
