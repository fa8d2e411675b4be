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
//! exact `orient2d`; the incircle test is its filter ([`super::predicates`]): an edge is flipped
//! only when that is certain, so the flips end and the result is Delaunay to within rounding,
//! cocircular cells included.

use robust::{Coord, orient2d};

use super::predicates::incircle;

const NONE: u32 = u32::MAX;
/// Edge indices one and two on from an edge (tables, not `% 3`: flips run a few dozen times a
/// rock).
const NEXT: [usize; 3] = [1, 2, 0];
const AFTER: [usize; 3] = [2, 0, 1];

fn c(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Triangles with their neighbours: `adj[t][e]` is across edge `e` = `(v[e], v[e+1])`.
struct Mesh<'a> {
    points: &'a [[f64; 2]],
    tri: &'a mut Vec<[u32; 3]>,
    adj: &'a mut Vec<[u32; 3]>,
}

/// Working memory for [`triangulate_with`], reused from one rock to the next (a field's rocks
/// would otherwise allocate and free it tens of thousands of times).
#[derive(Debug, Default)]
pub struct Scratch {
    tri: Vec<[u32; 3]>,
    adj: Vec<[u32; 3]>,
    stack: Vec<(u32, usize)>,
}

impl Mesh<'_> {
    fn p(&self, i: u32) -> Coord<f64> {
        c(self.points[i as usize])
    }

    /// Points the neighbour `n`'s pointer that was `from` at `to`.
    fn repoint(&mut self, n: u32, from: u32, to: u32) {
        if n != NONE
            && let Some(e) = self.adj[n as usize].iter().position(|&a| a == from)
        {
            self.adj[n as usize][e] = to;
        }
    }

    /// Flips edge `e` of `t` if the vertex across it lies inside `t`'s circumcircle. The flipped
    /// pair is `t = (a, q, p)`, `u = (q, b, p)` (`p` was `t`'s vertex facing the edge `(a, b)`,
    /// `q` the other's); returns `u`.
    fn legalize(&mut self, t: u32, e: usize) -> Option<u32> {
        let u = self.adj[t as usize][e];
        if u == NONE {
            return None;
        }
        let tt = self.tri[t as usize];
        let [a, b, p] = [tt[e], tt[NEXT[e]], tt[AFTER[e]]];
        let au = self.adj[u as usize];
        let f = if au[0] == t {
            0
        } else if au[1] == t {
            1
        } else if au[2] == t {
            2
        } else {
            return None;
        };
        let q = self.tri[u as usize][AFTER[f]];
        let pt = |i: u32| self.points[i as usize];
        if incircle(pt(a), pt(b), pt(p), pt(q)) <= 0.0 {
            return None;
        }
        let at = self.adj[t as usize];
        let (ta, tb) = (at[AFTER[e]], at[NEXT[e]]);
        let (ua, ub) = (au[NEXT[f]], au[AFTER[f]]);
        self.tri[t as usize] = [a, q, p];
        self.adj[t as usize] = [ua, u, ta];
        self.tri[u as usize] = [q, b, p];
        self.adj[u as usize] = [ub, tb, t];
        self.repoint(ua, u, t);
        self.repoint(tb, t, u);
        Some(u)
    }

    /// Flips until the edges on `stack` and those a flip exposes are locally Delaunay. After
    /// inserting a point `p` only the edges facing it need checking (Lawson); otherwise all
    /// four outer edges of a flipped pair.
    fn settle(&mut self, stack: &mut Vec<(u32, usize)>, inserting: bool) {
        while let Some((t, e)) = stack.pop() {
            if let Some(u) = self.legalize(t, e) {
                stack.push((t, 0));
                stack.push((u, 0));
                if !inserting {
                    stack.push((t, 2));
                    stack.push((u, 1));
                }
            }
        }
    }

    /// The triangle holding point `p` (inside the hull), walking from triangle `from` towards it
    /// across the edge it lies beyond; a full search if the walk goes on too long (it cannot
    /// loop in a Delaunay triangulation, but this one is Delaunay only to within rounding).
    fn locate(&self, from: u32, p: Coord<f64>) -> Option<u32> {
        let mut t = from;
        'walk: for _ in 0..self.tri.len() + 4 {
            let v = self.tri[t as usize];
            for e in 0..3 {
                let (a, b) = (v[e], v[NEXT[e]]);
                if orient2d(self.p(a), self.p(b), p) < 0.0 {
                    let n = self.adj[t as usize][e];
                    if n == NONE {
                        break 'walk;
                    }
                    t = n;
                    continue 'walk;
                }
            }
            return Some(t);
        }
        (0..self.tri.len() as u32).find(|&t| {
            let [a, b, c] = self.tri[t as usize];
            orient2d(self.p(a), self.p(b), p) >= 0.0
                && orient2d(self.p(b), self.p(c), p) >= 0.0
                && orient2d(self.p(c), self.p(a), p) >= 0.0
        })
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
    let Scratch { tri, adj, stack } = scratch;
    let mut m = Mesh { points, tri, adj };
    // The fan from vertex 0: triangle i is (0, i+1, i+2).
    let fan = hull - 2;
    for i in 0..fan {
        m.tri.push([0, i as u32 + 1, i as u32 + 2]);
        let before = if i == 0 { NONE } else { i as u32 - 1 };
        let after = if i + 1 == fan { NONE } else { i as u32 + 1 };
        m.adj.push([before, NONE, after]);
    }
    // Its diagonals: edge 2 of each triangle but the last.
    stack.extend((0..fan as u32 - 1).map(|t| (t, 2)));
    m.settle(stack, false);
    for v in hull..n {
        let v = v as u32;
        let last = m.tri.len() as u32 - 1;
        let Some(t) = m.locate(last, m.p(v)) else {
            continue;
        };
        let [a, b, cc] = m.tri[t as usize];
        let [na, nb, nc] = m.adj[t as usize];
        let (t1, t2) = (m.tri.len() as u32, m.tri.len() as u32 + 1);
        m.tri[t as usize] = [a, b, v];
        m.adj[t as usize] = [na, t1, t2];
        m.tri.push([b, cc, v]);
        m.adj.push([nb, t2, t]);
        m.tri.push([cc, a, v]);
        m.adj.push([nc, t, t1]);
        m.repoint(nb, t, t1);
        m.repoint(nc, t, t2);
        stack.extend([(t, 0), (t1, 0), (t2, 0)]);
        m.settle(stack, true);
    }
    &scratch.tri
}
