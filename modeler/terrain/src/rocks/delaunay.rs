//! The Delaunay triangulation of one rock: a convex cell's vertices and points strictly inside
//! it (the seed's fig. 8 c).
//!
//! Why not a general triangulator: a rock has about ten points and a field tens of thousands of
//! rocks, so the cost is per call, not per point. `delaunator` (fast, robust orientation) spent
//! about 1.8 µs a rock here, most of it setting up its hull structures and a dozen allocations;
//! this starts from the cell's fan, which is already a triangulation of the hull, inserts the
//! points by splitting the triangle holding each, and flips edges (Lawson) until every edge is
//! locally Delaunay, with two allocations — about 4 times faster on fig. 1
//! (`cargo bench -p penmodel-terrain --bench rocks -- delaunay`). The predicates are the
//! `robust` crate's exact `orient2d` and `incircle` (Shewchuk's adaptive arithmetic), so the
//! flips end, and the result is Delaunay, even for cocircular cell vertices; `incircle` goes
//! through [`super::predicates`], which skips `robust`'s costly set-up on the cocircular cells
//! that are common here and returns the same values.

use robust::{Coord, orient2d};

use super::predicates::incircle;

const NONE: u32 = u32::MAX;

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

    /// Flips edge `e` of `t` if the vertex across it lies inside `t`'s circumcircle; returns the
    /// two edges that became outer edges of the flipped pair, to be checked in turn.
    fn legalize(&mut self, t: u32, e: usize, stack: &mut Vec<(u32, usize)>) {
        let u = self.adj[t as usize][e];
        if u == NONE {
            return;
        }
        // Edge indices one and two on from `e` (a table, not `% 3`: this runs a few dozen
        // times per rock).
        const NEXT: [usize; 3] = [1, 2, 0];
        const AFTER: [usize; 3] = [2, 0, 1];
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
            return;
        };
        let q = self.tri[u as usize][AFTER[f]];
        let pt = |i: u32| self.points[i as usize];
        if incircle(pt(a), pt(b), pt(p), pt(q)) <= 0.0 {
            return;
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
        stack.push((t, 0));
        stack.push((u, 0));
    }

    fn settle(&mut self, stack: &mut Vec<(u32, usize)>) {
        while let Some((t, e)) = stack.pop() {
            self.legalize(t, e, stack);
        }
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
    for t in 0..fan as u32 {
        stack.push((t, 0));
        stack.push((t, 2));
    }
    m.settle(stack);
    for v in hull..n {
        let v = v as u32;
        let pv = m.p(v);
        let found = (0..m.tri.len()).find(|&t| {
            let [a, b, c] = m.tri[t];
            orient2d(m.p(a), m.p(b), pv) >= 0.0
                && orient2d(m.p(b), m.p(c), pv) >= 0.0
                && orient2d(m.p(c), m.p(a), pv) >= 0.0
        });
        let Some(t) = found else {
            continue;
        };
        let t = t as u32;
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
        m.settle(stack);
    }
    &scratch.tri
}
