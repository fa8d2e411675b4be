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
//!   region's metric ([`crate::distance::figure_map`], [`crate::distance::edge_map`]): `taxicab`, seed 000's
//!   4-neighbour path through the region's cells and layer count, or `euclidean`, the exact
//!   Euclidean transforms of [`crate::edt`].
//! - eq. 1 `w_k = df/(df + dp_k)`, 1 on the figure; eq. 2 `shape(w_k, s_k)`
//!   ([`crate::profile::shape`]), with `s_k` the figure's slope, or for a nested figure eq. 4
//!   `(s_k + s0)·w_k − s0` where `s0` is the enclosing figure's slope. The engine takes eq. 2's
//!   power as an exponential of a logarithm rounded to `f32` ([`crate::fastmath::shape_log`],
//!   [`crate::fastmath::shape_from_log`]: polynomials within 2⁻⁴⁶ of `libm`'s, so that cells
//!   are computed in vector instructions); its heights differ from a `libm` evaluation
//!   ([`crate::profile::shape_from_log`]) by an `f32` unit of the relief in a few cells, and
//!   since 24 Nov are no longer bit-identical to earlier builds'. They still equal a full
//!   rebuild's to the bit after any edit.
//! - eq. 3: on one or more figures, the mean of their reliefs; elsewhere the inverse-distance
//!   blend `Σ(relief_k·shape_k/dp_k) / Σ(1/dp_k)`.
//! - height(x) = base + that blend, for the innermost region containing x; 0 outside every region.
//! - with the document's fractal detail, [`crate::detail`] adds its noise to that terrain (the
//!   regions paint the terrain before it and their gates; the detail follows the rectangle that
//!   changed, grown by a cell).
//! - with the document's base heightmap (`terrain.base`), its heights are added to that terrain
//!   (the regions, or the detail, write the sketch before it; the base follows the rectangle
//!   that changed, cell by cell), so the erosion below runs on the sum.
//! - with the document's erosion, [`crate::erosion`] erodes the terrain (with detail) after that
//!   (the regions, or the detail, write the terrain before it; the erosion follows the rectangle
//!   that changed, grown by its steps).
//! - with the document's fluvial erosion, [`crate::fluvial`] erodes the ridges' ground before
//!   the rivers are carved: not local, so a change re-erodes the whole grid, at once or
//!   progressively ([`TerrainEngine::set_progressive_erosion`]).
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
//! `base + Σ_k relief_k·coef_k(x)`, where `coef_k = shape_k × share_k`: `shape_k` is eq. 2's
//! term (eq. 1's `w_k`, eq. 4's slope) and `share_k` figure k's eq. 3 weight (1/|on| on figures,
//! `(1/dp_k)/Σ(1/dp_j)` elsewhere). The engine keeps, per region, the edge distances and eq. 3's
//! normaliser per cell, and per figure `dp_k`, `shape_k` (with its logarithm) and `coef_k` over
//! the region's bounding box (`engine/regions.rs` says how each edit updates them):
//!
//! - **height** of figure k (a pull): the region painted again, K multiply-adds per cell; a
//!   closed figure's nested region too (its base).
//! - **slope** of figure k: `shape_k` and `coef_k` (one `exp` per cell: a top-level figure keeps
//!   eq. 2's logarithm per cell), the region painted; a closed figure's nested region blended
//!   again (eq. 4 reads `s0`).
//! - **a moved figure** or a moved point of one: the figure's `dp` by one breadth-first search
//!   (or distance transform), compared with the old; only the cells where it changed get new
//!   shares and coefficients (the other figures' shape terms are kept) and are painted.
//! - **figures added, removed or replaced**: the new figure's `dp` and shape, the region's
//!   shares and coefficients. A closed figure that comes, goes or moves rebuilds its nested
//!   region; a changed boundary the region's maps.
//!
//! The per-cell work and each region's distance maps run on all cores.
//!
//! The engine is told what changed, not how: [`TerrainEngine::update`] takes the document after
//! a change and its [`Scope`] (which figure's height or slope, which figure list, which region),
//! and regenerates that part from the document. Turning an edit into a document change and a
//! scope is the editor's ([`crate::edit`], [`crate::editor`]).
//!
//! Other regions are not touched. Every path computes a cell's terms with the same functions
//! and its height as `base + Σ_k relief_k·coef_k` in `f32`, figures in order, from the cached
//! terms (nothing accumulates over edits), so an incrementally updated terrain equals a full
//! regeneration to the bit after any sequence of edits; the `editing` tests check exactly this.

