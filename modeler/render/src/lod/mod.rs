//! Level of detail for the heightfield (issue 18): a quadtree of nodes over the grid, each drawn
//! as [`NODE`] × [`NODE`] quads at a stride of `2^level` cells, chosen per frame by its error on
//! screen, so that a frame's cost follows the pixels, not the cells.
//!
//! - **The pyramid** ([`Pyramid`]): level 0 nodes are [`NODE`]² quads of the full grid; a node of
//!   level `L` covers `NODE·2^L` quads a side and samples every `2^L`-th vertex (plus the grid's
//!   last column and row, so every level ends where the grid does). Each node keeps the range of
//!   its heights (for culling) and its geometric error: the largest vertical distance between a
//!   full-grid vertex inside it and the node's decimated surface (its coarse quads split along the
//!   same diagonal as the full grid's), made monotone (a node's error is at least its children's),
//!   so an accepted node never hides a larger error in a child. It is built once per grid and
//!   updated only over the nodes whose cells a change rectangle touches ([`Pyramid::update`]).
//! - **Choosing** ([`Pyramid::select`]): from the root, a node whose box lies outside one plane of
//!   the view frustum is dropped; a node is drawn when its error projects to at most `τ` pixels
//!   ([`Bound::pixels`]: a vertical offset `e` at depth `w` moves a vertex by at most
//!   `e·|(|dX| + |x|·|dw|, |dY| + |y|·|dw|)| / (w − e·|dw|)` pixels, `d·` the clip coordinates'
//!   change per metre of height, `x, y` the farthest pixel of the viewport from the origin), else
//!   its four children are looked at. Level 0 is always drawn. Nodes holding a non-finite height
//!   are always split down to level 0, where the hole rule applies as in full detail.
//! - **No cracks: stitching.** Two nodes of the same level share their edge vertices (the same
//!   inputs give the same bits, so the rasteriser is watertight between them). Where a node meets
//!   a coarser one, its edge vertices that the coarser node lacks are collapsed onto the coarser
//!   node's vertices (each onto the one before it along the edge): the triangles touching the edge
//!   then use the coarser node's edge exactly, and the ones collapsed to nothing have zero area and
//!   are not drawn. This needs a node's corners to be vertices of its neighbours, which holds when
//!   neighbours differ by at most [`MAX_STEP`] levels (a stride ratio of at most [`NODE`]); the
//!   choice is refined until they do. No skirts: they would cover cracks only approximately.
//! - The choice per node ([`Pick`]) is data: the landscape tools' meshes may use [`Pyramid::select`]
//!   to pick their own levels later.

pub(crate) mod nodes;
pub(crate) mod reproject;

use rayon::prelude::*;

use crate::raster::rasterise::Bounds;
use crate::raster::transform::{Affine, CHUNK};
use penmodel_terrain::Heightmap;

/// Quads per node side at every level.
pub(crate) const NODE: usize = CHUNK;

/// The largest level difference between neighbouring nodes: `2^MAX_STEP` = [`NODE`], so a node's
/// corners lie on its coarser neighbours' vertices.
pub(crate) const MAX_STEP: u32 = 4;

/// The default largest error on screen, pixels ([`crate::Scene::terrain_lod`]).
pub const DEFAULT_PIXELS: f32 = 1.0;

/// A node's heights and error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Lowest finite height of its vertices (+∞ if none).
    pub min: f32,
    /// Highest finite height of its vertices (−∞ if none).
    pub max: f32,
    /// The largest vertical distance, metres of height (before the vertical scale), between the
    /// full grid and this node's decimated surface, or any of its descendants'; +∞ when a height
    /// inside is not finite.
    pub error: f32,
}

const EMPTY: Node = Node {
    min: f32::INFINITY,
    max: f32::NEG_INFINITY,
    error: 0.0,
};

#[derive(Debug, Default)]
struct Level {
    nx: usize,
    ny: usize,
    nodes: Vec<Node>,
}

/// A node chosen for drawing: its level and its column and row among that level's nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pick {
    /// The level: the node samples every `2^level`-th vertex.
    pub level: u32,
    /// Node column.
    pub i: u32,
    /// Node row.
    pub j: u32,
}

