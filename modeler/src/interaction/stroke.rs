//! From the positions of a drawing stroke to a figure: the seed's point, polyline or closed
//! curve.
//!
//! The pen reports 150 positions a second, each with most of a millimetre of noise while it
//! moves (the device's filter lets motion through with little lag). A figure should keep the
//! vertices that carry the drawn shape and not the noise:
//!
//! 1. breakpoints: Douglas–Peucker within 2 mm on the display, run on the positions averaged
//!    over five neighbours so that noise peaks do not pass for corners;
//! 2. each breakpoint moves, within a few positions, to where the stretches either side fit
//!    their lines best, and breakpoints whose two stretches fit one line (within the noise) go;
//! 3. each stretch becomes the least-squares line through its own positions, and the vertices go
//!    where neighbouring lines meet.
//!
//! Averaging over a stretch's tens of positions takes most of the noise out without rounding the
//! corners, as smoothing the positions themselves would. A closed curve whose end overshoots or
//! wobbles across its start is untangled: small loops are cut off.

use penmodel_terrain::document::{FigureKind, Point};
use penmodel_terrain::geometry::{distance, line_offset, segments_touch};

/// The tolerances of turning strokes into figures, in ground metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// A stroke that stays this close to its first position is a point.
    pub point: f64,
    /// A stroke whose end comes back this close to its start is a closed curve.
    pub close: f64,
    /// Douglas–Peucker's tolerance for the breakpoints: above the pen's noise.
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

