//! A rock's shape from its cell (the seed's section 3.3, fig. 8): as many random points inside
//! the cell as it has vertices, a Delaunay triangulation of the cell's vertices and those points,
//! then each added point moved out from (or in towards) their centroid by eq. 2 and raised by
//! eq. 3. The cell's own vertices stay on the ground, so the rock's rim is its cell.
//!
//! Readings where the seed is silent: `j1` and `j2` are uniform in [0, 1), so the seed's
//! presets all give rocks that stand up (`c_h ≥ 0`); eq. 2 prints no unit, and here it is scaled
//! by the radius like eq. 3 (`t_xy` in units of r), because the seed's fig. 11 shows a visible
//! widening at r = 9 and says points may move out of the cell; a contraction stops at the
//! centroid rather than passing through it.

use rand::{Rng, RngExt};

/// Coefficients of eq. 2 (`c_w1..3`, widths) and eq. 3 (`c_h1..3`, heights).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// `c_w1, c_w2, c_w3`: constant, per-rock and per-vertex parts of the sideways move (× r).
    pub widths: [f64; 3],
    /// `c_h1, c_h2, c_h3`: constant, per-rock and per-vertex parts of the height (× r).
    pub heights: [f64; 3],
}

impl Shape {
    /// The seed's defaults (table 1, fig. 9): no sideways move, height `0.3·r + 0.1·r·j2`.
    pub const DEFAULT: Shape = Shape {
        widths: [0.0, 0.0, 0.0],
        heights: [0.3, 0.0, 0.1],
    };
}

/// One rock's mesh in field coordinates (cells; z up, in cells), borrowed from its scatter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RockMesh<'a> {
    /// The added points where they were drawn, before eq. 2 and 3.
    pub added: &'a [[f64; 2]],
    /// The cell's vertices (z = 0), then the added points moved and raised.
    pub vertices: &'a [[f64; 3]],
    /// Triangles as vertex indices, clockwise in (x, y) — counter-clockwise seen from above when
    /// y is drawn downwards or mapped to the exports' Z with Y up.
    pub triangles: &'a [[u32; 3]],
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// A uniformly random point of the convex polygon `cell`, given its fan's cumulative areas.
fn inside(cell: &[[f64; 2]], fan: &[f64], rng: &mut impl Rng) -> [f64; 2] {
    let total = fan[fan.len() - 1];
    let pick = rng.random::<f64>() * total;
    let t = fan.iter().position(|&a| pick < a).unwrap_or(fan.len() - 1);
    let (a, b, c) = (cell[0], cell[t + 1], cell[t + 2]);
    let (mut u, mut v) = (rng.random::<f64>(), rng.random::<f64>());
    if u + v > 1.0 {
        (u, v) = (1.0 - u, 1.0 - v);
    }
    [
        a[0] + u * (b[0] - a[0]) + v * (c[0] - a[0]),
        a[1] + u * (b[1] - a[1]) + v * (c[1] - a[1]),
    ]
}

/// The rock of convex cell `cell` (at least 3 vertices) of a diagram of radius `radius`,
/// appended to `block`'s added points, vertices and triangles (the caller closes it).
pub(crate) fn rock_into(cell: &[[f64; 2]], radius: f64, shape: &Shape, rng: &mut impl Rng, block: Out<'_>) {
    SCRATCH.with_borrow_mut(|scratch| rock_with(cell, radius, shape, rng, scratch, block))
}

/// Where [`rock_into`] writes.
pub(crate) struct Out<'a> {
    pub(crate) added: &'a mut Vec<[f64; 2]>,
    pub(crate) vertices: &'a mut Vec<[f64; 3]>,
    pub(crate) triangles: &'a mut Vec<[u32; 3]>,
}

/// Working memory of [`rock_into`], one per thread.
#[derive(Debug, Default)]
struct Scratch {
    fan: Vec<f64>,
    points: Vec<[f64; 2]>,
    delaunay: super::delaunay::Scratch,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

fn rock_with(cell: &[[f64; 2]], radius: f64, shape: &Shape, rng: &mut impl Rng, scratch: &mut Scratch, out: Out<'_>) {
    let k = cell.len();
    let fan = &mut scratch.fan;
    fan.clear();
    let mut sum = 0.0;
    for t in 0..k.saturating_sub(2) {
        sum += cross(cell[0], cell[t + 1], cell[t + 2]).abs() * 0.5;
        fan.push(sum);
    }
    let first = out.added.len();
    if sum > 0.0 {
        out.added.extend((0..k).map(|_| inside(cell, fan, rng)));
    }
    let added = &out.added[first..];
    if !added.is_empty() {
        let points = &mut scratch.points;
        points.clear();
        points.extend(cell.iter().chain(added));
        // Counter-clockwise in (x, y) from the triangulation; turned clockwise (see `triangles`).
        out.triangles.extend(
            super::delaunay::triangulate_with(points, k, &mut scratch.delaunay)
                .iter()
                .map(|&[a, b, c]| [a, c, b]),
        );
    }
    let n = added.len().max(1) as f64;
    let g = added.iter().fold([0.0, 0.0], |g, p| [g[0] + p[0] / n, g[1] + p[1] / n]);
    let j1: f64 = rng.random();
    out.vertices.extend(cell.iter().map(|p| [p[0], p[1], 0.0]));
    for p in added {
        let j2: f64 = rng.random();
        let [w1, w2, w3] = shape.widths;
        let [h1, h2, h3] = shape.heights;
        let t_xy = (w1 + w2 * j1 + w3 * j2) * radius;
        let t_z = (h1 + h2 * j1 + h3 * j2) * radius;
        let d = [p[0] - g[0], p[1] - g[1]];
        let len = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let q = if len > 0.0 {
            let to = (len + t_xy).max(0.0) / len;
            [g[0] + d[0] * to, g[1] + d[1] * to]
        } else {
            *p
        };
        out.vertices.push([q[0], q[1], t_z]);
    }
}
