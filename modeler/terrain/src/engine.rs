//! Terrain as a pure function of the document, regenerated incrementally.
//!
//! # The rules (issue 6; seed 000 chapter 4)
//!
//! Every region — a top-level region, or the nested region a closed figure bounds — has a *base*
//! height: 0 for a top-level region, the enclosing figure's (absolute) height for a nested one. A
//! figure's *relief* is its height minus its region's base. For a cell `x` of a region with
//! figures `k`:
//!
//! - `dp_k(x)`: distance from figure k's cells; `df(x)`: distance from the region's edge, in the
//!   region's metric ([`distance::figure_map`], [`distance::edge_map`]): `taxicab`, seed 000's
//!   4-neighbour path through the region's cells and layer count, or `euclidean`, the exact
//!   Euclidean transforms of [`crate::edt`].
//! - eq. 1 `w_k = df/(df + dp_k)`, 1 on the figure; eq. 2 `shape(w_k, s_k)`
//!   ([`profile::shape`]), with `s_k` the figure's slope, or for a nested figure eq. 4
//!   `(s_k + s0)·w_k − s0` where `s0` is the enclosing figure's slope.
//! - eq. 3: on one or more figures, the mean of their reliefs; elsewhere the inverse-distance
//!   blend `Σ(relief_k·shape_k/dp_k) / Σ(1/dp_k)`.
//! - height(x) = base + that blend, for the innermost region containing x; 0 outside every region.
//! - with the document's fractal detail, [`crate::detail`] adds its noise to that terrain (the
//!   regions paint the terrain before it and their gates; the detail follows the rectangle that
//!   changed, grown by a cell).
//! - with the document's erosion, [`crate::erosion`] erodes the terrain (with detail) after that
//!   (the regions, or the detail, write the terrain before it; the erosion follows the rectangle
//!   that changed, grown by its steps).
//!
//! Distances move through every cell of the region, including cells a nested region covers. A
//! cell that no figure can reach (`dp` infinite for all) stays at the base height: an unreachable
//! figure weighs `1/dp = 0` and has `w = 0`. A region's cells are 4-connected (its boundary is a
//! 4-connected loop and every inside cell joins it along its row), so this happens only for a
//! region without figures; the rule is there so that no input divides by zero.
//!
//! # Incremental regeneration
//!
//! Eq. 2 is linear in the relief and eq. 3 is a weighted mean, so each cell's height is
//! `base + Σ_k relief_k·coef_k(x)`, where `coef_k = shape_k × share_k` and `share_k` is figure k's
//! eq. 3 weight (1/|on| on figures, `(1/dp_k)/Σ(1/dp_j)` elsewhere). The engine keeps, per region,
//! the distance maps and per figure `dp_k`, `share_k` and `coef_k` over the region's bounding box:
//!
//! - **height** of figure k (a pull): `height = rest_k + relief_k·coef_k` over the region, where
//!   `rest_k` (the other figures' sum) is computed once when a pull of k starts; one multiply-add
//!   per cell. If k is closed, its nested region moves with its base:
//!   `height = Σ_j h_j·coef_j + base·(1 − Σ_j coef_j)`, also cached.
//! - **slope** of figure k: `coef_k` again (one `powf` per cell), and if k is closed the nested
//!   region's coefficients (eq. 4 reads `s0`).
//! - **geometry** (figures added, removed, moved, points moved): the figure's `dp` by one
//!   breadth-first search, then the region's shares and coefficients; the other figures' `dp` are
//!   kept. A moved closed figure rebuilds its nested regions; a changed boundary the region's maps.
//!
//! The engine is told what changed, not how: [`TerrainEngine::update`] takes the document after
//! a change and its [`Scope`] (which figure's height or slope, which figure list, which region),
//! and regenerates that part from the document. Turning an edit into a document change and a
//! scope is the editor's ([`crate::edit`], [`crate::editor`]).
//!
//! Other regions are not touched. Coefficients are a deterministic function of the geometry, so
//! a rebuilt region equals a freshly generated one to the bit. Heights after a pull are the same
//! `f32` terms (base and `relief_k·coef_k`) summed in another order, or the algebraically equal
//! plateau form above; each way is within `(3K + 8)·u·M` of the exact value (K figures in the
//! region, u = 2⁻²⁴ the unit roundoff of `f32`, M the largest absolute height), so an
//! incrementally updated heightmap and a full regeneration differ by at most `(6K + 16)·u·M`
//! per cell, whatever the number of edits (nothing accumulates: each update recomputes a cell
//! from cached terms). The `editing` tests check exactly this bound.