/// Douglas–Peucker: the indices of the points to keep so that every dropped one lies within
/// `tolerance` of the kept line. Keeps the first and last point; iterative, no recursion.
pub fn simplify_indices(points: &[Point], tolerance: f64) -> Vec<usize> {
    if points.len() <= 2 {
        return (0..points.len()).collect();
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
    (0..points.len()).filter(|&i| keep[i]).collect()
}

/// Douglas–Peucker: the points [`simplify_indices`] keeps.
pub fn simplify(points: &[Point], tolerance: f64) -> Vec<Point> {
    simplify_indices(points, tolerance)
        .into_iter()
        .map(|i| points[i])
        .collect()
}

/// A line through `centre` along the unit vector `dir`.
#[derive(Debug, Clone, Copy)]
struct Line {
    centre: Point,
    dir: Point,
}

impl Line {
    /// The least-squares (total, orthogonal) line through `points`.
    fn fit(points: &[Point]) -> Line {
        let n = points.len() as f64;
        let c = points
            .iter()
            .fold([0.0, 0.0], |s, p| [s[0] + p[0] / n, s[1] + p[1] / n]);
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for p in points {
            let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
            sxx += dx * dx;
            sxy += dx * dy;
            syy += dy * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        Line {
            centre: c,
            dir: [angle.cos(), angle.sin()],
        }
    }

    fn project(&self, p: Point) -> Point {
        let t = (p[0] - self.centre[0]) * self.dir[0] + (p[1] - self.centre[1]) * self.dir[1];
        [self.centre[0] + t * self.dir[0], self.centre[1] + t * self.dir[1]]
    }

    /// Where this line meets `other`, if they cross at more than ~10°.
    fn meet(&self, other: &Line) -> Option<Point> {
        let den = self.dir[0] * other.dir[1] - self.dir[1] * other.dir[0];
        if den.abs() < 0.17 {
            return None;
        }
        let d = [other.centre[0] - self.centre[0], other.centre[1] - self.centre[1]];
        let t = (d[0] * other.dir[1] - d[1] * other.dir[0]) / den;
        Some([self.centre[0] + t * self.dir[0], self.centre[1] + t * self.dir[1]])
    }
}

/// The vertex between stretches fitted by `a` and `b` at breakpoint `p`: where the lines meet,
/// or, where they are nearly parallel or meet far from the breakpoint, the breakpoint's mean
/// projection onto both.
fn corner(a: &Line, b: &Line, p: Point, reach: f64) -> Point {
    match a.meet(b) {
        Some(x) if distance(x, p) <= reach => x,
        _ => {
            let (u, v) = (a.project(p), b.project(p));
            [0.5 * (u[0] + v[0]), 0.5 * (u[1] + v[1])]
        }
    }
}

/// Each position averaged with up to `k` neighbours on either side (fewer at the ends).
fn average(points: &[Point], k: usize) -> Vec<Point> {
    let n = points.len();
    (0..n)
        .map(|i| {
            let r = k.min(i).min(n - 1 - i);
            let w = &points[i - r..=i + r];
            let m = w.len() as f64;
            w.iter().fold([0.0, 0.0], |s, p| [s[0] + p[0] / m, s[1] + p[1] / m])
        })
        .collect()
}

/// Sum of squared distances of `points` from their least-squares line.
fn sse(points: &[Point]) -> f64 {
    let line = Line::fit(points);
    points.iter().map(|&p| distance(p, line.project(p)).powi(2)).sum()
}

/// Moves each interior breakpoint to the split, within a few positions, where the two stretches
/// either side fit their lines best: Douglas–Peucker puts a breakpoint at the position farthest
/// from a chord, which noise shifts by a position or two around the bend.
fn refine(points: &[Point], breaks: &mut [usize]) {
    const WINDOW: usize = 6;
    for j in 1..breaks.len().saturating_sub(1) {
        let (a, b) = (breaks[j - 1], breaks[j + 1]);
        if b < a + 4 {
            continue;
        }
        let lo = breaks[j].saturating_sub(WINDOW).max(a + 2);
        let hi = (breaks[j] + WINDOW).min(b - 2);
        if let Some(best) = (lo..=hi).min_by(|&x, &y| {
            (sse(&points[a..=x]) + sse(&points[x..=b])).total_cmp(&(sse(&points[a..=y]) + sse(&points[y..=b])))
        }) {
            breaks[j] = best;
        }
    }
}

/// The positions a stretch's line is fitted to: without the one at each end, which the bend
/// may have pulled.
fn inner(points: &[Point], a: usize, b: usize) -> &[Point] {
    if b > a + 3 { &points[a + 1..b] } else { &points[a..=b] }
}

/// Removes breakpoints that do not bend the line: while some interior breakpoint's two
/// stretches fit one line within `max_rms`, the best fitting one goes. Noise that pushed
/// Douglas–Peucker over its tolerance fits a line at the noise's RMS; a real bend does not.
fn merge_straight(points: &[Point], breaks: &mut Vec<usize>, max_rms: f64) {
    while breaks.len() > 2 {
        let rms = |j: usize| {
            let p = inner(points, breaks[j - 1], breaks[j + 1]);
            (sse(p) / p.len() as f64).sqrt()
        };
        let best = (1..breaks.len() - 1)
            .map(|j| (j, rms(j)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((j, rms)) if rms <= max_rms => {
                breaks.remove(j);
                refine(points, breaks);
            }
            _ => return,
        }
    }
}

/// The figure through `points` (a closed chain ends where it starts): breakpoints, stretches
/// replaced by least-squares lines, vertices where they meet (see the module's notes). For a
/// closed chain the result is the ring without its closing repeat.
pub fn fit(points: &[Point], tolerance: f64, closed: bool) -> Vec<Point> {
    let mut breaks = simplify_indices(&average(points, 1), tolerance);
    refine(points, &mut breaks);
    merge_straight(points, &mut breaks, 0.5 * tolerance);
    if breaks.len() < 2 {
        return breaks.iter().map(|&i| points[i]).collect();
    }
    let lines: Vec<Line> = breaks
        .windows(2)
        .map(|w| Line::fit(inner(points, w[0], w[1])))
        .collect();
    let reach = 2.0 * tolerance;
    let m = lines.len();
    let mut out = Vec::with_capacity(m + 1);
    out.push(if closed {
        corner(&lines[m - 1], &lines[0], points[0], reach)
    } else {
        lines[0].project(points[0])
    });
    for k in 1..m {
        out.push(corner(&lines[k - 1], &lines[k], points[breaks[k]], reach));
    }
    if !closed {
        out.push(lines[m - 1].project(points[points.len() - 1]));
    }
    out.dedup();
    out
}

/// Where segments `a b` and `c d` cross (their lines' intersection; the midpoint of `b c` if
/// they are parallel).
fn crossing(a: Point, b: Point, c: Point, d: Point) -> Point {
    let r = [b[0] - a[0], b[1] - a[1]];
    let q = [d[0] - c[0], d[1] - c[1]];
    let den = r[0] * q[1] - r[1] * q[0];
    if den == 0.0 {
        return [0.5 * (b[0] + c[0]), 0.5 * (b[1] + c[1])];
    }
    let t = ((c[0] - a[0]) * q[1] - (c[1] - a[1]) * q[0]) / den;
    [a[0] + t * r[0], a[1] + t * r[1]]
}

fn area(ring: &[Point]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|i| {
            let (p, q) = (ring[i], ring[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        .abs()
        * 0.5
}

/// Cuts the loops off a ring (vertices without the closing repeat) where two of its edges touch,
/// keeping the larger part each time, until no edges touch; `None` if fewer than 3 vertices
/// remain. Quadratic in the vertices per cut; rings of a drawn figure have tens of them.
pub fn untangle(mut ring: Vec<Point>) -> Option<Vec<Point>> {
    'cut: loop {
        let n = ring.len();
        if n < 3 {
            return None;
        }
        for i in 0..n {
            // Edges i → i+1 and j → j+1, not neighbours (edge n−1 closes onto edge 0).
            for j in i + 2..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                let (a, b, c, d) = (ring[i], ring[i + 1], ring[j], ring[(j + 1) % n]);
                if !segments_touch(a, b, c, d) {
                    continue;
                }
                let x = crossing(a, b, c, d);
                let mut inner: Vec<Point> = ring[i + 1..=j].to_vec();
                inner.push(x);
                let mut outer: Vec<Point> = ring[j + 1..].iter().chain(&ring[..=i]).copied().collect();
                outer.push(x);
                ring = if area(&inner) > area(&outer) { inner } else { outer };
                ring.dedup();
                continue 'cut;
            }
        }
        return Some(ring);
    }
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
        // close the chain on the first position, fit, and cut off any loop where the end crossed
        // the start.
        let end = positions
            .iter()
            .rposition(|&p| distance(first, p) > tol.close)
            .map_or(positions.len(), |i| i + 1);
        let mut chain = positions[..end].to_vec();
        chain.push(first);
        if let Some(mut ring) = untangle(fit(&chain, tol.simplify, true)) {
            ring.push(ring[0]);
            return Some(Shape {
                kind: FigureKind::Closed,
                points: ring,
            });
        }
    }
    Some(Shape {
        kind: FigureKind::Polyline,
        points: fit(positions, tol.simplify, false),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modeler's defaults, in display mm.
    const TOL: Tolerances = Tolerances {
        point: 3.0,
        close: 10.0,
        simplify: 2.0,
    };

    /// A pen drawing through `corners` with a position every `step` mm (the corners included)
    /// and Gaussian noise of `sigma` mm per axis, reproducibly.
    fn stroke(corners: &[Point], step: f64, sigma: f64, seed: u64) -> Vec<Point> {
        let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut gauss = move || {
            let (u, v) = (uniform().max(1e-12), uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let mut out = Vec::new();
        for s in corners.windows(2) {
            let n = (distance(s[0], s[1]) / step).ceil() as usize;
            for i in 0..n {
                let t = i as f64 / n as f64;
                out.push([
                    s[0][0] + t * (s[1][0] - s[0][0]) + sigma * gauss(),
                    s[0][1] + t * (s[1][1] - s[0][1]) + sigma * gauss(),
                ]);
            }
        }
        out.push(corners[corners.len() - 1]);
        out
    }

    fn worst(points: &[Point], corners: &[Point]) -> f64 {
        points
            .iter()
            .zip(corners)
            .map(|(p, c)| distance(*p, *c))
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_touch_is_a_point() {
        let s = classify(&[[10.0, 10.0], [10.5, 9.8], [11.0, 10.2]], &TOL).unwrap();
        assert_eq!(s.kind, FigureKind::Point);
        assert!((s.points[0][0] - 10.5).abs() < 1e-9);
        assert_eq!(classify(&[], &TOL), None);
    }

    /// Errors of the vertices over 40 noisy strokes, `[RMS, worst]` mm, for the vertices
    /// `which` selects (by index).
    fn vertex_errors(corners: &[Point], truth: &[Point], closed: bool, which: impl Fn(usize) -> bool) -> [f64; 2] {
        let mut errors = Vec::new();
        for seed in 1..=40 {
            let s = classify(&stroke(corners, 2.5, 0.7, seed), &TOL).unwrap();
            let kind = if closed {
                FigureKind::Closed
            } else {
                FigureKind::Polyline
            };
            assert_eq!(s.kind, kind, "seed {seed}");
            assert_eq!(
                s.points.len(),
                truth.len() + usize::from(closed),
                "seed {seed}: {:?}",
                s.points
            );
            errors.extend(
                s.points
                    .iter()
                    .zip(truth)
                    .enumerate()
                    .filter(|(i, _)| which(*i))
                    .map(|(_, (p, c))| distance(*p, *c)),
            );
        }
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        [rms, errors.iter().copied().fold(0.0, f64::max)]
    }

    // With the moving pen's noise (0.7 mm per axis, a position every 2.5 mm), one position is
    // off by 0.7·√2 = 0.99 mm RMS. A vertex where two fitted lines meet is better; a vertex that
    // is one position (where the stroke began) is not.

    #[test]
    fn a_noisy_stroke_is_a_polyline_with_its_corners() {
        let corners = [[0.0, 0.0], [100.0, 40.0], [200.0, 20.0]];
        // Exactly the corners without noise.
        let clean = classify(&stroke(&corners, 2.5, 0.0, 1), &TOL).unwrap();
        assert_eq!(clean.kind, FigureKind::Polyline);
        assert!(worst(&clean.points, &corners) < 1e-9, "{:?}", clean.points);
        // A shallow bend (33°): the lines' errors along the bisector grow by 1/sin(16.5°) = 3.5,
        // and the vertex is still better than one position.
        let [rms, max] = vertex_errors(&corners, &corners, false, |i| i == 1);
        assert!(rms < 0.9 && max < 3.5, "RMS {rms:.2} mm, worst {max:.2} mm");
        let [rms, _] = vertex_errors(&corners, &corners, false, |i| i == 0);
        assert!(rms < 1.0, "the start: RMS {rms:.2} mm");
    }

    #[test]
    fn back_at_the_start_is_a_closed_curve() {
        let square = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0], [0.0, 0.0]];
        let mut inexact = square;
        inexact[4] = [1.0, 0.5];
        let clean = classify(&stroke(&inexact, 2.5, 0.0, 1), &TOL).unwrap();
        assert_eq!(clean.kind, FigureKind::Closed);
        assert_eq!(clean.points.len(), 5, "four corners and the repeat: {:?}", clean.points);
        // Right angles, every vertex where two lines meet.
        let [rms, max] = vertex_errors(&square, &square[..4], true, |_| true);
        assert!(rms < 0.5 && max < 1.5, "RMS {rms:.2} mm, worst {max:.2} mm");
        // Ending far from the start stays open.
        let open = [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0], [0.0, 30.0]];
        assert_eq!(
            classify(&stroke(&open, 2.5, 0.7, 3), &TOL).unwrap().kind,
            FigureKind::Polyline
        );
    }

    #[test]
    fn untangle_cuts_off_the_loop_where_the_end_crossed_the_start() {
        // A square whose last edge overshoots past the first vertex and back: a small loop.
        let ring = vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 10.0],
            [0.0, 10.0],
            [0.5, -1.0],
            [-1.0, 0.5],
        ];
        let clean = untangle(ring).expect("a ring");
        // The corner at the origin becomes the crossing point.
        assert_eq!(clean.len(), 4, "{clean:?}");
        for (i, a) in clean.iter().enumerate() {
            for j in i + 2..clean.len() {
                if i == 0 && j == clean.len() - 1 {
                    continue;
                }
                let (b, c, d) = (clean[i + 1], clean[j], clean[(j + 1) % clean.len()]);
                assert!(!segments_touch(*a, b, c, d), "edges {i} and {j} touch: {clean:?}");
            }
        }
        assert!((area(&clean) - 97.7).abs() < 0.1, "{}", area(&clean));
        assert_eq!(untangle(vec![[0.0, 0.0], [1.0, 0.0]]), None);
    }

    #[test]
    fn simplify_keeps_ends_and_drops_collinear_points() {
        let line: Vec<Point> = (0..=10).map(|i| [i as f64, 0.0]).collect();
        assert_eq!(simplify(&line, 0.1), vec![[0.0, 0.0], [10.0, 0.0]]);
        let bent = [[0.0, 0.0], [5.0, 5.0], [10.0, 0.0]];
        assert_eq!(simplify(&bent, 0.1), bent.to_vec());
    }
}
