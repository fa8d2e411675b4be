//! Alg. 2.1's polygons for a [`Skeleton`].
//!
//! - **Flanks**: a segment from `p0` (elevation `z0`) to `p1` (`z1`) has a flank on each side
//!   sloping down at α: at horizontal parameter `t` along the segment and horizontal distance `r`
//!   from it, `z = z0 + t(z1 − z0) − r·tan α`, down to the ground (`z = 0`, at
//!   `r = z(t)/tan α`). Each flank is a planar quadrilateral `p0, p1, p1 + n·z1/tan α,
//!   p0 + n·z0/tan α` (`n` the side's unit normal); the pair is one [`Polygon::Flanks`].
//! - **Joints**: at a node P (elevation zP) the segments leave it in directions sorted by angle.
//!   Between two neighbouring directions more than 180° apart, their flanks leave a wedge
//!   uncovered; the seed fills it with triangles. Planar triangles with their corners on the
//!   cone's foot fall steeper than α between the corners (by 1/cos of half their angle: 39° for
//!   α = 30° across a 90° triangle), so here the wedge is filled by the cone itself,
//!   `z = zP − |q − P|·tan α`, which falls at α in every direction. A convex outline from P
//!   around the wedge, a corner every 30° at most (3.5 % beyond the foot `R = zP/tan α`, so
//!   its edges touch the foot's circle), bounds the cells a row visits. A ridgeline's end is such a
//!   node with one segment: its 180° wedge gets a half cone, a rounded hip instead of a cliff.
//!
//! The polygons of one node are one [`Polygon::Fan`]. Everything below the ground (z ≤ 0) is
//! left out, so a segment reaching down to 0 narrows to a point.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use super::Skeleton;
use crate::rect::Rect;

/// What a polygon belongs to: its skeleton and its segment or node there. Keys are how an
/// incremental update matches a changed skeleton's polygons with the old ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Part {
    /// Segment `i`'s two flanks.
    Edge(u32),
    /// Node `i`'s joint triangles.
    Node(u32),
}

/// One of Alg. 2.1's polygons, in metres.
#[derive(Debug, Clone, PartialEq)]
pub enum Polygon {
    /// The two flanks of a segment.
    Flanks {
        /// Start `[x, y]`.
        p0: [f64; 2],
        /// End `[x, y]`.
        p1: [f64; 2],
        /// Elevation at `p0`.
        z0: f64,
        /// Elevation at `p1`.
        z1: f64,
        /// tan α.
        tan: f64,
    },
    /// The cone sectors around a node: apex `[x, y]` at elevation `z`, falling at α over each
    /// wedge, each wedge bounded by a convex outline from the apex around it.
    Fan {
        /// The node `[x, y]`.
        apex: [f64; 2],
        /// Its elevation.
        z: f64,
        /// tan α.
        tan: f64,
        /// The wedges `[from, to]` (radians, counter-clockwise, each at most 180°).
        wedges: Vec<[f64; 2]>,
        /// Per wedge, the convex outline holding it: the apex, then corners around the arc.
        outlines: Vec<Vec<[f64; 2]>>,
    },
}

impl Polygon {
    /// The ground-plane bounding box `[x0, y0, x1, y1]`.
    pub fn bounds(&self) -> [f64; 4] {
        match self {
            Polygon::Flanks { p0, p1, z0, z1, tan } => {
                let reach = z0.max(*z1).max(0.0) / tan;
                [
                    p0[0].min(p1[0]) - reach,
                    p0[1].min(p1[1]) - reach,
                    p0[0].max(p1[0]) + reach,
                    p0[1].max(p1[1]) + reach,
                ]
            }
            Polygon::Fan { apex, outlines, .. } => {
                let mut b = [apex[0], apex[1], apex[0], apex[1]];
                for q in outlines.iter().flatten() {
                    b = [b[0].min(q[0]), b[1].min(q[1]), b[2].max(q[0]), b[3].max(q[1])];
                }
                b
            }
        }
    }