use crate::cells::{self, Cell, Mask};
use crate::change::{FigureList, ListChange, Scope};
use crate::detail;
use crate::distance;
use crate::document::{Document, Figure, FigureKind, Grid, Metric, Point, Region};
use crate::erosion;
use crate::heightmap::Heightmap;
use crate::profile;
use crate::river::layer::{Layer, Water};
use crate::validate::{self, ValidationError};

/// Generates the terrain of a document (validating it first).
pub fn generate(doc: &Document) -> Result<Heightmap, ValidationError> {
    Ok(TerrainEngine::new(doc)?.into_heightmap())
}

pub use crate::rect::Rect;

/// A run of cells in one row of a region's box: `start..end` in box columns.
#[derive(Debug, Clone, Copy)]
struct Run {
    row: u32,
    start: u32,
    end: u32,
}

/// Per-figure caches, over the owning region's box.
struct FigureNode {
    dp: Vec<f32>,
    share: Vec<f32>,
    coef: Vec<f32>,
    /// The nested region of a closed figure.
    child: Option<Box<RegionNode>>,
}

/// Per-region caches, over the region's box.
struct RegionNode {
    mask: Mask,
    /// The distances' metric, the region's (its nested regions inherit it).
    metric: Metric,
    df: Vec<f32>,
    /// The cells this region decides: its cells minus its nested regions'.
    owned: Vec<Run>,
    figures: Vec<FigureNode>,
    /// `base + Σ_{j≠k} relief_j·coef_j` for the figure k being pulled.
    rest: Option<(usize, Vec<f32>)>,
    /// `(Σ h_j·coef_j, 1 − Σ coef_j)`, for pulls of the enclosing figure.
    plateau: Option<(Vec<f32>, Vec<f32>)>,
}

/// The cells of the nested region a closed curve bounds. Validation keeps a closed figure strictly
/// inside its region, which puts its cells inside the region's; the intersection only guards
/// against a rounding tie at a cell border, so that no region paints outside its parent.
fn nested_mask(grid: &Grid, points: &[Point], parent: &Mask) -> Mask {
    cells::closed_mask(grid, points).intersect(parent)
}

/// The cells a figure stands on; a closed figure's are its nested region's.
fn sources(grid: &Grid, f: &Figure, child: Option<&RegionNode>) -> Vec<Cell> {
    match child {
        Some(c) if f.kind == FigureKind::Closed => c.mask.cells().collect(),
        _ => cells::figure_cells(grid, f),
    }
}

impl FigureNode {
    fn build(grid: &Grid, region: &Mask, metric: Metric, f: &Figure) -> FigureNode {
        let child = (f.kind == FigureKind::Closed).then(|| {
            let mask = nested_mask(grid, &f.points, region);
            Box::new(RegionNode::build(grid, mask, metric, &f.figures, Some(f.slope)))
        });
        FigureNode {
            dp: distance::figure_map(metric, region, &sources(grid, f, child.as_deref())),
            share: Vec::new(),
            coef: Vec::new(),
            child,
        }
    }
}

impl RegionNode {
    fn build(grid: &Grid, mask: Mask, metric: Metric, figs: &[Figure], outer: Option<f64>) -> RegionNode {
        let df = distance::edge_map(metric, &mask);
        let figures = figs.iter().map(|f| FigureNode::build(grid, &mask, metric, f)).collect();
        let mut node = RegionNode {
            mask,
            metric,
            df,
            owned: Vec::new(),
            figures,
            rest: None,
            plateau: None,
        };
        node.settle(figs, outer);
        node
    }

    /// New cells for the region; its figures' nested regions are kept.
    fn reshape(&mut self, grid: &Grid, mask: Mask, figs: &[Figure], outer: Option<f64>) {
        self.mask = mask;
        self.df = distance::edge_map(self.metric, &self.mask);
        for (f, node) in figs.iter().zip(&mut self.figures) {
            node.dp = distance::figure_map(self.metric, &self.mask, &sources(grid, f, node.child.as_deref()));
        }
        self.settle(figs, outer);
    }

