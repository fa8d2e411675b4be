//! The Delaunay triangulation of one rock: a convex cell's vertices and points strictly inside
//! it (the seed's fig. 8 c).
//!
//! Why not a general triangulator: a rock has about ten points and a field tens of thousands of
//! rocks, so the cost is per call, not per point. `delaunator` (fast, robust orientation) spent
//! about 1.8 µs a rock here, most of it setting up its hull structures and a dozen allocations;
//! this starts from the cell's fan, which is already a triangulation of the hull, makes it
//! Delaunay by flipping edges (Lawson), then inserts the points one by one — walking from the
//! last new triangle to the one holding the point, splitting it in three, and flipping the edges
//! facing the point while they are not locally Delaunay — in memory reused from rock to rock
//! (`cargo bench -p penmodel-terrain --bench rocks -- delaunay`). Orientation is `robust`'s
//! exact `orient2d`; the incircle test is its filter (`super::predicates`): an edge is flipped
//! only when that is certain, so the flips end and the result is Delaunay to within rounding,
//! cocircular cells included.
//!
//! Each neighbour link names the triangle across an edge and that edge's index in it
//! (`4·triangle + edge`), so a flip finds its way back without searching. A rock of up to
//! `SMALL` triangles (hulls of up to 22 vertices with as many points inside: every rock of
//! the seed's figures) is triangulated in fixed arrays whose indices are masked to their size,
//! so no access is range-checked; larger ones run the same steps on growable lists.

use robust::{Coord, orient2d};

use super::predicates::incircle;

const NONE: u32 = u32::MAX;

/// Triangles (and points) of the fixed arrays: a power of two, so that masked indices are
/// always in range.
const SMALL: usize = 64;
/// Links waiting to be checked in the fixed arrays: more than Lawson's flips of a convex hull of
/// 22 vertices can push (at most 3 a flip, and at most one flip per pair of vertices: 3·231 + 19).
const STACK: usize = 1024;

fn c(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// A link to edge `e` of triangle `t`.
fn link(t: u32, e: usize) -> u32 {
    t << 2 | e as u32
}

/// Where a triangulation is kept: points, and per triangle its vertices (counter-clockwise) and
/// its links, across edge `e` = `(v[e], v[e+1])` ([`NONE`] on the hull); and the links waiting
/// to be checked.
trait Store {
    fn point(&self, i: u32) -> [f64; 2];
    /// Vertex `k` of triangle `t`, counting on past the third (`k` < 5: `k` and `k − 3` alike).
    fn vertex(&self, t: u32, k: usize) -> u32;
    /// The link across edge `k` of triangle `t`, `k` as in [`Store::vertex`].
    fn across(&self, t: u32, k: usize) -> u32;
    fn set(&mut self, t: u32, tri: [u32; 3], adj: [u32; 3]);
    /// Sets the link at `at` (itself a link: a triangle and edge) to `to`.
    fn relink(&mut self, at: u32, to: u32);
    fn push(&mut self, tri: [u32; 3], adj: [u32; 3]);
    fn count(&self) -> u32;
    fn push_edge(&mut self, l: u32);
    fn pop_edge(&mut self) -> Option<u32>;
}

/// Fixed arrays of [`SMALL`] points and triangles. A triangle's row holds its vertices from
/// slot 0 and its links from slot 8, each twice over (`v0 v1 v2 v0 v1`), so that an edge's
/// start, end and opposite vertex are slots `e`, `e + 1`, `e + 2` without wrapping; every index
/// is masked to its array, so no access is range-checked.
#[derive(Debug)]
struct Small {
    points: [[f64; 2]; SMALL],
    rows: [[u32; 16]; SMALL],
    count: u32,
    stack: [u32; STACK],
    depth: usize,
}

impl Default for Small {
    fn default() -> Small {
        Small {
            points: [[0.0; 2]; SMALL],
            rows: [[NONE; 16]; SMALL],
            count: 0,
            stack: [0; STACK],
            depth: 0,
        }
    }
}

fn at(i: u32) -> usize {
    i as usize & (SMALL - 1)
}

impl Store for Small {
    #[inline(always)]
    fn point(&self, i: u32) -> [f64; 2] {
        self.points[at(i)]
    }
    #[inline(always)]
    fn vertex(&self, t: u32, k: usize) -> u32 {
        self.rows[at(t)][k & 7]
    }
    #[inline(always)]
    fn across(&self, t: u32, k: usize) -> u32 {
        self.rows[at(t)][8 + (k & 7)]
    }
    #[inline(always)]
    fn set(&mut self, t: u32, [v0, v1, v2]: [u32; 3], [a0, a1, a2]: [u32; 3]) {
        let row = &mut self.rows[at(t)];
        row[..5].copy_from_slice(&[v0, v1, v2, v0, v1]);
        row[8..13].copy_from_slice(&[a0, a1, a2, a0, a1]);
    }
    #[inline(always)]
    fn relink(&mut self, link: u32, to: u32) {
        if link != NONE {
            // The link and its copy three on (slot 8 + 5, past the copies, when e = 2).
            let (row, e) = (&mut self.rows[at(link >> 2)], link as usize & 3);
            row[8 + e] = to;
            row[(11 + e) & 15] = to;
        }
    }
    #[inline(always)]
    fn push(&mut self, tri: [u32; 3], adj: [u32; 3]) {
        self.set(self.count, tri, adj);
        self.count += 1;
    }
    #[inline(always)]
    fn count(&self) -> u32 {
        self.count
    }
    #[inline(always)]
    fn push_edge(&mut self, l: u32) {
        debug_assert!(self.depth < STACK);
        self.stack[self.depth & (STACK - 1)] = l;
        self.depth += 1;
    }
    #[inline(always)]
    fn pop_edge(&mut self) -> Option<u32> {
        if self.depth == 0 {
            return None;
        }
        self.depth -= 1;
        Some(self.stack[self.depth & (STACK - 1)])
    }
}

/// `k` and `k − 3` alike, for `k` < 5.
const WRAP: [usize; 5] = [0, 1, 2, 0, 1];

/// Growable lists, for rocks too large for [`Small`].
struct Large<'a> {
    points: &'a [[f64; 2]],
    tri: &'a mut Vec<[u32; 3]>,
    adj: &'a mut Vec<[u32; 3]>,
    stack: &'a mut Vec<u32>,
}