    /// The cells whose centres the bounding box may hold, on a `cols × rows` grid of `cell`
    /// metres; empty when it misses the grid.
    pub fn cells(&self, cols: u32, rows: u32, cell: f64) -> Rect {
        let b = self.bounds();
        // Cell c's centre (c + ½)·s is in [x0, x1] for c in [x0/s − ½, x1/s − ½].
        let lo = |v: f64| (v / cell - 0.5).ceil().max(0.0);
        let hi = |v: f64, n: u32| (v / cell - 0.5).floor().min(f64::from(n) - 1.0);
        let (c0, c1) = (lo(b[0]), hi(b[2], cols));
        let (r0, r1) = (lo(b[1]), hi(b[3], rows));
        if !(c0 <= c1 && r0 <= r1) {
            return Rect::EMPTY;
        }
        // In range: clamped to [0, n − 1] above.
        Rect {
            c0: c0 as u32,
            r0: r0 as u32,
            width: (c1 - c0) as u32 + 1,
            height: (r1 - r0) as u32 + 1,
        }
    }

    /// Convex outlines whose union holds the polygon (the flanks' trapezoid, each fan wedge's
    /// outline): they bound the cells a row visits ([`span`]).
    pub fn outlines(&self) -> Vec<Vec<[f64; 2]>> {
        match self {
            Polygon::Flanks { p0, p1, z0, z1, tan } => {
                let d = [p1[0] - p0[0], p1[1] - p0[1]];
                let len = d[0].hypot(d[1]);
                if len == 0.0 {
                    return Vec::new();
                }
                let n = [-d[1] / len, d[0] / len];
                let (r0, r1) = (z0.max(0.0) / tan, z1.max(0.0) / tan);
                let at = |p: &[f64; 2], r: f64| [p[0] + n[0] * r, p[1] + n[1] * r];
                vec![vec![at(p0, r0), at(p1, r1), at(p1, -r1), at(p0, -r0)]]
            }
            Polygon::Fan { outlines, .. } => outlines.clone(),
        }
    }

    /// A form of the polygon that evaluates cells quickly.
    pub fn prepare(&self) -> Prepared {
        match self {
            Polygon::Flanks { p0, p1, z0, z1, tan } => {
                let d = [p1[0] - p0[0], p1[1] - p0[1]];
                let len2 = d[0] * d[0] + d[1] * d[1];
                Prepared::Flanks {
                    p0: *p0,
                    d,
                    inv_len2: if len2 > 0.0 { 1.0 / len2 } else { 0.0 },
                    inv_len: if len2 > 0.0 { 1.0 / len2.sqrt() } else { 0.0 },
                    z0: *z0,
                    dz: z1 - z0,
                    tan: *tan,
                    empty: len2 == 0.0,
                }
            }
            Polygon::Fan {
                apex, z, tan, wedges, ..
            } => Prepared::Fan {
                apex: *apex,
                z: *z,
                tan: *tan,
                reach2: (z / tan).powi(2),
                wedges: wedges
                    .iter()
                    .map(|&[from, to]| [[from.cos(), from.sin()], [to.cos(), to.sin()]])
                    .collect(),
            },
        }
    }
}

/// A polygon in the form [`Prepared::value`] reads.
#[derive(Debug, Clone)]
#[allow(missing_docs)] // the fields are the polygon's, precomputed.
pub enum Prepared {
    Flanks {
        p0: [f64; 2],
        d: [f64; 2],
        inv_len2: f64,
        inv_len: f64,
        z0: f64,
        dz: f64,
        tan: f64,
        empty: bool,
    },
    Fan {
        apex: [f64; 2],
        z: f64,
        tan: f64,
        /// The foot's radius squared.
        reach2: f64,
        /// Each wedge's bounding directions, unit vectors.
        wedges: Vec<[[f64; 2]; 2]>,
    },
}

impl Prepared {
    /// The polygon's elevation at ground point `q`, or `None` if `q` is outside it (or the
    /// polygon is below the ground there).
    #[inline]
    pub fn value(&self, q: [f64; 2]) -> Option<f64> {
        match self {
            Prepared::Flanks {
                p0,
                d,
                inv_len2,
                inv_len,
                z0,
                dz,
                tan,
                empty,
            } => {
                if *empty {
                    return None;
                }
                let v = [q[0] - p0[0], q[1] - p0[1]];
                let t = (v[0] * d[0] + v[1] * d[1]) * inv_len2;
                if !(0.0..=1.0).contains(&t) {
                    return None;
                }
                let r = (d[0] * v[1] - d[1] * v[0]).abs() * inv_len;
                let z = z0 + t * dz - r * tan;
                (z >= 0.0).then_some(z)
            }
            Prepared::Fan {
                apex,
                z,
                tan,
                reach2,
                wedges,
            } => {
                let w = [q[0] - apex[0], q[1] - apex[1]];
                let r2 = w[0] * w[0] + w[1] * w[1];
                // Within a wedge of at most 180°: counter-clockwise of `from`, clockwise of `to`.
                let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
                if r2 > *reach2
                    || !wedges
                        .iter()
                        .any(|&[from, to]| cross(from, w) >= 0.0 && cross(w, to) >= 0.0)
                {
                    return None;
                }
                let v = z - r2.sqrt() * tan;
                (v >= 0.0).then_some(v)
            }
        }
    }
}