    /// Figure k's points changed (its nested figures did not).
    fn outline(&mut self, grid: &Grid, k: usize, figs: &[Figure]) {
        let f = &figs[k];
        if let Some(child) = self.figures[k].child.as_deref_mut() {
            child.reshape(
                grid,
                nested_mask(grid, &f.points, &self.mask),
                &f.figures,
                Some(f.slope),
            );
        }
        let node = &mut self.figures[k];
        node.dp = distance::figure_map(self.metric, &self.mask, &sources(grid, f, node.child.as_deref()));
    }

    /// Recomputes what depends on the set of figures: owned cells, shares, coefficients.
    fn settle(&mut self, figs: &[Figure], outer: Option<f64>) {
        self.owned = self.owned_runs();
        self.shares();
        for k in 0..figs.len() {
            self.coefficients(k, figs, outer);
        }
        self.rest = None;
        self.plateau = None;
    }

    fn owned_runs(&self) -> Vec<Run> {
        let mut own = self.mask.bits().to_vec();
        for child in self.figures.iter().filter_map(|f| f.child.as_deref()) {
            for cell in child.mask.cells() {
                if let Some(i) = self.mask.index(cell) {
                    own[i] = false;
                }
            }
        }
        let w = self.mask.width as usize;
        let mut runs = Vec::new();
        for (row, line) in own.chunks(w.max(1)).enumerate() {
            let mut c = 0;
            while c < line.len() {
                if line[c] {
                    let start = c;
                    while c < line.len() && line[c] {
                        c += 1;
                    }
                    runs.push(Run {
                        row: row as u32,
                        start: start as u32,
                        end: c as u32,
                    });
                } else {
                    c += 1;
                }
            }
        }
        runs
    }