/// The vertices a node covers: columns `c0..=c1`, rows `r0..=r1`, sampled every `step`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Area {
    /// First vertex column.
    pub c0: usize,
    /// Last vertex column.
    pub c1: usize,
    /// First vertex row.
    pub r0: usize,
    /// Last vertex row.
    pub r1: usize,
    /// Cells between sampled vertices.
    pub step: usize,
}

impl Area {
    /// Quads across and down.
    pub fn quads(&self) -> (usize, usize) {
        (
            (self.c1 - self.c0).div_ceil(self.step),
            (self.r1 - self.r0).div_ceil(self.step),
        )
    }

    /// The grid column of the node's `k`-th sampled column.
    #[inline]
    pub fn col(&self, k: usize) -> usize {
        (self.c0 + k * self.step).min(self.c1)
    }

    /// The grid row of the node's `k`-th sampled row.
    #[inline]
    pub fn row(&self, k: usize) -> usize {
        (self.r0 + k * self.step).min(self.r1)
    }
}

/// The quadtree of a heightmap's levels of detail.
#[derive(Debug, Default)]
pub struct Pyramid {
    cols: usize,
    rows: usize,
    cell: f64,
    levels: Vec<Level>,
    /// Cells visited by builds and updates since the pyramid was made (the bench and a test read
    /// it: a frame whose terrain did not change visits none).
    visited: u64,
}

/// How to project a node's error: [`Bound::pixels`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bound {
    /// `|(|dX| + |x|·|dw|, |dY| + |y|·|dw|)|`.
    k: f32,
    /// `|dw|`: clip depth per metre of height.
    dw: f32,
}

impl Bound {
    /// The bound for `affine` drawn into `viewport`.
    pub(crate) fn new(affine: &Affine, viewport: Bounds) -> Bound {
        let d = affine.height_axis();
        let x = viewport.x0.unsigned_abs().max(viewport.x1.unsigned_abs()) as f32;
        let y = viewport.y0.unsigned_abs().max(viewport.y1.unsigned_abs()) as f32;
        let dw = d[2].abs();
        let (a, b) = (d[0].abs() + x * dw, d[1].abs() + y * dw);
        Bound {
            k: (a * a + b * b).sqrt(),
            dw,
        }
    }

    /// The most pixels a vertical offset of `e` metres of height moves a point at depth `w` or
    /// more: +∞ when the offset may reach the eye's plane.
    #[inline]
    pub(crate) fn pixels(&self, e: f32, w: f32) -> f32 {
        if e <= 0.0 {
            return 0.0;
        }
        let d = w - e * self.dw;
        if d <= 0.0 { f32::INFINITY } else { e * self.k / d }
    }
}

impl Pyramid {
    /// The pyramid of `map`.
    pub fn new(map: &Heightmap) -> Pyramid {
        let mut p = Pyramid::default();
        p.build(map);
        p
    }

    /// Whether it was built for a grid of `map`'s size and cell.
    pub fn fits(&self, map: &Heightmap) -> bool {
        self.cols == map.cols() as usize && self.rows == map.rows() as usize && self.cell == map.cell_size()
    }

    /// Cells visited by builds and updates so far.
    pub fn visited(&self) -> u64 {
        self.visited
    }

    /// Levels, level 0 first.
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Node `(i, j)` of `level`.
    pub fn node(&self, level: u32, i: u32, j: u32) -> Option<Node> {
        let l = self.levels.get(level as usize)?;
        if i as usize >= l.nx || j as usize >= l.ny {
            return None;
        }
        Some(l.nodes[j as usize * l.nx + i as usize])
    }

    /// The vertices node `(i, j)` of `level` covers.
    pub fn area(&self, level: u32, i: u32, j: u32) -> Area {
        let span = NODE << level;
        let (c0, r0) = (i as usize * span, j as usize * span);
        Area {
            c0,
            c1: (c0 + span).min(self.cols - 1),
            r0,
            r1: (r0 + span).min(self.rows - 1),
            step: 1 << level,
        }
    }

