//! From the positions of a drawing stroke to a figure: the seed's point, polyline or closed
//! curve.
//!
//! The pen reports 150 positions a second, each with a little noise; a figure keeps the vertices
//! that carry its shape. Positions closer than a minimum step to the last one are not recorded,
//! and the recorded line is simplified by Douglas–Peucker within a tolerance below the drawing's
//! precision (a millimetre on the display, about one grid cell at the default scale).

use crate::document::{FigureKind, Point};

/// The tolerances of turning strokes into figures, in ground metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// A stroke that stays this close to its first position is a point.
    pub point: f64,
    /// A stroke whose end comes back this close to its start is a closed curve.
    pub close: f64,
    /// Vertices within this distance of the simplified line are dropped.
    pub simplify: f64,
}

/// A figure's shape as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Point, polyline or closed curve.
    pub kind: FigureKind,
    /// Its points; a closed curve repeats its first point at the end.
    pub points: Vec<Point>,
}

fn distance(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance from `p` to the line through `a` and `b` (to `a` if they coincide).
fn line_offset(a: Point, b: Point, p: Point) -> f64 {
    let len = distance(a, b);
    if len == 0.0 {
        return distance(a, p);
    }
    ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])).abs() / len
}

/// Douglas–Peucker: the vertices of `points` to keep so that every dropped one lies within
/// `tolerance` of the kept line. Keeps the first and last point; iterative, no recursion.
pub fn simplify(points: &[Point], tolerance: f64) -> Vec<Point> {
    if points.len() <= 2 {
        return points.to_vec();
    }
    let mut keep = vec![false; points.len()];
    keep[0] = true;
    keep[points.len() - 1] = true;
    let mut spans = vec![(0, points.len() - 1)];
    while let Some((i, j)) = spans.pop() {
        let (far, offset) = (i + 1..j)
            .map(|k| (k, line_offset(points[i], points[j], points[k])))
            .fold((i, -1.0), |best, c| if c.1 > best.1 { c } else { best });
        if far > i && offset > tolerance {
            keep[far] = true;
            spans.push((i, far));
            spans.push((far, j));
        }
    }
    points.iter().zip(&keep).filter(|(_, k)| **k).map(|(p, _)| *p).collect()
}