    /// Box index ranges of the owned runs, with the matching grid index of each run's start.
    fn spans(&self, cols: u32) -> impl Iterator<Item = (std::ops::Range<usize>, usize)> + '_ {
        let w = self.mask.width as usize;
        self.owned.iter().map(move |run| {
            let b = run.row as usize * w + run.start as usize;
            let len = (run.end - run.start) as usize;
            let g = (self.mask.r0 + run.row) as usize * cols as usize + (self.mask.c0 + run.start) as usize;
            (b..b + len, g)
        })
    }

    /// Eq. 3's weights of every figure on the owned cells. Written in place: a second set of
    /// share maps would add 4 bytes per figure per cell to the engine's peak memory.
    fn shares(&mut self) {
        let n = self.mask.box_len();
        let RegionNode {
            mask, owned, figures, ..
        } = self;
        for f in figures.iter_mut() {
            f.share.clear();
            f.share.resize(n, 0.0);
        }
        let w = mask.width as usize;
        for run in owned.iter() {
            let b = run.row as usize * w;
            for i in b + run.start as usize..b + run.end as usize {
                let on = figures.iter().filter(|f| f.dp[i] == 0.0).count();
                if on > 0 {
                    let each = 1.0 / on as f64;
                    for f in figures.iter_mut() {
                        if f.dp[i] == 0.0 {
                            f.share[i] = each as f32;
                        }
                    }
                } else {
                    let total: f64 = figures
                        .iter()
                        .map(|f| profile::inverse_distance_real(f64::from(f.dp[i])))
                        .sum();
                    if total > 0.0 {
                        for f in figures.iter_mut() {
                            f.share[i] = (profile::inverse_distance_real(f64::from(f.dp[i])) / total) as f32;
                        }
                    }
                }
            }
        }
    }

    /// Figure k's `shape × share` on the owned cells (eq. 1, 2, 4).
    fn coefficients(&mut self, k: usize, figs: &[Figure], outer: Option<f64>) {
        let s1 = figs[k].slope;
        let w = self.mask.width as usize;
        let mut coef = vec![0.0f32; self.mask.box_len()];
        let node = &self.figures[k];
        for run in &self.owned {
            let b = run.row as usize * w;
            let cells = b + run.start as usize..b + run.end as usize;
            for (i, out) in cells.clone().zip(&mut coef[cells]) {
                let wk = profile::weight_real(f64::from(self.df[i]), f64::from(node.dp[i]));
                let s = outer.map_or(s1, |s0| profile::nested_slope(s1, s0, wk));
                *out = (profile::shape(wk, s) * f64::from(node.share[i])) as f32;
            }
        }
        self.figures[k].coef = coef;
    }

    /// Paints the owned cells: `base + Σ relief_k·coef_k`, figures in order.
    fn paint_own(&self, figs: &[Figure], base: f64, map: &mut Heightmap) {
        let cols = map.cols();
        let out = map.heights_mut();
        let reliefs: Vec<f32> = figs.iter().map(|f| (f.height - base) as f32).collect();
        for (b, g) in self.spans(cols) {
            let dst = &mut out[g..g + b.len()];
            dst.fill(base as f32);
            for (node, &rel) in self.figures.iter().zip(&reliefs) {
                for (d, &c) in dst.iter_mut().zip(&node.coef[b.clone()]) {
                    *d += rel * c;
                }
            }
        }
    }

    /// Paints the owned cells and every nested region.
    fn paint_all(&self, figs: &[Figure], base: f64, map: &mut Heightmap) {
        self.paint_own(figs, base, map);
        for (node, f) in self.figures.iter().zip(figs) {
            if let Some(child) = node.child.as_deref() {
                child.paint_all(&f.figures, f.height, map);
            }
        }
    }

    /// Paints the owned cells after figure k's height or slope changed: `rest_k + relief_k·coef_k`.
    fn paint_pull(&mut self, k: usize, figs: &[Figure], base: f64, map: &mut Heightmap) {
        let cols = map.cols();
        if self.rest.as_ref().is_none_or(|(j, _)| *j != k) {
            let mut rest = vec![0.0f32; self.mask.box_len()];
            for (b, _) in self.spans(cols) {
                let dst = &mut rest[b.clone()];
                dst.fill(base as f32);
                for (j, (node, f)) in self.figures.iter().zip(figs).enumerate() {
                    if j != k {
                        let rel = (f.height - base) as f32;
                        for (d, &c) in dst.iter_mut().zip(&node.coef[b.clone()]) {
                            *d += rel * c;
                        }
                    }
                }
            }
            self.rest = Some((k, rest));
        }
        let Some((_, rest)) = &self.rest else { return };
        let rel = (figs[k].height - base) as f32;
        let coef = &self.figures[k].coef;
        let out = map.heights_mut();
        for (b, g) in self.spans(cols) {
            for ((d, &r), &c) in out[g..g + b.len()].iter_mut().zip(&rest[b.clone()]).zip(&coef[b]) {
                *d = r + rel * c;
            }
        }
    }

    /// Paints the owned cells after the base (the enclosing figure's height) changed:
    /// `Σ h_j·coef_j + base·(1 − Σ coef_j)`.
    fn paint_plateau(&mut self, figs: &[Figure], base: f64, map: &mut Heightmap) {
        let cols = map.cols();
        if self.plateau.is_none() {
            let n = self.mask.box_len();
            let (mut a, mut b) = (vec![0.0f32; n], vec![0.0f32; n]);
            for (r, _) in self.spans(cols) {
                b[r.clone()].fill(1.0);
                for (node, f) in self.figures.iter().zip(figs) {
                    let h = f.height as f32;
                    for ((a, b), &c) in a[r.clone()]
                        .iter_mut()
                        .zip(&mut b[r.clone()])
                        .zip(&node.coef[r.clone()])
                    {
                        *a += h * c;
                        *b -= c;
                    }
                }
            }
            self.plateau = Some((a, b));
        }
        let Some((a, b)) = &self.plateau else { return };
        let base = base as f32;
        let out = map.heights_mut();
        for (r, g) in self.spans(cols) {
            for ((d, &a), &b) in out[g..g + r.len()].iter_mut().zip(&a[r.clone()]).zip(&b[r]) {
                *d = a + base * b;
            }
        }
    }

    fn clear(&self, map: &mut Heightmap, gate: Option<&mut [f32]>) {
        let cols = map.cols() as usize;
        let out = map.heights_mut();
        for (c, r) in self.mask.cells() {
            out[r as usize * cols + c as usize] = 0.0;
        }
        if let Some(gate) = gate {
            for (c, r) in self.mask.cells() {
                gate[r as usize * cols + c as usize] = 0.0;
            }
        }
    }

    /// Paints the detail's gates ([`detail::gate`]) of the owned cells and every nested region's:
    /// they follow the distances, so only a change of shape repaints them.
    fn paint_gates(&self, gate: &mut [f32], cols: u32) {
        for (b, g) in self.spans(cols) {
            for (i, out) in b.zip(&mut gate[g..]) {
                let near = self.figures.iter().map(|f| f.dp[i]).fold(f32::INFINITY, f32::min);
                *out = detail::gate(self.df[i], near);
            }
        }
        for child in self.figures.iter().filter_map(|f| f.child.as_deref()) {
            child.paint_gates(gate, cols);
        }
    }
}