impl Store for Large<'_> {
    fn point(&self, i: u32) -> [f64; 2] {
        self.points[i as usize]
    }
    fn vertex(&self, t: u32, k: usize) -> u32 {
        self.tri[t as usize][WRAP[k]]
    }
    fn across(&self, t: u32, k: usize) -> u32 {
        self.adj[t as usize][WRAP[k]]
    }
    fn set(&mut self, t: u32, tri: [u32; 3], adj: [u32; 3]) {
        self.tri[t as usize] = tri;
        self.adj[t as usize] = adj;
    }
    fn relink(&mut self, link: u32, to: u32) {
        if link != NONE {
            self.adj[(link >> 2) as usize][link as usize & 3] = to;
        }
    }
    fn push(&mut self, tri: [u32; 3], adj: [u32; 3]) {
        self.tri.push(tri);
        self.adj.push(adj);
    }
    fn count(&self) -> u32 {
        self.tri.len() as u32
    }
    fn push_edge(&mut self, l: u32) {
        self.stack.push(l);
    }
    fn pop_edge(&mut self) -> Option<u32> {
        self.stack.pop()
    }
}

/// Working memory for [`triangulate_with`], reused from one rock to the next (a field's rocks
/// would otherwise allocate and free it tens of thousands of times).
#[derive(Debug, Default)]
pub struct Scratch {
    small: Box<Small>,
    tri: Vec<[u32; 3]>,
    adj: Vec<[u32; 3]>,
    /// Links (triangle and edge) to check.
    stack: Vec<u32>,
}

/// Flips edge `e` of `t` if the vertex across it lies inside `t`'s circumcircle. The flipped
/// pair is `t = (a, q, p)`, `u = (q, b, p)` (`p` was `t`'s vertex facing the edge `(a, b)`,
/// `q` the other's); returns `u` and the links now across `t`'s edges 0 and 2 and `u`'s edges 0
/// and 1 (the pair's outer edges).
#[inline(always)]
fn legalize<S: Store>(m: &mut S, t: u32, e: usize) -> Option<(u32, [u32; 4])> {
    let across = m.across(t, e);
    if across == NONE {
        return None;
    }
    let (u, f) = (across >> 2, across as usize & 3);
    if f > 2 {
        return None;
    }
    let [a, b, p] = [m.vertex(t, e), m.vertex(t, e + 1), m.vertex(t, e + 2)];
    let q = m.vertex(u, f + 2);
    if incircle(m.point(a), m.point(b), m.point(p), m.point(q)) <= 0.0 {
        return None;
    }
    let (ta, tb) = (m.across(t, e + 2), m.across(t, e + 1));
    let (ua, ub) = (m.across(u, f + 1), m.across(u, f + 2));
    m.set(t, [a, q, p], [ua, link(u, 2), ta]);
    m.set(u, [q, b, p], [ub, tb, link(t, 1)]);
    m.relink(ua, link(t, 0));
    m.relink(ta, link(t, 2));
    m.relink(ub, link(u, 0));
    m.relink(tb, link(u, 1));
    Some((u, [ua, ta, ub, tb]))
}

