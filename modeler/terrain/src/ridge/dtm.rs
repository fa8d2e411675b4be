//! The DTM of Alg. 2.1, kept up to date polygon by polygon.
//!
//! Each cell holds the maximum over the polygons covering its centre (0, the ground, where none
//! does) — the *raw* layer — and, in a second array of the same size, the id of the polygon
//! that won it (Alg. 2.3). The output is the raw layer low-pass filtered ([`super::filter`]).
//!
//! Changing a skeleton ([`Dtm::set`]) compares its new polygons with the old ones by
//! [`Part`]; only those that differ are touched:
//!
//! 1. removed polygons: every cell of theirs that they won is reset to the ground (and marked);
//! 2. the remaining polygons overlapping those cells are rasterised again into the marked cells
//!    only (the seed's "re-rasterise only the affected polygons");
//! 3. added polygons are rasterised with max, as in a full build;
//! 4. the output is filtered again over the changed cells grown by the filter's reach.
//!
//! Every cell's value is the same `f64 → f32` of the same polygon evaluation, and max does not
//! depend on order, so the result equals a full rebuild bit for bit (the `ridges` tests check
//! it). Which polygon is recorded as the winner may differ where two polygons tie exactly.
//!
//! Why Alg. 2.3 and not Alg. 2.2 (per-cell lists sorted by elevation): the lists grow by an
//! entry per covering polygon (flanks of every nearby segment, joint fans) and need a sorted
//! insert per polygon per cell on every build and drag; the winner array is 4 bytes per cell
//! whatever the overlap. On the bench's one-segment move the two take the same time
//! (docs/ridgelines.md), so the fixed memory decides.

use std::collections::HashMap;

use rayon::prelude::*;

use super::Skeleton;
use super::filter::{self, Filter};
use super::polygon::{self, Part, Polygon, Prepared};
use crate::rect::Rect;

/// No polygon won the cell (it is ground).
pub const NONE: u32 = u32::MAX;

struct Slot {
    poly: Polygon,
    prepared: Prepared,
    outlines: Vec<Vec<[f64; 2]>>,
    rect: Rect,
}

/// A ridgeline DTM over a `cols × rows` grid.
pub struct Dtm {
    cols: u32,
    rows: u32,
    cell: f64,
    filter: Filter,
    raw: Vec<f32>,
    winner: Vec<u32>,
    /// Cells reset by a delete, waiting to be filled again (all false between updates).
    hole: Vec<bool>,
    out: Vec<f32>,
    slots: Vec<Option<Slot>>,
    free: Vec<u32>,
    keys: HashMap<(u32, Part), u32>,
}

impl std::fmt::Debug for Dtm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dtm")
            .field("cols", &self.cols)
            .field("rows", &self.rows)
            .field("polygons", &self.keys.len())
            .finish()
    }
}

impl Dtm {
    /// A DTM without ridgelines: all ground.
    pub fn new(cols: u32, rows: u32, cell_size: f64, filter: Filter) -> Dtm {
        let n = cols as usize * rows as usize;
        Dtm {
            cols,
            rows,
            cell: cell_size,
            filter,
            raw: vec![0.0; n],
            // Filled on all cores (4 bytes a cell to write and fault in).
            winner: rayon::iter::repeat_n(NONE, n).collect(),
            hole: vec![false; n],
            out: vec![0.0; n],
            slots: Vec::new(),
            free: Vec::new(),
            keys: HashMap::new(),
        }
    }

