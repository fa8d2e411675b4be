//! The rivers of a document over its terrain: each river's processed shape and carving, and the
//! carved heightmap and water, kept up to date incrementally.
//!
//! A river's shape depends only on its entry; its carving on its shape and the ground under its
//! window. [`Layer::sync`] compares the document's entries with the cached ones, reprocesses the
//! rivers that changed, recarves those whose window meets the ground that changed, and
//! recomposites only the union of those windows: `carved = min(ground, every river's target)`.

use super::carve::{self, Carve};
use super::{Constants, Shape, Window};
use crate::document::{Document, River};
use crate::export::Mesh;
use crate::heightmap::Heightmap;

/// Water over the grid: its surface level per cell (NaN where dry) and whether it stands (lakes).
#[derive(Debug, Clone, PartialEq)]
pub struct Water {
    /// Columns.
    pub cols: u32,
    /// Rows.
    pub rows: u32,
    /// Surface level per cell, row-major, NaN where dry.
    pub level: Vec<f32>,
    /// Whether the water of a cell is a lake.
    pub lake: Vec<bool>,
}

impl Water {
    /// Whether any cell is wet.
    pub fn any(&self) -> bool {
        self.level.iter().any(|l| !l.is_nan())
    }

    /// The water surface as a mesh in the terrain mesh's frame (`[x, level, y]`, Y up): a flat
    /// square at its level over each wet cell, normals up.
    pub fn mesh(&self, cell_size: f64) -> Mesh {
        let mut m = Mesh::default();
        for (i, &l) in self.level.iter().enumerate() {
            if l.is_nan() {
                continue;
            }
            let (c, r) = ((i % self.cols as usize) as f64, (i / self.cols as usize) as f64);
            let a = m.positions.len() as u32;
            for (dc, dr) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                m.positions
                    .push([((c + dc) * cell_size) as f32, l, ((r + dr) * cell_size) as f32]);
                m.normals.push([0.0, 1.0, 0.0]);
            }
            // Counter-clockwise seen from +Y, as the terrain's triangles.
            m.indices.extend_from_slice(&[a, a + 2, a + 1, a + 1, a + 2, a + 3]);
        }
        m
    }
}

struct Cached {
    river: River,
    shape: Shape,
    carve: Carve,
}

/// The rivers' caches and the carved terrain.
#[derive(Default)]
pub struct Layer {
    cached: Vec<Cached>,
    carved: Option<(Heightmap, Water)>,
}

impl std::fmt::Debug for Layer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Layer").field("rivers", &self.cached.len()).finish()
    }
}

fn rect_of(w: &Window) -> Window {
    *w
}

fn meets(a: &Window, b: &Window) -> bool {
    a.width > 0
        && a.height > 0
        && b.width > 0
        && b.height > 0
        && (a.c0 as usize) < b.c0 as usize + b.width
        && (b.c0 as usize) < a.c0 as usize + a.width
        && (a.r0 as usize) < b.r0 as usize + b.height
        && (b.r0 as usize) < a.r0 as usize + a.height
}

fn union(a: Option<Window>, b: Window) -> Option<Window> {
    if b.is_empty() {
        return a;
    }
    Some(a.map_or(b, |a| {
        let (c0, r0) = (a.c0.min(b.c0), a.r0.min(b.r0));
        let c1 = (a.c0 as usize + a.width).max(b.c0 as usize + b.width);
        let r1 = (a.r0 as usize + a.height).max(b.r0 as usize + b.height);
        Window {
            c0,
            r0,
            width: c1 - c0 as usize,
            height: r1 - r0 as usize,
        }
    }))
}

impl Layer {
    /// The carved terrain and its water, or `None` when the document has no rivers.
    pub fn carved(&self) -> Option<&(Heightmap, Water)> {
        self.carved.as_ref()
    }

    /// The processed shape of river `i`.
    pub fn shape(&self, i: usize) -> Option<&Shape> {
        self.cached.get(i).map(|c| &c.shape)
    }