/// The polygons of a skeleton, keyed by their part. Segments of zero horizontal length have no
/// flanks (their nodes' fans stand for them).
pub fn polygons(s: &Skeleton) -> Vec<(Part, Polygon)> {
    let tan = s.slope.tan();
    let mut out = Vec::with_capacity(s.edges.len() + s.nodes.len());
    // Directions leaving each node, as angles.
    let mut leaving: Vec<Vec<f64>> = vec![Vec::new(); s.nodes.len()];
    for (i, &[a, b]) in s.edges.iter().enumerate() {
        let (pa, pb) = (s.nodes[a as usize], s.nodes[b as usize]);
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        if d[0] == 0.0 && d[1] == 0.0 {
            continue;
        }
        leaving[a as usize].push(d[1].atan2(d[0]));
        leaving[b as usize].push((-d[1]).atan2(-d[0]));
        if pa[2] > 0.0 || pb[2] > 0.0 {
            out.push((
                Part::Edge(i as u32),
                Polygon::Flanks {
                    p0: [pa[0], pa[1]],
                    p1: [pb[0], pb[1]],
                    z0: pa[2],
                    z1: pb[2],
                    tan,
                },
            ));
        }
    }
    for (i, dirs) in leaving.iter_mut().enumerate() {
        let p = s.nodes[i];
        if p[2] <= 0.0 || dirs.is_empty() {
            continue;
        }
        let reach = p[2] / tan;
        dirs.sort_by(f64::total_cmp);
        let (mut outlines, mut wedges) = (Vec::new(), Vec::new());
        for k in 0..dirs.len() {
            let a = dirs[k];
            let gap = if dirs.len() == 1 {
                TAU
            } else if k + 1 < dirs.len() {
                dirs[k + 1] - a
            } else {
                dirs[0] + TAU - a
            };
            // The wedge from a's left flank (a + 90°) to the next direction's right flank.
            let wedge = gap - PI;
            if wedge <= 1e-12 {
                continue;
            }
            wedges.push([a + FRAC_PI_2, a + FRAC_PI_2 + wedge]);
            let n = (wedge / (PI / 6.0)).ceil().max(1.0) as usize;
            // Corners at R / cos(half the step): each edge between two touches the foot's circle,
            // so the outline holds the whole sector; convex, since the wedge is at most 180°.
            let out = reach / (wedge / n as f64 / 2.0).cos();
            let corner = |j: usize| {
                let ang = a + FRAC_PI_2 + wedge * j as f64 / n as f64;
                [p[0] + out * ang.cos(), p[1] + out * ang.sin()]
            };
            outlines.push(std::iter::once([p[0], p[1]]).chain((0..=n).map(corner)).collect());
        }
        if !outlines.is_empty() {
            out.push((
                Part::Node(i as u32),
                Polygon::Fan {
                    apex: [p[0], p[1]],
                    z: p[2],
                    tan,
                    wedges,
                    outlines,
                },
            ));
        }
    }
    out
}

/// The x-interval the convex `outlines` cover on the horizontal line at `y` (the hull of each
/// outline's interval), or `None` if the line misses them all.
pub fn span(outlines: &[Vec<[f64; 2]>], y: f64) -> Option<(f64, f64)> {
    let mut out: Option<(f64, f64)> = None;
    for o in outlines {
        for k in 0..o.len() {
            let (a, b) = (o[k], o[(k + 1) % o.len()]);
            let (lo, hi) = if a[1] <= b[1] { (a, b) } else { (b, a) };
            if y < lo[1] || y > hi[1] {
                continue;
            }
            let x = if hi[1] == lo[1] {
                // A horizontal edge on the line: both ends count.
                out = Some(out.map_or((lo[0].min(hi[0]), lo[0].max(hi[0])), |(x0, x1)| {
                    (x0.min(lo[0]).min(hi[0]), x1.max(lo[0]).max(hi[0]))
                }));
                continue;
            } else {
                lo[0] + (y - lo[1]) / (hi[1] - lo[1]) * (hi[0] - lo[0])
            };
            out = Some(out.map_or((x, x), |(x0, x1)| (x0.min(x), x1.max(x))));
        }
    }
    out
}