mod regions;

use crate::cells;
use crate::change::{FigureList, Scope};
use crate::detail;
use crate::document::{Document, Figure, Grid, Region};
use crate::erosion;
use crate::fluvial;
use crate::heightmap::Heightmap;
use crate::river::layer::{Layer, Water};
use crate::validate::{self, ValidationError};
use regions::{List, RegionNode};

/// Generates the terrain of a document (validating it first).
pub fn generate(doc: &Document) -> Result<Heightmap, ValidationError> {
    Ok(TerrainEngine::new(doc)?.into_heightmap())
}

pub use crate::rect::Rect;

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
    /// The base heightmap and the sketch before it is added, if the document has a base.
    base: Option<BaseLayer>,
    /// The erosion and the terrain before it, if the document has erosion.
    erosion: Option<erosion::Layer>,
    /// The ridgelines (seed 002) and the ground they make with `map`.
    ridges: crate::ridge::layer::Layer,
    /// The fluvial erosion, if the document has it.
    fluvial: Option<FluvialLayer>,
    /// Whether a change of the land under the fluvial erosion is followed progressively
    /// ([`TerrainEngine::set_progressive_erosion`]).
    progressive: bool,
    rivers: Layer,
}

/// The fluvial erosion's settings, the land shown and the ground it was made from.
struct FluvialLayer {
    settings: crate::document::Fluvial,
    /// The eroded land shown: exact when `run` is `None`.
    land: Heightmap,
    /// The ground (the ridges') `land` follows.
    ground: Heightmap,
    /// The exact erosion of `ground` while it runs, a few steps at a time.
    run: Option<fluvial::Model>,
    /// Whether `ground` changed since `run` started: the next settle starts it again (once
    /// for any number of updates between two frames).
    restart: bool,
}

impl FluvialLayer {
    fn new(settings: crate::document::Fluvial, ground: &Heightmap, doc: &Document) -> FluvialLayer {
        FluvialLayer {
            settings,
            land: fluvial::erode(settings, ground, Some(fluvial::held_cells(doc))),
            ground: ground.clone(),
            run: None,
            restart: false,
        }
    }

    /// Follows a change of the ground in `rect`: exactly (the whole grid eroded again), or,
    /// `progressive`, by adding the ground's change in `rect` to the land shown and starting
    /// the exact run, which [`TerrainEngine::settle_erosion`] advances. Returns what changed.
    fn follow(&mut self, ground: &Heightmap, doc: &Document, rect: Rect, progressive: bool) -> Rect {
        if !progressive {
            *self = FluvialLayer::new(self.settings, ground, doc);
            return whole_of(ground);
        }
        let cols = ground.cols() as usize;
        let (new, old, land) = (ground.heights(), self.ground.heights_mut(), self.land.heights_mut());
        for r in rect.r0..rect.r0 + rect.height {
            for c in rect.c0..rect.c0 + rect.width {
                let i = r as usize * cols + c as usize;
                land[i] += new[i] - old[i];
                old[i] = new[i];
            }
        }
        self.run = None;
        self.restart = true;
        rect
    }
}

/// A base heightmap under the sketch (`terrain.base`).
struct BaseLayer {
    /// The document's entry, its heights shared.
    settings: crate::document::Base,
    heights: std::sync::Arc<[f32]>,
    /// The sketch (the regions' terrain, with detail) before the base is added.
    sketch: Heightmap,
}

impl BaseLayer {
    fn new(doc: &Document) -> Option<BaseLayer> {
        let settings = doc.terrain.base.clone()?;
        let heights = settings.heights.shared()?;
        Some(BaseLayer {
            settings,
            heights,
            sketch: Heightmap::new(&doc.grid),
        })
    }