    /// Brings the rivers up to date with `doc` over `ground`, whose cells in `ground_changed`
    /// changed since the last call; returns the cells whose carved height or water may have
    /// changed (beyond `ground_changed`). The rectangles are the engine's
    /// (the cell rectangle of the `rect` module, through `From`) or windows.
    pub fn sync<R: From<Window> + Into<Window>>(
        &mut self,
        doc: &Document,
        ground: &Heightmap,
        ground_changed: R,
    ) -> Option<R> {
        let ground_changed: Window = ground_changed.into();
        let constants = Constants::default();
        let mut dirty: Option<Window> = None;
        // Rivers gone.
        while self.cached.len() > doc.rivers.len() {
            if let Some(c) = self.cached.pop() {
                dirty = union(dirty, rect_of(&c.carve.window));
            }
        }
        for (i, r) in doc.rivers.iter().enumerate() {
            match self.cached.get_mut(i) {
                Some(c) if c.river == *r => {
                    if meets(&rect_of(&c.carve.window), &ground_changed) {
                        c.carve = carve::carve(&c.shape, r.width, r.depth, ground);
                        dirty = union(dirty, rect_of(&c.carve.window));
                    }
                }
                slot => {
                    let shape = Shape::process(r, &doc.grid, &constants);
                    let carve = carve::carve(&shape, r.width, r.depth, ground);
                    dirty = union(dirty, rect_of(&carve.window));
                    let fresh = Cached {
                        river: r.clone(),
                        shape,
                        carve,
                    };
                    match slot {
                        Some(old) => {
                            dirty = union(dirty, rect_of(&old.carve.window));
                            *old = fresh;
                        }
                        None => self.cached.push(fresh),
                    }
                }
            }
        }
        if self.cached.is_empty() {
            self.carved = None;
            return dirty.map(R::from);
        }
        let all = Window {
            c0: 0,
            r0: 0,
            width: ground.cols() as usize,
            height: ground.rows() as usize,
        };
        let (map, water) = self.carved.get_or_insert_with(|| {
            dirty = Some(all);
            let cells = ground.heights().len();
            (
                ground.clone(),
                Water {
                    cols: ground.cols(),
                    rows: ground.rows(),
                    level: vec![f32::NAN; cells],
                    lake: vec![false; cells],
                },
            )
        });
        let rect = union(dirty, ground_changed)?;
        composite(&self.cached, ground, map, water, &rect);
        Some(R::from(rect))
    }
}

/// `carved = min(ground, targets)` and the water, over `rect`.
fn composite(cached: &[Cached], ground: &Heightmap, map: &mut Heightmap, water: &mut Water, rect: &Window) {
    let cols = ground.cols() as usize;
    let (c1, r1) = (rect.c0 + rect.width as u32, rect.r0 + rect.height as u32);
    {
        let out = map.heights_mut();
        for r in rect.r0..r1 {
            let row = r as usize * cols;
            let span = row + rect.c0 as usize..row + c1 as usize;
            out[span.clone()].copy_from_slice(&ground.heights()[span.clone()]);
            water.level[span.clone()].fill(f32::NAN);
            water.lake[span].fill(false);
        }
    }
    for c in cached {
        let w = c.carve.window;
        let (a0, a1) = (w.c0.max(rect.c0), (w.c0 + w.width as u32).min(c1));
        let (b0, b1) = (w.r0.max(rect.r0), (w.r0 + w.height as u32).min(r1));
        let out = map.heights_mut();
        for r in b0..b1 {
            for col in a0..a1 {
                let i = (r - w.r0) as usize * w.width + (col - w.c0) as usize;
                let g = r as usize * cols + col as usize;
                let t = c.carve.target[i];
                if out[g] > t {
                    out[g] = t;
                }
                let l = c.carve.water[i];
                if !l.is_nan() && (water.level[g].is_nan() || water.level[g] < l) {
                    water.level[g] = l;
                    water.lake[g] = c.carve.lake[i];
                }
            }
        }
    }
}