/// Flips until the edges waiting and those a flip exposes are locally Delaunay. After
/// inserting a point `p` only the edges facing it need checking (Lawson); otherwise all
/// four outer edges of a flipped pair. Edges on the hull are never pushed (they cannot flip).
#[inline(always)]
fn settle<S: Store>(m: &mut S, inserting: bool) {
    while let Some(l) = m.pop_edge() {
        let (t, e) = (l >> 2, l as usize & 3);
        if e > 2 {
            continue;
        }
        if let Some((u, [t0, t2, u0, u1])) = legalize(m, t, e) {
            push_inner(m, t0, link(t, 0));
            push_inner(m, u0, link(u, 0));
            if !inserting {
                push_inner(m, t2, link(t, 2));
                push_inner(m, u1, link(u, 1));
            }
        }
    }
}

/// Pushes `edge` unless what lies across it, `across`, is nothing (the hull).
#[inline(always)]
fn push_inner<S: Store>(m: &mut S, across: u32, edge: u32) {
    if across != NONE {
        m.push_edge(edge);
    }
}

/// The triangle holding point `p` (inside the hull), walking from triangle `from` towards it
/// across the edge it lies beyond; a full search if the walk goes on too long (it cannot
/// loop in a Delaunay triangulation, but this one is Delaunay only to within rounding).
#[inline(always)]
fn locate<S: Store>(m: &S, from: u32, p: Coord<f64>) -> Option<u32> {
    let mut t = from;
    'walk: for _ in 0..m.count() + 4 {
        for e in 0..3 {
            let (a, b) = (m.vertex(t, e), m.vertex(t, e + 1));
            if orient2d(c(m.point(a)), c(m.point(b)), p) < 0.0 {
                let n = m.across(t, e);
                if n == NONE {
                    break 'walk;
                }
                t = n >> 2;
                continue 'walk;
            }
        }
        return Some(t);
    }
    (0..m.count()).find(|&t| {
        let [a, b, cc] = [0, 1, 2].map(|k| c(m.point(m.vertex(t, k))));
        orient2d(a, b, p) >= 0.0 && orient2d(b, cc, p) >= 0.0 && orient2d(cc, a, p) >= 0.0
    })
}

/// The steps on any store holding the points: the fan, its flips, then each point inserted.
fn run<S: Store>(m: &mut S, hull: usize, n: usize) {
    // The fan from vertex 0: triangle i is (0, i+1, i+2), its edge 0 shared with the one
    // before and its edge 2 with the one after.
    let fan = hull - 2;
    for i in 0..fan {
        let before = if i == 0 { NONE } else { link(i as u32 - 1, 2) };
        let after = if i + 1 == fan { NONE } else { link(i as u32 + 1, 0) };
        m.push([0, i as u32 + 1, i as u32 + 2], [before, NONE, after]);
    }
    // Its diagonals: edge 2 of each triangle but the last.
    for t in 0..fan as u32 - 1 {
        m.push_edge(link(t, 2));
    }
    settle(m, false);
    for v in hull..n {
        let v = v as u32;
        let last = m.count() - 1;
        let Some(t) = locate(m, last, c(m.point(v))) else {
            continue;
        };
        let [a, b, cc] = [0, 1, 2].map(|k| m.vertex(t, k));
        let [na, nb, nc] = [0, 1, 2].map(|k| m.across(t, k));
        let (t1, t2) = (m.count(), m.count() + 1);
        m.set(t, [a, b, v], [na, link(t1, 2), link(t2, 1)]);
        m.push([b, cc, v], [nb, link(t2, 2), link(t, 1)]);
        m.push([cc, a, v], [nc, link(t, 2), link(t1, 1)]);
        m.relink(nb, link(t1, 0));
        m.relink(nc, link(t2, 0));
        push_inner(m, na, link(t, 0));
        push_inner(m, nb, link(t1, 0));
        push_inner(m, nc, link(t2, 0));
        settle(m, true);
    }
}

/// Triangles (vertex indices, counter-clockwise: positive area in (x, y)) of the Delaunay
/// triangulation of `points`, whose first `hull` points are a convex polygon with positive area
/// in order and whose others lie strictly inside it. Empty when `hull < 3`.
pub fn triangulate(points: &[[f64; 2]], hull: usize) -> Vec<[u32; 3]> {
    triangulate_with(points, hull, &mut Scratch::default()).to_vec()
}

