//! A document's ridgelines as a height layer of the terrain, kept up to date incrementally.
//!
//! The layer is the ridgeline DTM ([`Dtm`]) of every ridgeline and tree in the document's
//! `ridges` entry. It combines with the regions' terrain (seed 000) by **max where it stands
//! above the ground**: a cell the ridge layer raises (z > 0) gets `max(regions, layer)`, any other
//! keeps the regions' height. A ridge drawn in the air at the pen's height stays at that height
//! whatever lies under it, its flanks run down until they meet the terrain, and a depression of
//! the regions (below 0) away from the ridges is left alone — what a modeler sketching a ridge
//! over existing terrain expects; adding the layer on top would lift the ridge by whatever
//! terrain happens to be below it, away from where the pen drew it.
//!
//! Skeleton ids: ridgeline i is id i, tree j is id [`TREE_ID`] + j. A change compares each
//! skeleton with the last one the layer saw and hands only those that differ to [`Dtm::set`].

use std::collections::BTreeMap;

use super::tree::Tree;
use super::{Dtm, Filter, RidgeError, Skeleton, check_slope};
use crate::document::{Document, Ridges};
use crate::heightmap::Heightmap;
use crate::rect::Rect;

/// The first tree's skeleton id.
pub const TREE_ID: u32 = 1 << 31;

/// The largest filter half-width and pass count a document may ask for.
pub const MAX_FILTER: u32 = 64;

/// The filter a `ridges` entry asks for.
pub fn filter_of(r: &Ridges) -> Filter {
    Filter {
        radius: r.filter_radius,
        passes: r.filter_passes,
    }
}

/// The tree `ridges.trees[j]` as a [`Tree`] (degrees to radians).
pub fn tree_of(t: &crate::document::RidgeTree) -> Tree {
    Tree {
        nodes: t.nodes.clone(),
        edges: t.edges.clone(),
        theta: t.theta.to_radians(),
        h_end: t.h_end,
    }
}

/// Every ridgeline and tree of `r` as a skeleton with its id, checked; errors name the element
/// (`ridges.lines[2].points[1]`, `ridges.trees[0].edges[3]`, `ridges.slope`).
pub fn skeletons(r: &Ridges) -> Result<Vec<(u32, Skeleton)>, RidgeError> {
    let slope = r.slope.to_radians();
    if !r.slope.is_finite() {
        return Err(RidgeError::NotFinite {
            what: "ridges.slope".into(),
        });
    }
    check_slope(slope, "ridges.slope")?;
    for (name, v) in [
        ("ridges.filter_radius", r.filter_radius),
        ("ridges.filter_passes", r.filter_passes),
    ] {
        if v > MAX_FILTER {
            return Err(RidgeError::Parameter {
                what: name.into(),
                value: f64::from(v),
                expected: "it must be at most 64",
            });
        }
    }
    let mut out = Vec::with_capacity(r.lines.len() + r.trees.len());
    for (i, l) in r.lines.iter().enumerate() {
        let s = Skeleton::polyline(&l.points, slope);
        s.check(&format!("ridges.lines[{i}]"))?;
        out.push((i as u32, s));
    }
    for (j, t) in r.trees.iter().enumerate() {
        let what = format!("ridges.trees[{j}]");
        if !t.theta.is_finite() {
            return Err(RidgeError::NotFinite {
                what: format!("{what}.theta"),
            });
        }
        let tree = tree_of(t);
        tree.check(&what)?;
        out.push((TREE_ID + j as u32, tree.skeleton(slope)));
    }
    Ok(out)
}

/// The ridge layer of a document and the terrain it makes with the regions' heights.
#[derive(Debug, Default)]
pub struct Layer {
    dtm: Option<Dtm>,
    seen: BTreeMap<u32, Skeleton>,
    /// The regions' terrain combined with the layer.
    ground: Option<Heightmap>,
}

impl Layer {
    /// The layer of `doc` (valid) over the regions' terrain `map`.
    pub fn new(doc: &Document, map: &Heightmap) -> Layer {
        let mut l = Layer::default();
        l.sync(doc, map, Rect::EMPTY);
        l
    }

    /// The terrain: the regions' `map` combined with the ridges (`map` itself without ridges).
    pub fn ground<'a>(&'a self, map: &'a Heightmap) -> &'a Heightmap {
        self.ground.as_ref().unwrap_or(map)
    }

    /// The ridgeline DTM, if the document has ridges.
    pub fn dtm(&self) -> Option<&Dtm> {
        self.dtm.as_ref()
    }

    /// Follows `doc` after a change: the regions' terrain `map` changed over `changed`, and the
    /// ridges may have changed. Returns the cells whose combined height may have changed beyond
    /// `changed`.
    pub fn sync(&mut self, doc: &Document, map: &Heightmap, changed: Rect) -> Rect {
        let grid = doc.grid;
        let all = Rect {
            c0: 0,
            r0: 0,
            width: grid.cols,
            height: grid.rows,
        };
        let Some(r) = &doc.ridges else {
            let had = self.dtm.is_some();
            *self = Layer::default();
            return if had { all } else { Rect::EMPTY };
        };
        // The document is valid; an entry that is not is treated as no ridgelines.
        let now: BTreeMap<u32, Skeleton> = skeletons(r).unwrap_or_default().into_iter().collect();
        let filter = filter_of(r);
        let fits = self.dtm.as_ref().is_some_and(|d| {
            d.size() == (grid.cols, grid.rows) && d.filter() == filter && d.cell_size() == grid.cell_size
        }) && self
            .ground
            .as_ref()
            .is_some_and(|g| g.cols() == grid.cols && g.rows() == grid.rows);
        let dirty = if fits {
            let dtm = self.dtm.as_mut().map(|d| (d, &self.seen));
            let mut dirty = Rect::EMPTY;
            if let Some((dtm, seen)) = dtm {
                let ids: std::collections::BTreeSet<u32> = seen.keys().chain(now.keys()).copied().collect();
                for id in ids {
                    let (old, new) = (seen.get(&id), now.get(&id));
                    if old != new {
                        dirty = dirty.union(dtm.set(id, new));
                    }
                }
            }
            dirty
        } else {
            let ids: Vec<(u32, &Skeleton)> = now.iter().map(|(i, s)| (*i, s)).collect();
            self.dtm = Some(Dtm::build(grid.cols, grid.rows, grid.cell_size, filter, &ids));
            self.ground = Some(map.clone());
            all
        };
        self.seen = now;
        if let (Some(dtm), Some(ground)) = (&self.dtm, &mut self.ground) {
            combine(map, dtm.heights(), ground, dirty.union(changed));
        }
        dirty
    }
}

/// `ground = layer > 0 ? max(map, layer) : map` over `rect`.
fn combine(map: &Heightmap, layer: &[f32], ground: &mut Heightmap, rect: Rect) {
    let cols = map.cols() as usize;
    let (src, dst) = (map.heights(), ground.heights_mut());
    for r in rect.r0..rect.r0 + rect.height {
        let s = r as usize * cols + rect.c0 as usize;
        let e = s + rect.width as usize;
        for ((d, &m), &l) in dst[s..e].iter_mut().zip(&src[s..e]).zip(&layer[s..e]) {
            *d = if l > 0.0 { m.max(l) } else { m };
        }
    }
}