/// The figure a stroke's positions make; `None` for no positions.
pub fn classify(positions: &[Point], tol: &Tolerances) -> Option<Shape> {
    let first = *positions.first()?;
    let reach = positions.iter().map(|&p| distance(first, p)).fold(0.0, f64::max);
    if reach <= tol.point {
        // The mean of a held touch is steadier than its first position.
        let n = positions.len() as f64;
        let mean = positions
            .iter()
            .fold([0.0, 0.0], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
        return Some(Shape {
            kind: FigureKind::Point,
            points: vec![mean],
        });
    }
    let last = positions[positions.len() - 1];
    if distance(first, last) <= tol.close && reach > 2.0 * tol.close {
        // Back at the start: drop the positions that returned into the start's neighbourhood,
        // simplify the rest and close the ring on the first point.
        let end = positions
            .iter()
            .rposition(|&p| distance(first, p) > tol.close)
            .map_or(positions.len(), |i| i + 1);
        let mut chain = positions[..end].to_vec();
        chain.push(first);
        let ring = simplify(&chain, tol.simplify);
        if ring.len() >= 4 {
            return Some(Shape {
                kind: FigureKind::Closed,
                points: ring,
            });
        }
    }
    let mut line = simplify(positions, tol.simplify);
    line.dedup();
    Some(Shape {
        kind: FigureKind::Polyline,
        points: line,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: Tolerances = Tolerances {
        point: 3.0,
        close: 10.0,
        simplify: 1.0,
    };

    /// Positions every `step` along the segments through `corners`, wobbling by `wobble`.
    fn stroke(corners: &[Point], step: f64, wobble: f64) -> Vec<Point> {
        let mut out = Vec::new();
        for (k, s) in corners.windows(2).enumerate() {
            let n = (distance(s[0], s[1]) / step).ceil() as usize;
            for i in 0..n {
                let t = i as f64 / n as f64;
                // Zero at the corners, so they are drawn exactly.
                let w = wobble * (i as f64 * 2.1 + k as f64).sin() * if i == 0 { 0.0 } else { 1.0 };
                out.push([
                    s[0][0] + t * (s[1][0] - s[0][0]) + w,
                    s[0][1] + t * (s[1][1] - s[0][1]) - w,
                ]);
            }
        }
        out.push(corners[corners.len() - 1]);
        out
    }

    #[test]
    fn a_touch_is_a_point() {
        let s = classify(&[[10.0, 10.0], [10.5, 9.8], [11.0, 10.2]], &TOL).unwrap();
        assert_eq!(s.kind, FigureKind::Point);
        assert!((s.points[0][0] - 10.5).abs() < 1e-9);
        assert_eq!(classify(&[], &TOL), None);
    }

    /// The simplified line keeps every corner (a vertex within `TOL.simplify` of it), stays
    /// within the tolerance of the drawn line, and adds at most one vertex per corner (noise at a
    /// corner can split it in two).
    fn check_shape(points: &[Point], corners: &[Point], drawn: &[Point]) {
        let dist_to = |p: Point, line: &[Point]| {
            line.windows(2)
                .map(|s| {
                    let d = [s[1][0] - s[0][0], s[1][1] - s[0][1]];
                    let t = (((p[0] - s[0][0]) * d[0] + (p[1] - s[0][1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]))
                        .clamp(0.0, 1.0);
                    distance(p, [s[0][0] + t * d[0], s[0][1] + t * d[1]])
                })
                .fold(f64::INFINITY, f64::min)
        };
        for c in corners {
            let nearest = points.iter().map(|p| distance(*p, *c)).fold(f64::INFINITY, f64::min);
            assert!(nearest <= TOL.simplify, "corner {c:?} lost: {points:?}");
        }
        for p in points {
            assert!(dist_to(*p, drawn) <= TOL.simplify, "{p:?} off the line");
        }
        assert!(
            points.len() <= 2 * corners.len(),
            "{} vertices: {points:?}",
            points.len()
        );
    }

    #[test]
    fn a_stroke_is_a_polyline_with_its_corners() {
        let corners = [[0.0, 0.0], [100.0, 40.0], [200.0, 20.0]];
        let s = classify(&stroke(&corners, 2.0, 0.3), &TOL).unwrap();
        assert_eq!(s.kind, FigureKind::Polyline);
        check_shape(&s.points, &corners, &corners);
        assert_eq!(s.points[0], corners[0]);
        assert_eq!(s.points.last(), corners.last());
        // Without noise, exactly the corners.
        let clean = classify(&stroke(&corners, 2.0, 0.0), &TOL).unwrap();
        assert_eq!(clean.points.len(), 3, "{:?}", clean.points);
    }

    #[test]
    fn back_at_the_start_is_a_closed_curve() {
        let corners = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0], [3.0, 4.0]];
        let s = classify(&stroke(&corners, 2.0, 0.3), &TOL).unwrap();
        assert_eq!(s.kind, FigureKind::Closed);
        assert_eq!(s.points.first(), s.points.last());
        // The end within the closing tolerance of the start is not a corner.
        let drawn = [
            [0.0, 0.0],
            [100.0, 0.0],
            [100.0, 80.0],
            [0.0, 80.0],
            [3.0, 4.0],
            [0.0, 0.0],
        ];
        check_shape(&s.points, &drawn[..4], &drawn);
        let mut clean_corners = corners;
        clean_corners[4] = [1.0, 0.5];
        let clean = classify(&stroke(&clean_corners, 2.0, 0.0), &TOL).unwrap();
        assert_eq!(clean.points.len(), 5, "four corners and the repeat: {:?}", clean.points);
        // Ending far from the start stays open.
        let open = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0], [0.0, 30.0]];
        assert_eq!(
            classify(&stroke(&open, 2.0, 0.3), &TOL).unwrap().kind,
            FigureKind::Polyline
        );
    }

    #[test]
    fn simplify_keeps_ends_and_drops_collinear_points() {
        let line: Vec<Point> = (0..=10).map(|i| [i as f64, 0.0]).collect();
        assert_eq!(simplify(&line, 0.1), vec![[0.0, 0.0], [10.0, 0.0]]);
        let bent = [[0.0, 0.0], [5.0, 5.0], [10.0, 0.0]];
        assert_eq!(simplify(&bent, 0.1), bent.to_vec());
    }
}