    /// Writes `sketch + base` into `out` over `rect`; returns `rect` (the sum is per cell).
    fn apply(&self, rect: Rect, out: &mut Heightmap) -> Rect {
        let cols = out.cols() as usize;
        let sketch = self.sketch.heights();
        let out = out.heights_mut();
        for r in rect.r0..rect.r0 + rect.height {
            let row = r as usize * cols;
            for i in row + rect.c0 as usize..row + (rect.c0 + rect.width) as usize {
                out[i] = sketch[i] + self.heights[i];
            }
        }
        rect
    }
}

/// Every cell of `map`'s grid.
fn whole_of(map: &Heightmap) -> Rect {
    Rect {
        c0: 0,
        r0: 0,
        width: map.cols(),
        height: map.rows(),
    }
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

/// The document's erosion settings if they ask for a thermal pass (`iterations` 0: none).
fn thermal(doc: &Document) -> Option<crate::document::Erosion> {
    doc.terrain.erosion.filter(|e| e.iterations > 0)
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
        validate::base_loaded(doc)?;
        Ok(TerrainEngine::build(doc))
    }

    /// Generates the terrain of a valid document.
    fn build(doc: &Document) -> TerrainEngine {
        let grid = doc.grid;
        let regions: Vec<RegionNode> = doc.regions.iter().map(|r| region_node(doc, r)).collect();
        let mut map = Heightmap::new(&grid);
        let mut detail = doc.terrain.detail.map(|d| detail::Layer::new(&grid, d));
        let mut base = BaseLayer::new(doc);
        let mut erosion = thermal(doc).map(|e| erosion::Layer::new(&grid, e));
        // The terrain before erosion: the erosion's, or the map itself; the sketch before the
        // base: the base's, or that.
        let before = erosion.as_mut().map_or(&mut map, |e| &mut e.before);
        {
            let sketch = match &mut base {
                Some(b) => &mut b.sketch,
                None => &mut *before,
            };
            for (node, r) in regions.iter().zip(&doc.regions) {
                match &mut detail {
                    Some(layer) => {
                        node.paint_all(&r.figures, 0.0, &mut layer.smooth);
                        node.paint_gates(&mut layer.gate, grid.cols);
                    }
                    None => node.paint_all(&r.figures, 0.0, sketch),
                }
            }
            if let Some(layer) = &detail {
                layer.apply(whole(&grid), sketch);
            }
        }
        if let Some(b) = &base {
            b.apply(whole(&grid), before);
        }
        if let Some(layer) = &erosion {
            layer.apply(whole(&grid), &mut map);
        }
        let ridges = crate::ridge::layer::Layer::new(doc, &map);
        let fluvial = doc
            .terrain
            .erosion
            .and_then(|e| e.fluvial)
            .map(|f| FluvialLayer::new(f, ridges.ground(&map), doc));
        let mut rivers = Layer::default();
        let ground = fluvial.as_ref().map_or(ridges.ground(&map), |f| &f.land);
        rivers.sync(doc, ground, Rect::EMPTY);
        TerrainEngine {
            regions,
            map,
            detail,
            base,
            erosion,
            ridges,
            fluvial,
            progressive: false,
            rivers,
        }
    }

    /// Whether a change under the fluvial erosion is followed progressively: the change is
    /// added to the eroded land at once (the cells it touches, as without erosion), and the
    /// exact erosion runs a few steps per [`TerrainEngine::settle_erosion`] and replaces it when
    /// done. Off (the default), every update re-erodes the whole grid before it returns. The
    /// live modeler turns it on so the hand never waits.
    pub fn set_progressive_erosion(&mut self, on: bool) {
        self.progressive = on;
    }

    /// Whether an exact erosion is still running ([`TerrainEngine::set_progressive_erosion`]).
    pub fn erosion_pending(&self) -> bool {
        self.fluvial.as_ref().is_some_and(|f| f.restart || f.run.is_some())
    }

    /// Advances a running exact erosion by up to `steps` steps; when it finishes, it replaces
    /// the land shown, the rivers are carved into it again, and the whole grid is returned as
    /// changed. `doc` is the document of the last update.
    pub fn settle_erosion(&mut self, doc: &Document, steps: u32) -> Rect {
        let Some(f) = &mut self.fluvial else { return Rect::EMPTY };
        if std::mem::take(&mut f.restart) {
            f.run = Some(fluvial::Model::new(f.settings, &f.ground).holding(fluvial::held_cells(doc)));
        }
        let Some(run) = &mut f.run else { return Rect::EMPTY };
        run.advance(steps);
        if !run.finished() {
            return Rect::EMPTY;
        }
        run.write(&mut f.land);
        f.run = None;
        let all = whole(&doc.grid);
        self.rivers.sync(doc, &f.land, all);
        all
    }

    /// The land before the fluvial erosion: the ridges' ground.
    pub fn sketch(&self) -> &Heightmap {
        self.ridges.ground(&self.map)
    }

    /// The land the rivers are carved into: the fluvial erosion's, or the ridges' ground.
    pub fn land(&self) -> &Heightmap {
        self.fluvial.as_ref().map_or(self.ridges.ground(&self.map), |f| &f.land)
    }

    /// The terrain as of the last update.
    pub fn heightmap(&self) -> &Heightmap {
        self.rivers.carved().map_or(self.land(), |(carved, _)| carved)
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
            map,
            ridges,
            fluvial,
            rivers,
            ..
        } = self;
        match (rivers.carved(), fluvial) {
            (Some((carved, _)), _) => carved.clone(),
            (None, Some(f)) => f.land,
            (None, None) => ridges.ground(&map).clone(),
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
                let rect = match (&self.detail, &mut self.base) {
                    (Some(layer), Some(b)) => layer.apply(rect, &mut b.sketch),
                    (Some(layer), None) => layer.apply(rect, before),
                    (None, _) => rect,
                };
                let rect = match &self.base {
                    Some(b) => b.apply(rect, before),
                    None => rect,
                };
                let rect = match &self.erosion {
                    Some(layer) => layer.apply(rect, &mut self.map),
                    None => rect,
                };
                // The ridges follow their entry and join the regions' terrain that changed; the
                // rivers follow their entries and the ground that changed under them.
                let mut rect = rect.union(self.ridges.sync(doc, &self.map, rect));
                // Fluvial erosion is not local (a cell's drainage is its whole catchment): any
                // change of the ground re-erodes the whole grid.
                if let Some(f) = &mut self.fluvial
                    && rect.width > 0
                    && rect.height > 0
                {
                    rect = f.follow(self.ridges.ground(&self.map), doc, rect, self.progressive);
                }
                let ground = self.fluvial.as_ref().map_or(self.ridges.ground(&self.map), |f| &f.land);
                match self.rivers.sync(doc, ground, rect) {
                    Some(more) => rect.union(more),
                    None => rect,
                }
            }
            None => {
                let progressive = self.progressive;
                *self = TerrainEngine::build(doc);
                self.progressive = progressive;
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
            base,
            erosion,
            ..
        } = self;
        // Settings are not edits with a scope: a change of them regenerates everything.
        if detail.as_ref().map(|l| *l.settings()) != doc.terrain.detail
            || base.as_ref().map(|b| &b.settings) != doc.terrain.base.as_ref()
            || erosion.as_ref().map(|l| *l.settings()) != thermal(doc)
            || (regions.len() == doc.regions.len()
                && regions
                    .iter()
                    .zip(&doc.regions)
                    .any(|(n, r)| n.metric != doc.metric_of(r)))
        {
            return None;
        }
        // With detail the regions paint the terrain before it, and the shapes' gates.
        let (map, mut gate) = match (detail, base) {
            (Some(detail::Layer { smooth, gate, .. }), _) => (smooth, Some(gate.as_mut_slice())),
            (None, Some(b)) => (&mut b.sketch, None),
            (None, None) => (erosion.as_mut().map_or(map, |e| &mut e.before), None),
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
                figs.get(k)?;
                node.figures.get(k)?;
                node.pull(k, figs, base, map)
            }
            Scope::Slope(at) => {
                let (node, figs, base, outer) = locate(regions, doc, &FigureList::of(at))?;
                let k = at.index();
                figs.get(k)?;
                node.figures.get(k)?;
                node.slope(k, List { figs, base, outer }, map)
            }
            Scope::Figures(list, change) => {
                let (node, figs, base, outer) = locate(regions, doc, list)?;
                node.change(&grid, *change, List { figs, base, outer }, map, gate)?
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
