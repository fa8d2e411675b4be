//! The river's course: a chain of Bézier segments through its control points, sampled at even
//! arc length, with the seed's curvature at each sample.
//!
//! Points 0, 3, 6, … are on the course; the two between each pair are handles, so 4 points are
//! one cubic Bézier curve and `3k + 1` points are k cubic segments joined end to end. A last
//! segment with fewer points has a lower degree (2 points: a line; 3: a quadratic), so any count
//! of two or more is a course.

use glam::DVec2;

/// A sample of a course: its position, and the first and second derivatives of a
/// parametrisation there (any parametrisation: curvature does not depend on it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Position.
    pub p: DVec2,
    /// First derivative.
    pub d1: DVec2,
    /// Second derivative.
    pub d2: DVec2,
}

impl Sample {
    /// The seed's curvature κ = |x′y″ − x″y′| / (x′² + y′²)^{3/2}.
    pub fn curvature(&self) -> f64 {
        curvature(self.d1, self.d2)
    }

    /// The sign of the turn: +1 when the course bends to the left (counter-clockwise, x right and
    /// y up), −1 to the right, 0 straight.
    pub fn turn(&self) -> i8 {
        let cross = self.d1.perp_dot(self.d2);
        // Below this the bend is noise in the samples.
        if cross.abs() <= 1e-9 * self.d1.length_squared().powf(1.5).max(1e-300) {
            0
        } else if cross > 0.0 {
            1
        } else {
            -1
        }
    }
}

/// κ = |x′y″ − x″y′| / (x′² + y′²)^{3/2} (0 where the derivative vanishes).
pub fn curvature(d1: DVec2, d2: DVec2) -> f64 {
    let speed2 = d1.length_squared();
    if speed2 == 0.0 {
        return 0.0;
    }
    d1.perp_dot(d2).abs() / speed2.powf(1.5)
}

/// The segments of a course: slices of 2 to 4 control points sharing their end points.
pub fn segments(points: &[DVec2]) -> impl Iterator<Item = &[DVec2]> {
    let n = points.len();
    (0..n.saturating_sub(1))
        .step_by(3)
        .map(move |i| &points[i..(i + 4).min(n)])
}

/// Position and derivatives of one Bézier segment (2 to 4 control points) at `t` in `[0, 1]`.
pub fn eval(seg: &[DVec2], t: f64) -> Sample {
    let s = 1.0 - t;
    match *seg {
        [a, b] => Sample {
            p: a * s + b * t,
            d1: b - a,
            d2: DVec2::ZERO,
        },
        [a, b, c] => Sample {
            p: a * (s * s) + b * (2.0 * s * t) + c * (t * t),
            d1: (b - a) * (2.0 * s) + (c - b) * (2.0 * t),
            d2: (c - 2.0 * b + a) * 2.0,
        },
        [a, b, c, d] => Sample {
            p: a * (s * s * s) + b * (3.0 * s * s * t) + c * (3.0 * s * t * t) + d * (t * t * t),
            d1: ((b - a) * (s * s) + (c - b) * (2.0 * s * t) + (d - c) * (t * t)) * 3.0,
            d2: ((c - 2.0 * b + a) * s + (d - 2.0 * c + b) * t) * 6.0,
        },
        _ => Sample {
            p: seg.first().copied().unwrap_or_default(),
            d1: DVec2::ZERO,
            d2: DVec2::ZERO,
        },
    }
}