    /// Rebuilds every node of `map`.
    pub fn build(&mut self, map: &Heightmap) {
        let (cols, rows) = (map.cols() as usize, map.rows() as usize);
        self.cols = cols;
        self.rows = rows;
        self.cell = map.cell_size();
        self.levels.clear();
        if cols < 2 || rows < 2 {
            return;
        }
        let mut level = 0u32;
        loop {
            let span = NODE << level;
            let (nx, ny) = ((cols - 1).div_ceil(span), (rows - 1).div_ceil(span));
            self.levels.push(Level {
                nx,
                ny,
                nodes: vec![EMPTY; nx * ny],
            });
            if nx == 1 && ny == 1 {
                break;
            }
            level += 1;
        }
        self.update(map, (0, cols, 0, rows));
    }

    /// Brings the nodes up to date after the heights of columns `c0..c1`, rows `r0..r1` changed
    /// (rebuilds all of it if `map` is not the grid it was built for).
    pub fn update(&mut self, map: &Heightmap, (c0, c1, r0, r1): (usize, usize, usize, usize)) {
        if !self.fits(map) {
            self.build(map);
            return;
        }
        let (c1, r1) = (c1.min(self.cols), r1.min(self.rows));
        if c0 >= c1 || r0 >= r1 || self.levels.is_empty() {
            return;
        }
        let h = map.heights();
        let cols = self.cols;
        for level in 0..self.levels.len() {
            let span = NODE << level;
            let (below, above) = self.levels.split_at_mut(level);
            let this = &mut above[0];
            let children = below.last();
            // A vertex on a node's edge belongs to both nodes beside it.
            let (i0, i1) = (c0.saturating_sub(1) / span, ((c1 - 1) / span).min(this.nx - 1));
            let (j0, j1) = (r0.saturating_sub(1) / span, ((r1 - 1) / span).min(this.ny - 1));
            let nx = this.nx;
            let (tc, tr) = (self.cols, self.rows);
            let visited: u64 = this
                .nodes
                .par_chunks_mut(nx)
                .enumerate()
                .skip(j0)
                .take(j1 + 1 - j0)
                .map(|(j, line)| {
                    let mut visited = 0u64;
                    for (i, node) in line.iter_mut().enumerate().take(i1 + 1).skip(i0) {
                        let span_c0 = i * span;
                        let span_r0 = j * span;
                        let area = Area {
                            c0: span_c0,
                            c1: (span_c0 + span).min(tc - 1),
                            r0: span_r0,
                            r1: (span_r0 + span).min(tr - 1),
                            step: 1 << level,
                        };
                        visited += ((area.c1 - area.c0 + 1) * (area.r1 - area.r0 + 1)) as u64;
                        *node = match children {
                            None => leaf(h, cols, &area),
                            Some(kids) => parent(h, cols, &area, kids, (i, j)),
                        };
                    }
                    visited
                })
                .sum();
            self.visited += visited;
        }
    }

    /// The nodes to draw for a view: those not outside the frustum of `affine` (near plane `near`,
    /// drawing into `viewport`), each at the coarsest level whose error is at most `pixels` on
    /// screen, neighbours at most [`MAX_STEP`] levels apart. `pixels` ≤ 0 picks level 0 (full
    /// detail). `out` is cleared first.
    pub fn select(&self, affine: &Affine, near: f32, viewport: Bounds, pixels: f32, out: &mut Vec<Pick>) {
        out.clear();
        let Some(top) = self.levels.len().checked_sub(1) else {
            return;
        };
        let view = Frustum {
            affine,
            near,
            viewport,
            bound: Bound::new(affine, viewport),
        };
        let top = top as u32;
        let root = self.levels[top as usize].nx * self.levels[top as usize].ny;
        for k in 0..root as u32 {
            let nx = self.levels[top as usize].nx as u32;
            self.visit(&view, pixels, top, k % nx, k / nx, out);
        }
        self.restrict(&view, out);
    }