/// A document's terrain with the caches that let it follow the document's changes: per region
/// its distance maps and per figure its eq. 1–3 coefficients. Regenerates only what a change
/// touches.
pub struct TerrainEngine {
    regions: Vec<RegionNode>,
    /// The regions' terrain, before the ridges join it and the rivers carve it (with the
    /// detail, if the document has it).
    map: Heightmap,
    /// The fractal detail and the regions' terrain before it, if the document has detail.
    detail: Option<detail::Layer>,
    /// The erosion and the terrain before it, if the document has erosion.
    erosion: Option<erosion::Layer>,
    /// The ridgelines (seed 002) and the ground they make with `map`.
    ridges: crate::ridge::layer::Layer,
    rivers: Layer,
}

/// The node that owns figure list `list`, with that list's figures, base and outer slope.
fn locate<'a, 'd>(
    regions: &'a mut [RegionNode],
    doc: &'d Document,
    list: &FigureList,
) -> Option<(&'a mut RegionNode, &'d [Figure], f64, Option<f64>)> {
    match list {
        FigureList::Region(i) => Some((regions.get_mut(*i)?, &doc.regions.get(*i)?.figures, 0.0, None)),
        FigureList::Nested(p) => {
            let f = p.get(doc)?;
            let mut node = regions.get_mut(p.region())?;
            for &i in p.indices() {
                node = node.figures.get_mut(i)?.child.as_deref_mut()?;
            }
            Some((node, &f.figures, f.height, Some(f.slope)))
        }
    }
}

/// Every cell of the grid.
fn whole(grid: &Grid) -> Rect {
    Rect {
        c0: 0,
        r0: 0,
        width: grid.cols,
        height: grid.rows,
    }
}

fn region_node(doc: &Document, r: &Region) -> RegionNode {
    RegionNode::build(
        &doc.grid,
        cells::closed_mask(&doc.grid, &r.boundary),
        doc.metric_of(r),
        &r.figures,
        None,
    )
}

impl TerrainEngine {
    /// Validates `doc` and generates its terrain.
    pub fn new(doc: &Document) -> Result<TerrainEngine, ValidationError> {
        validate::document(doc)?;
        Ok(TerrainEngine::build(doc))
    }

    /// Generates the terrain of a valid document.
    fn build(doc: &Document) -> TerrainEngine {
        let grid = doc.grid;
        let regions: Vec<RegionNode> = doc.regions.iter().map(|r| region_node(doc, r)).collect();
        let mut map = Heightmap::new(&grid);
        let mut detail = doc.terrain.detail.map(|d| detail::Layer::new(&grid, d));
        let mut erosion = doc.terrain.erosion.map(|e| erosion::Layer::new(&grid, e));
        // The terrain before erosion: the erosion's, or the map itself.
        let before = erosion.as_mut().map_or(&mut map, |e| &mut e.before);
        for (node, r) in regions.iter().zip(&doc.regions) {
            match &mut detail {
                Some(layer) => {
                    node.paint_all(&r.figures, 0.0, &mut layer.smooth);
                    node.paint_gates(&mut layer.gate, grid.cols);
                }
                None => node.paint_all(&r.figures, 0.0, before),
            }
        }
        if let Some(layer) = &detail {
            layer.apply(whole(&grid), before);
        }
        if let Some(layer) = &erosion {
            layer.apply(whole(&grid), &mut map);
        }
        let ridges = crate::ridge::layer::Layer::new(doc, &map);
        let mut rivers = Layer::default();
        rivers.sync(doc, ridges.ground(&map), Rect::EMPTY);
        TerrainEngine {
            regions,
            map,
            detail,
            erosion,
            ridges,
            rivers,
        }
    }