    /// The whole DTM of `skeletons` (each with its id) at once, on all cores: the reference an
    /// incremental update must equal.
    pub fn build(cols: u32, rows: u32, cell_size: f64, filter: Filter, skeletons: &[(u32, &Skeleton)]) -> Dtm {
        let mut d = Dtm::new(cols, rows, cell_size, filter);
        for (id, s) in skeletons {
            for (part, poly) in polygon::polygons(s) {
                d.insert(*id, part, poly);
            }
        }
        let (cols, cell) = (d.cols as usize, d.cell);
        let slots = &d.slots;
        const BAND: usize = 16;
        d.raw
            .par_chunks_mut(cols * BAND)
            .zip(d.winner.par_chunks_mut(cols * BAND))
            .enumerate()
            .for_each(|(band, (raw, win))| {
                let r0 = (band * BAND) as u32;
                let r1 = r0 + (raw.len() / cols) as u32;
                for (id, slot) in slots.iter().enumerate() {
                    let Some(slot) = slot else { continue };
                    let rr0 = slot.rect.r0.max(r0);
                    let rr1 = (slot.rect.r0 + slot.rect.height).min(r1);
                    for r in rr0..rr1 {
                        let base = (r - r0) as usize * cols;
                        raster_row(
                            slot,
                            slot.rect,
                            r,
                            cell,
                            id as u32,
                            None,
                            &mut raw[base..base + cols],
                            &mut win[base..base + cols],
                        );
                    }
                }
            });
        let all = Rect {
            c0: 0,
            r0: 0,
            width: d.cols,
            height: d.rows,
        };
        filter::apply(&d.raw, d.cols, d.filter, all, &mut d.out);
        d
    }

    /// Replaces skeleton `id` by `skeleton` (`None` removes it) and updates the DTM. Returns
    /// the cells whose output may have changed.
    pub fn set(&mut self, id: u32, skeleton: Option<&Skeleton>) -> Rect {
        let new: Vec<(Part, Polygon)> = skeleton.map(polygon::polygons).unwrap_or_default();
        let mut old: Vec<(Part, u32)> = self
            .keys
            .iter()
            .filter(|((s, _), _)| *s == id)
            .map(|((_, p), slot)| (*p, *slot))
            .collect();
        old.sort_unstable();
        let mut removed: Vec<u32> = Vec::new();
        let mut added: Vec<(Part, Polygon)> = Vec::new();
        let new_parts: HashMap<Part, &Polygon> = new.iter().map(|(p, g)| (*p, g)).collect();
        for (part, slot) in &old {
            match new_parts.get(part) {
                Some(g) if self.slots[*slot as usize].as_ref().is_some_and(|s| &s.poly == *g) => {}
                _ => removed.push(*slot),
            }
        }
        for (part, g) in new {
            let same = self
                .keys
                .get(&(id, part))
                .and_then(|s| self.slots[*s as usize].as_ref())
                .is_some_and(|s| s.poly == g);
            if !same {
                added.push((part, g));
            }
        }
        let mut dirty = Rect::EMPTY;
        // 1. Cells the removed polygons won go back to the ground.
        let mut hole = Rect::EMPTY;
        for &slot_id in &removed {
            let Some(slot) = self.slots[slot_id as usize].take() else {
                continue;
            };
            self.free.push(slot_id);
            self.keys.retain(|_, v| *v != slot_id);
            dirty = dirty.union(slot.rect);
            let w = self.cols as usize;
            for r in slot.rect.r0..slot.rect.r0 + slot.rect.height {
                for c in slot.rect.c0..slot.rect.c0 + slot.rect.width {
                    let i = r as usize * w + c as usize;
                    if self.winner[i] == slot_id {
                        self.winner[i] = NONE;
                        self.raw[i] = 0.0;
                        self.hole[i] = true;
                        hole = hole.union(Rect {
                            c0: c,
                            r0: r,
                            width: 1,
                            height: 1,
                        });
                    }
                }
            }
        }
        // 2. The remaining polygons over those cells fill them again.
        if hole.width > 0 {
            let w = self.cols as usize;
            for (sid, slot) in self.slots.iter().enumerate() {
                let Some(slot) = slot else { continue };
                let Some(meet) = intersect(slot.rect, hole) else {
                    continue;
                };
                for r in meet.r0..meet.r0 + meet.height {
                    let row = r as usize * w;
                    raster_row(
                        slot,
                        meet,
                        r,
                        self.cell,
                        sid as u32,
                        Some(&self.hole[row..row + w]),
                        &mut self.raw[row..row + w],
                        &mut self.winner[row..row + w],
                    );
                }
            }
        }
        for r in hole.r0..hole.r0 + hole.height {
            let row = r as usize * self.cols as usize;
            self.hole[row + hole.c0 as usize..row + (hole.c0 + hole.width) as usize].fill(false);
        }
        // 3. Added polygons with max.
        for (part, poly) in added {
            let sid = self.insert(id, part, poly);
            let Some(slot) = &self.slots[sid as usize] else {
                continue;
            };
            dirty = dirty.union(slot.rect);
            let w = self.cols as usize;
            for r in slot.rect.r0..slot.rect.r0 + slot.rect.height {
                let row = r as usize * w;
                raster_row(
                    slot,
                    slot.rect,
                    r,
                    self.cell,
                    sid,
                    None,
                    &mut self.raw[row..row + w],
                    &mut self.winner[row..row + w],
                );
            }
        }
        // 4. The output over the changed cells and as far as the filter carries them.
        let out_rect = filter::grow(dirty, self.filter.reach(), self.cols, self.rows);
        filter::apply(&self.raw, self.cols, self.filter, out_rect, &mut self.out);
        out_rect
    }