    fn visit(&self, view: &Frustum, pixels: f32, level: u32, i: u32, j: u32, out: &mut Vec<Pick>) {
        let node = self.levels[level as usize].nodes[j as usize * self.levels[level as usize].nx + i as usize];
        let area = self.area(level, i, j);
        let Some(w) = view.nearest(&node, &area) else {
            return;
        };
        if level == 0 || (pixels > 0.0 && view.bound.pixels(node.error, w) <= pixels) {
            out.push(Pick { level, i, j });
            return;
        }
        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (ci, cj) = (2 * i + di, 2 * j + dj);
            let below = &self.levels[level as usize - 1];
            if (ci as usize) < below.nx && (cj as usize) < below.ny {
                self.visit(view, pixels, level - 1, ci, cj, out);
            }
        }
    }

    /// Splits chosen nodes until no two neighbours are more than [`MAX_STEP`] levels apart.
    fn restrict(&self, view: &Frustum, picks: &mut Vec<Pick>) {
        let mut map = Levels::default();
        loop {
            map.fill(self, picks);
            let mut split = false;
            let mut next = Vec::with_capacity(picks.len());
            for p in picks.iter() {
                let finest = map.finest_around(p);
                if finest.is_some_and(|f| p.level > f + MAX_STEP) {
                    split = true;
                    for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let (ci, cj) = (2 * p.i + di, 2 * p.j + dj);
                        let below = &self.levels[p.level as usize - 1];
                        if (ci as usize) < below.nx && (cj as usize) < below.ny {
                            let node = below.nodes[cj as usize * below.nx + ci as usize];
                            if view.nearest(&node, &self.area(p.level - 1, ci, cj)).is_some() {
                                next.push(Pick {
                                    level: p.level - 1,
                                    i: ci,
                                    j: cj,
                                });
                            }
                        }
                    }
                } else {
                    next.push(*p);
                }
            }
            *picks = next;
            if !split {
                return;
            }
        }
    }
}

/// Level 0: the range of the heights, no error (a hole is drawn as in full detail).
fn leaf(h: &[f32], cols: usize, a: &Area) -> Node {
    let mut n = EMPTY;
    for r in a.r0..=a.r1 {
        for &v in &h[r * cols + a.c0..=r * cols + a.c1] {
            if v.is_finite() {
                n.min = n.min.min(v);
                n.max = n.max.max(v);
            }
        }
    }
    n
}

/// Level ≥ 1: the children's range, and the largest vertical distance of the full grid's vertices
/// from the decimated surface (or the children's, if larger).
fn parent(h: &[f32], cols: usize, a: &Area, kids: &Level, (i, j): (usize, usize)) -> Node {
    let mut n = EMPTY;
    for (ci, cj) in [
        (2 * i, 2 * j),
        (2 * i + 1, 2 * j),
        (2 * i, 2 * j + 1),
        (2 * i + 1, 2 * j + 1),
    ] {
        if ci < kids.nx && cj < kids.ny {
            let k = kids.nodes[cj * kids.nx + ci];
            n.min = n.min.min(k.min);
            n.max = n.max.max(k.max);
            n.error = n.error.max(k.error);
        }
    }
    if n.error.is_infinite() {
        return n;
    }
    let s = a.step;
    let at = |c: usize, r: usize| h[r * cols + c];
    for r in a.r0..=a.r1 {
        let (ra, rb, v) = coarse_span(r, a.r0, a.r1, s);
        for c in a.c0..=a.c1 {
            let z = at(c, r);
            if !z.is_finite() {
                n.error = f32::INFINITY;
                return n;
            }
            let (ca, cb, u) = coarse_span(c, a.c0, a.c1, s);
            n.error = n.error.max((z - surface(at, (ca, cb, ra, rb), u, v)).abs());
        }
    }
    n
}

/// The coarse span at stride `s` (clipped to `hi`) that holds index `i` of a node from `lo`, and
/// `i`'s fraction across it (0 on a span of no length).
#[inline]
fn coarse_span(i: usize, lo: usize, hi: usize, s: usize) -> (usize, usize, f32) {
    let a = lo + (i - lo) / s * s;
    let b = (a + s).min(hi);
    let t = if b > a { (i - a) as f32 / (b - a) as f32 } else { 0.0 };
    (a, b, t)
}

/// The height of the coarse quad with corners at columns `ca`, `cb` and rows `ra`, `rb`, at
/// fractions `(u, v)` across it: split along (cb, ra)–(ca, rb) as the grid's quads are.
#[inline]
fn surface(at: impl Fn(usize, usize) -> f32, (ca, cb, ra, rb): (usize, usize, usize, usize), u: f32, v: f32) -> f32 {
    let (b, d) = (at(cb, ra), at(ca, rb));
    if u + v <= 1.0 {
        let a = at(ca, ra);
        a + u * (b - a) + v * (d - a)
    } else {
        let e = at(cb, rb);
        e + (1.0 - u) * (d - e) + (1.0 - v) * (b - e)
    }
}