/// Samples of the course about `spacing` apart along it (the first and last control points
/// included), with the Bézier derivatives at each.
pub fn sample(points: &[DVec2], spacing: f64) -> Vec<Sample> {
    // A fine polyline per segment gives the arc length; samples are then placed at even arc
    // length and evaluated exactly.
    const FINE: usize = 64;
    let mut table: Vec<(usize, f64, f64)> = Vec::new(); // (segment, t, arc length)
    let segs: Vec<&[DVec2]> = segments(points).collect();
    let mut arc = 0.0;
    let mut prev = points.first().copied().unwrap_or_default();
    for (k, seg) in segs.iter().enumerate() {
        for j in 0..=FINE {
            if k > 0 && j == 0 {
                continue;
            }
            let t = j as f64 / FINE as f64;
            let p = eval(seg, t).p;
            arc += p.distance(prev);
            prev = p;
            table.push((k, t, arc));
        }
    }
    if segs.is_empty() || table.is_empty() {
        return Vec::new();
    }
    let n = ((arc / spacing).round() as usize).max(1);
    let mut out = Vec::with_capacity(n + 1);
    let mut at = 0;
    for i in 0..=n {
        let want = arc * i as f64 / n as f64;
        while at + 1 < table.len() && table[at + 1].2 < want {
            at += 1;
        }
        let (k, t) = match table.get(at + 1) {
            Some(&(k1, t1, a1)) => {
                // The entry before a segment's first is the previous one's end: t = 0 of this one.
                let (a0, t0) = if table[at].0 == k1 {
                    (table[at].2, table[at].1)
                } else {
                    (table[at].2, 0.0)
                };
                let f = if a1 > a0 {
                    ((want - a0) / (a1 - a0)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                (k1, t0 + (t1 - t0) * f)
            }
            None => (table[at].0, table[at].1),
        };
        out.push(eval(segs[k], t));
    }
    if let (Some(last), Some(&end)) = (out.last_mut(), points.last()) {
        last.p = end;
    }
    out
}

/// A polyline resampled at even arc length, about `spacing` apart, its ends kept; derivatives by
/// central differences over `±stencil` samples (one-sided at the ends), the index as parameter.
pub fn resample(line: &[DVec2], spacing: f64, stencil: usize) -> Vec<Sample> {
    let mut arcs = Vec::with_capacity(line.len());
    let mut arc = 0.0;
    for (i, p) in line.iter().enumerate() {
        if i > 0 {
            arc += p.distance(line[i - 1]);
        }
        arcs.push(arc);
    }
    let Some(&first) = line.first() else {
        return Vec::new();
    };
    let n = ((arc / spacing).round() as usize).max(1);
    let mut pts = Vec::with_capacity(n + 1);
    let mut at = 0;
    for i in 0..=n {
        let want = arc * i as f64 / n as f64;
        while at + 2 < line.len() && arcs[at + 1] < want {
            at += 1;
        }
        let p = match (line.get(at + 1), arcs.get(at + 1)) {
            (Some(&b), Some(&ab)) if ab > arcs[at] => {
                line[at].lerp(b, ((want - arcs[at]) / (ab - arcs[at])).clamp(0.0, 1.0))
            }
            _ => line[at],
        };
        pts.push(p);
    }
    if let (Some(last), Some(&end)) = (pts.last_mut(), line.last()) {
        *last = end;
    }
    pts[0] = first;
    differentiate(&pts, stencil)
}

/// Samples of the points with derivatives by differences over `±stencil` neighbours.
pub fn differentiate(pts: &[DVec2], stencil: usize) -> Vec<Sample> {
    let n = pts.len();
    let m = stencil.max(1);
    (0..n)
        .map(|i| {
            // Keep the stencil symmetric where it fits, shrink it near the ends.
            let h = m.min(i).min(n - 1 - i);
            let (d1, d2) = if h == 0 {
                let (a, b) = if i + 1 < n {
                    (pts[i], pts[i + 1])
                } else if i > 0 {
                    (pts[i - 1], pts[i])
                } else {
                    (pts[i], pts[i])
                };
                (b - a, DVec2::ZERO)
            } else {
                let hf = h as f64;
                let (a, c, b) = (pts[i - h], pts[i], pts[i + h]);
                ((b - a) / (2.0 * hf), (b - 2.0 * c + a) / (hf * hf))
            };
            Sample { p: pts[i], d1, d2 }
        })
        .collect()
}

/// Control points fitted to a pen stroke: `anchors` points at even arc length along it (at least
/// 2) joined by cubic segments whose handles follow the stroke's direction (Catmull–Rom tangents),
/// so the course passes through the anchors. Returns `3·(anchors − 1) + 1` points.
pub fn fit(stroke: &[DVec2], anchors: usize) -> Vec<DVec2> {
    let anchors = anchors.max(2);
    let total: f64 = stroke.windows(2).map(|w| w[0].distance(w[1])).sum();
    if stroke.len() < 2 || total <= 0.0 {
        return stroke.iter().take(1).chain(stroke.iter().take(1)).copied().collect();
    }
    let a: Vec<DVec2> = resample(stroke, total / (anchors - 1) as f64, 1)
        .iter()
        .map(|s| s.p)
        .collect();
    let n = a.len();
    let tangent = |i: usize| -> DVec2 {
        let (p, q) = (a[i.saturating_sub(1)], a[(i + 1).min(n - 1)]);
        (q - p) / if i == 0 || i == n - 1 { 1.0 } else { 2.0 }
    };
    let mut out = vec![a[0]];
    for i in 0..n - 1 {
        out.push(a[i] + tangent(i) / 3.0);
        out.push(a[i + 1] - tangent(i + 1) / 3.0);
        out.push(a[i + 1]);
    }
    out
}