    /// The terrain as of the last update.
    pub fn heightmap(&self) -> &Heightmap {
        self.rivers
            .carved()
            .map_or(self.ridges.ground(&self.map), |(carved, _)| carved)
    }

    /// The ridgelines' layer (its DTM, and the terrain before the rivers).
    pub fn ridges(&self) -> &crate::ridge::layer::Layer {
        &self.ridges
    }

    /// The rivers' water (surface level per cell, lakes), if the document has rivers.
    pub fn water(&self) -> Option<&Water> {
        self.rivers.carved().map(|(_, water)| water)
    }

    /// The rivers' processed shapes and carvings.
    pub fn rivers(&self) -> &Layer {
        &self.rivers
    }

    /// The terrain, without the caches.
    pub fn into_heightmap(self) -> Heightmap {
        let TerrainEngine {
            map, ridges, rivers, ..
        } = self;
        match rivers.carved() {
            Some((carved, _)) => carved.clone(),
            None => ridges.ground(&map).clone(),
        }
    }

    /// Brings the terrain up to date with `doc` after the change `scope` describes, regenerating
    /// only that part, and returns the cells whose height may have changed.
    ///
    /// `doc` is the document this engine last saw (at [`TerrainEngine::new`] or the last update)
    /// with that one change made, and valid. A scope that does not fit the engine's regions and
    /// figures (an index out of range, a list of another length) regenerates everything; any
    /// other mismatch leaves a terrain that does not match the document.
    pub fn update(&mut self, doc: &Document, scope: &Scope) -> Rect {
        match self.regenerate(doc, scope) {
            Some(rect) => {
                // The detail follows the regions' terrain that changed (and the cells beside it),
                // the erosion the terrain before it (and the cells its steps reach).
                let before = self.erosion.as_mut().map_or(&mut self.map, |e| &mut e.before);
                let rect = match &self.detail {
                    Some(layer) => layer.apply(rect, before),
                    None => rect,
                };
                let rect = match &self.erosion {
                    Some(layer) => layer.apply(rect, &mut self.map),
                    None => rect,
                };
                // The ridges follow their entry and join the regions' terrain that changed; the
                // rivers follow their entries and the ground that changed under them.
                let rect = rect.union(self.ridges.sync(doc, &self.map, rect));
                match self.rivers.sync(doc, self.ridges.ground(&self.map), rect) {
                    Some(more) => rect.union(more),
                    None => rect,
                }
            }
            None => {
                *self = TerrainEngine::build(doc);
                whole(&doc.grid)
            }
        }
    }