/// The view against which nodes are tested.
struct Frustum<'a> {
    affine: &'a Affine,
    near: f32,
    viewport: Bounds,
    bound: Bound,
}

impl Frustum<'_> {
    /// The nearest depth of the node's box, or `None` when it is outside one of the frustum's
    /// planes (or holds no finite height).
    fn nearest(&self, node: &Node, a: &Area) -> Option<f32> {
        if node.min > node.max {
            return None;
        }
        let vp = &self.viewport;
        let (x0, x1, y0, y1) = (vp.x0 as f32, vp.x1 as f32, vp.y0 as f32, vp.y1 as f32);
        // Each plane: inside where its value ≥ 0. Outside when all eight corners are outside one.
        let mut inside = [false; 5];
        let mut nearest = f32::INFINITY;
        for c in [a.c0, a.c1] {
            for r in [a.r0, a.r1] {
                for h in [node.min, node.max] {
                    let p = self.affine.clip_point(c as f32, r as f32, h, 0.0);
                    nearest = nearest.min(p.w);
                    let values = [
                        p.w - self.near,
                        p.x - x0 * p.w,
                        x1 * p.w - p.x,
                        p.y - y0 * p.w,
                        y1 * p.w - p.y,
                    ];
                    for (i, v) in values.iter().enumerate() {
                        inside[i] |= *v >= 0.0;
                    }
                }
            }
        }
        inside.iter().all(|&i| i).then_some(nearest)
    }
}

/// The level chosen over each level-0 node's square, for finding neighbours.
#[derive(Debug, Default)]
pub(crate) struct Levels {
    nx: usize,
    ny: usize,
    /// `u8::MAX` where nothing was chosen (culled).
    level: Vec<u8>,
}

impl Levels {
    /// Marks each pick's squares with its level.
    pub(crate) fn fill(&mut self, p: &Pyramid, picks: &[Pick]) {
        let Some(l0) = p.levels.first() else {
            return;
        };
        self.nx = l0.nx;
        self.ny = l0.ny;
        self.level.clear();
        self.level.resize(l0.nx * l0.ny, u8::MAX);
        for pk in picks {
            let (i0, j0) = ((pk.i as usize) << pk.level, (pk.j as usize) << pk.level);
            let (i1, j1) = ((i0 + (1 << pk.level)).min(self.nx), (j0 + (1 << pk.level)).min(self.ny));
            for j in j0..j1 {
                self.level[j * self.nx + i0..j * self.nx + i1].fill(pk.level as u8);
            }
        }
    }

    /// The level chosen at level-0 square `(i, j)`, if any.
    fn at(&self, i: isize, j: isize) -> Option<u32> {
        if i < 0 || j < 0 || i as usize >= self.nx || j as usize >= self.ny {
            return None;
        }
        let l = self.level[j as usize * self.nx + i as usize];
        (l != u8::MAX).then_some(u32::from(l))
    }

    /// The coarser neighbour's level across each edge of `pk` (north, east, south, west): the
    /// neighbour's level when one node coarser than `pk` lies across it.
    pub(crate) fn coarser(&self, pk: &Pick) -> [Option<u32>; 4] {
        let n = 1isize << pk.level;
        let (i0, j0) = ((pk.i as isize) << pk.level, (pk.j as isize) << pk.level);
        // A coarser neighbour covers the whole edge, so one square beside the edge tells.
        let across = [(i0, j0 - 1), (i0 + n, j0), (i0, j0 + n), (i0 - 1, j0)];
        across.map(|(i, j)| self.at(i, j).filter(|&l| l > pk.level))
    }

    /// The finest level chosen along `pk`'s four sides.
    fn finest_around(&self, pk: &Pick) -> Option<u32> {
        let n = 1isize << pk.level;
        let (i0, j0) = ((pk.i as isize) << pk.level, (pk.j as isize) << pk.level);
        let mut finest: Option<u32> = None;
        let mut see = |l: Option<u32>| {
            if let Some(l) = l {
                finest = Some(finest.map_or(l, |f| f.min(l)));
            }
        };
        for k in 0..n {
            see(self.at(i0 + k, j0 - 1));
            see(self.at(i0 + k, j0 + n));
            see(self.at(i0 - 1, j0 + k));
            see(self.at(i0 + n, j0 + k));
        }
        finest
    }
}