/// [`triangulate`] in `scratch`'s memory; the triangles are valid until its next use.
pub fn triangulate_with<'a>(points: &[[f64; 2]], hull: usize, scratch: &'a mut Scratch) -> &'a [[u32; 3]] {
    scratch.tri.clear();
    scratch.adj.clear();
    scratch.stack.clear();
    if hull < 3 {
        return &scratch.tri;
    }
    let n = points.len();
    let Scratch { small, tri, adj, stack } = scratch;
    // Triangles at the end: 2n − hull − 2.
    if n <= SMALL && 2 * n - hull - 2 <= SMALL {
        small.points[..n].copy_from_slice(points);
        small.count = 0;
        small.depth = 0;
        run(&mut **small, hull, n);
        tri.extend(small.rows[..small.count as usize].iter().map(|r| [r[0], r[1], r[2]]));
    } else {
        run(
            &mut Large {
                points,
                tri,
                adj,
                stack,
            },
            hull,
            n,
        );
    }
    &scratch.tri
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A convex polygon of `k` vertices (counter-clockwise) about `(cx, cy)` and `k` points
    /// strictly inside it.
    fn rock(k: usize, rng: &mut ChaCha8Rng) -> Vec<[f64; 2]> {
        let mut angles: Vec<f64> = (0..k).map(|_| rng.random::<f64>() * std::f64::consts::TAU).collect();
        angles.sort_by(f64::total_cmp);
        angles.dedup();
        let mut pts: Vec<[f64; 2]> = angles
            .iter()
            .map(|a| [10.0 + 5.0 * a.cos(), 10.0 + 5.0 * a.sin()])
            .collect();
        let hull = pts.len();
        // Points inside: convex combinations of the hull's vertices, pulled a little inwards.
        for _ in 0..hull {
            let w: Vec<f64> = (0..hull).map(|_| rng.random::<f64>() + 1e-3).collect();
            let s: f64 = w.iter().sum();
            let p = (0..hull).fold([0.0, 0.0], |p, i| {
                [p[0] + pts[i][0] * w[i] / s, p[1] + pts[i][1] * w[i] / s]
            });
            pts.push(p);
        }
        pts
    }

    /// The circumcircle test of the tests' own: positive when `d` is inside the circle through
    /// `a`, `b`, `c` (counter-clockwise), in f64 from the centre and radius.
    fn inside_circumcircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
        let dd = 2.0 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]));
        let l = |p: [f64; 2]| p[0] * p[0] + p[1] * p[1];
        let ux = (l(a) * (b[1] - c[1]) + l(b) * (c[1] - a[1]) + l(c) * (a[1] - b[1])) / dd;
        let uy = (l(a) * (c[0] - b[0]) + l(b) * (a[0] - c[0]) + l(c) * (b[0] - a[0])) / dd;
        let r2 = (a[0] - ux).powi(2) + (a[1] - uy).powi(2);
        r2 - ((d[0] - ux).powi(2) + (d[1] - uy).powi(2))
    }

    /// Hulls of 3 to 40 vertices (both stores: fixed arrays up to 22, lists above): every
    /// triangle counter-clockwise, 2n − h − 2 of them covering the hull's area, and none whose
    /// circumcircle holds another point; the fixed arrays give what the lists give.
    #[test]
    fn rocks_of_every_size_are_delaunay_in_both_stores() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for round in 0..400 {
            let k = 3 + round % 38;
            let pts = rock(k, &mut rng);
            // The hull (k vertices unless two angles fell together) and as many inside.
            let hull = pts.len() / 2;
            let tris = triangulate(&pts, hull);
            let n = pts.len();
            assert_eq!(tris.len(), 2 * n - hull - 2, "k {k}");
            let area = |t: &[u32; 3]| {
                let [a, b, c] = t.map(|i| pts[i as usize]);
                ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) * 0.5
            };
            let hull_area: f64 = (1..hull - 1).map(|i| area(&[0, i as u32, i as u32 + 1])).sum();
            let sum: f64 = tris.iter().map(area).sum();
            assert!(tris.iter().all(|t| area(t) > 0.0), "k {k}");
            assert!(
                (sum - hull_area).abs() < 1e-9 * hull_area,
                "k {k}: {sum} vs {hull_area}"
            );
            for t in &tris {
                let [a, b, c] = t.map(|i| pts[i as usize]);
                for (i, &p) in pts.iter().enumerate() {
                    if !t.contains(&(i as u32)) {
                        assert!(inside_circumcircle(a, b, c, p) < 1e-9, "k {k}: point {i} in {t:?}");
                    }
                }
            }
            let mut tri = Vec::new();
            let mut adj = Vec::new();
            let mut stack = Vec::new();
            run(
                &mut Large {
                    points: &pts,
                    tri: &mut tri,
                    adj: &mut adj,
                    stack: &mut stack,
                },
                hull,
                n,
            );
            assert_eq!(tri, tris, "k {k}");
        }
    }
}