    /// The part of [`TerrainEngine::update`] that regenerates by scope; `None` when the scope
    /// does not fit.
    fn regenerate(&mut self, doc: &Document, scope: &Scope) -> Option<Rect> {
        let TerrainEngine {
            regions,
            map,
            detail,
            erosion,
            ..
        } = self;
        // Settings are not edits with a scope: a change of them regenerates everything.
        if detail.as_ref().map(|l| *l.settings()) != doc.terrain.detail
            || erosion.as_ref().map(|l| *l.settings()) != doc.terrain.erosion
            || (regions.len() == doc.regions.len()
                && regions
                    .iter()
                    .zip(&doc.regions)
                    .any(|(n, r)| n.metric != doc.metric_of(r)))
        {
            return None;
        }
        // With detail the regions paint the terrain before it, and the shapes' gates.
        let (map, mut gate) = match detail {
            Some(detail::Layer { smooth, gate, .. }) => (smooth, Some(gate.as_mut_slice())),
            None => (erosion.as_mut().map_or(map, |e| &mut e.before), None),
        };
        let grid = doc.grid;
        let before = match scope {
            Scope::RegionAdded(_) => doc.regions.len().checked_sub(1)?,
            Scope::RegionRemoved(_) => doc.regions.len() + 1,
            _ => doc.regions.len(),
        };
        if regions.len() != before {
            return None;
        }
        let rect = match scope {
            Scope::Rocks(_) | Scope::Rivers(_) | Scope::Ridges | Scope::Trees => Rect {
                c0: 0,
                r0: 0,
                width: 0,
                height: 0,
            },
            Scope::Height(at) => {
                let (node, figs, base, _) = locate(regions, doc, &FigureList::of(at))?;
                let k = at.index();
                let f = figs.get(k)?;
                node.figures.get(k)?;
                node.plateau = None;
                node.paint_pull(k, figs, base, map);
                let mut rect = Rect::of(&node.mask);
                if let Some(child) = node.figures[k].child.as_deref_mut() {
                    child.rest = None;
                    child.paint_plateau(&f.figures, f.height, map);
                    rect = rect.union(Rect::of(&child.mask));
                }
                rect
            }
            Scope::Slope(at) => {
                let (node, figs, base, outer) = locate(regions, doc, &FigureList::of(at))?;
                let k = at.index();
                let f = figs.get(k)?;
                node.figures.get(k)?;
                node.coefficients(k, figs, outer);
                node.plateau = None;
                node.paint_pull(k, figs, base, map);
                let mut rect = Rect::of(&node.mask);
                if let Some(child) = node.figures[k].child.as_deref_mut() {
                    for j in 0..f.figures.len() {
                        child.coefficients(j, &f.figures, Some(f.slope));
                    }
                    child.rest = None;
                    child.plateau = None;
                    child.paint_own(&f.figures, f.height, map);
                    rect = rect.union(Rect::of(&child.mask));
                }
                rect
            }
            Scope::Figures(list, change) => {
                let (node, figs, base, outer) = locate(regions, doc, list)?;
                let fits = match *change {
                    ListChange::Added(k) => k < figs.len() && k <= node.figures.len(),
                    ListChange::Removed(k) => k < node.figures.len(),
                    ListChange::Replaced(k) | ListChange::Outline(k) => k < figs.len() && k < node.figures.len(),
                };
                if !fits {
                    return None;
                }
                match *change {
                    ListChange::Added(k) => node
                        .figures
                        .insert(k, FigureNode::build(&grid, &node.mask, node.metric, &figs[k])),
                    ListChange::Removed(k) => {
                        node.figures.remove(k);
                    }
                    ListChange::Replaced(k) => {
                        node.figures[k] = FigureNode::build(&grid, &node.mask, node.metric, &figs[k])
                    }
                    ListChange::Outline(k) => node.outline(&grid, k, figs),
                }
                if node.figures.len() != figs.len() {
                    return None;
                }
                node.settle(figs, outer);
                node.paint_all(figs, base, map);
                if let Some(g) = gate.as_deref_mut() {
                    node.paint_gates(g, grid.cols);
                }
                Rect::of(&node.mask)
            }
            Scope::RegionAdded(i) => {
                let r = doc.regions.get(*i)?;
                let node = region_node(doc, r);
                node.paint_all(&r.figures, 0.0, map);
                if let Some(g) = gate.as_deref_mut() {
                    node.paint_gates(g, grid.cols);
                }
                let rect = Rect::of(&node.mask);
                regions.insert(*i, node);
                rect
            }
            Scope::RegionRemoved(i) => {
                if *i >= regions.len() {
                    return None;
                }
                let node = regions.remove(*i);
                node.clear(map, gate.as_deref_mut());
                Rect::of(&node.mask)
            }
            Scope::RegionReplaced(i) => {
                let r = doc.regions.get(*i)?;
                let old = std::mem::replace(regions.get_mut(*i)?, region_node(doc, r));
                old.clear(map, gate.as_deref_mut());
                regions[*i].paint_all(&r.figures, 0.0, map);
                if let Some(g) = gate.as_deref_mut() {
                    regions[*i].paint_gates(g, grid.cols);
                }
                Rect::of(&old.mask).union(Rect::of(&regions[*i].mask))
            }
            Scope::RegionOutline(i) => {
                let r = doc.regions.get(*i)?;
                let node = regions.get_mut(*i)?;
                if node.figures.len() != r.figures.len() {
                    return None;
                }
                node.clear(map, gate.as_deref_mut());
                let old = Rect::of(&node.mask);
                node.reshape(&grid, cells::closed_mask(&grid, &r.boundary), &r.figures, None);
                node.paint_all(&r.figures, 0.0, map);
                if let Some(g) = gate {
                    node.paint_gates(g, grid.cols);
                }
                old.union(Rect::of(&node.mask))
            }
        };
        Some(rect)
    }
}