    fn insert(&mut self, id: u32, part: Part, poly: Polygon) -> u32 {
        let slot = Slot {
            prepared: poly.prepare(),
            outlines: poly.outlines(),
            rect: poly.cells(self.cols, self.rows, self.cell),
            poly,
        };
        let sid = match self.free.pop() {
            Some(s) => {
                self.slots[s as usize] = Some(slot);
                s
            }
            None => {
                self.slots.push(Some(slot));
                (self.slots.len() - 1) as u32
            }
        };
        self.keys.insert((id, part), sid);
        sid
    }

    /// The filtered DTM, row-major, metres.
    pub fn heights(&self) -> &[f32] {
        &self.out
    }

    /// The unfiltered maximum over the polygons, row-major, metres.
    pub fn raw(&self) -> &[f32] {
        &self.raw
    }

    /// Per cell, the id of the polygon that won it ([`NONE`] for ground).
    pub fn winners(&self) -> &[u32] {
        &self.winner
    }

    /// The filter.
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The cell size, metres.
    pub fn cell_size(&self) -> f64 {
        self.cell
    }

    /// Columns and rows.
    pub fn size(&self) -> (u32, u32) {
        (self.cols, self.rows)
    }

    /// How many polygons are rasterised.
    pub fn polygon_count(&self) -> usize {
        self.keys.len()
    }
}

fn intersect(a: Rect, b: Rect) -> Option<Rect> {
    let c0 = a.c0.max(b.c0);
    let r0 = a.r0.max(b.r0);
    let c1 = (a.c0 + a.width).min(b.c0 + b.width);
    let r1 = (a.r0 + a.height).min(b.r0 + b.height);
    (c0 < c1 && r0 < r1).then(|| Rect {
        c0,
        r0,
        width: c1 - c0,
        height: r1 - r0,
    })
}

/// Rasterises one row `r` of `poly` over `rect`'s columns into a grid row, keeping the maximum.
/// With `hole`, only the marked cells are written (those a delete reset to ground).
#[allow(clippy::too_many_arguments)] // one row of the raster loop, called from three places.
#[inline]
fn raster_row(
    slot: &Slot,
    rect: Rect,
    r: u32,
    cell: f64,
    id: u32,
    hole: Option<&[bool]>,
    raw: &mut [f32],
    win: &mut [u32],
) {
    let y = (f64::from(r) + 0.5) * cell;
    let Some((x0, x1)) = polygon::span(&slot.outlines, y) else {
        return;
    };
    // The cells whose centres fall in [x0, x1], a cell wider on each side for rounding; the
    // polygon's own test decides.
    let c0 = ((x0 / cell - 1.5).ceil().max(f64::from(rect.c0))) as u32;
    let c1 = ((x1 / cell + 0.5).floor().min(f64::from(rect.c0 + rect.width) - 1.0)).max(-1.0) as i64;
    let poly = &slot.prepared;
    for c in c0..(c1 + 1).max(i64::from(c0)) as u32 {
        let i = c as usize;
        if let Some(m) = hole
            && !m[i]
        {
            continue;
        }
        let x = (f64::from(c) + 0.5) * cell;
        if let Some(v) = poly.value([x, y]) {
            let v = v as f32;
            if v > raw[i] || (win[i] == NONE && v >= raw[i]) {
                raw[i] = v;
                win[i] = id;
            }
        }
    }
}
