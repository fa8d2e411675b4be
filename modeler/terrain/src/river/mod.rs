//! Rivers shaped by morphology (seed 003, Matsui 2010), carved into the terrain.
//!
//! A river's course is a chain of Bézier segments ([`course`]); its water is the sweep of a disc
//! of radius `width` along it. Each iteration (a "year") works on the current mask and centre
//! line:
//!
//! 1. every cell of the river's window takes the nearest centre-line sample ([`near`]);
//! 2. each sample has a curvature (the seed's κ), a turn sign (the cross product of successive
//!    tangents) and a structuring-element level ([`level`]): a diamond of `(2n − 1)²` cells;
//! 3. on the **outer** bank of each sample the mask is dilated by its diamond (erosion of the bank:
//!    the cells within `n − 1` city-block steps of the water join it), on the **inner** bank it is
//!    eroded (deposition: the water cells within `n − 1` of the land leave it) ([`morph`]);
//! 4. the centre line moves the same `n − 1` cells towards the outer bank (smoothed along the
//!    course, the ends fixed) and is resampled;
//! 5. where two parts of the line more than [`NECK_ARC`] widths apart along it come within two
//!    widths of each other, the bend's neck has closed: the loop's water becomes an oxbow lake
//!    (standing water, cut off from the river by a sediment plug [`PLUG`] cells wide), and the
//!    river continues straight through the neck.
//!
//! The processed shape is derived from the document's [`River`] entry, not stored: it regenerates
//! in milliseconds, and it needs no randomness. Carving it into a heightmap is [`carve`].

mod buffers;
pub mod carve;
pub mod course;
pub mod drag;
pub mod edt;
pub mod layer;
pub mod level;
pub mod morph;
pub mod near;

use glam::DVec2;
use rayon::prelude::*;

use crate::document::{Grid, River};
use course::Sample;
pub use level::Constants;
use near::{NONE, Near};

/// The most iterations a river may ask for (validation refuses more).
pub const MAX_ITERATIONS: u32 = 20;

/// The widest river (the disc's radius) in cells: each course sample visits cells across it, so the
/// work grows with the width's square (validation refuses wider).
pub const MAX_WIDTH_CELLS: f64 = 64.0;

/// Course samples per cell of length (spacing 1 cell).
pub const SPACING: f64 = 1.0;

/// Along-course separation, in widths, beyond which two close parts of the line are a neck.
pub const NECK_ARC: f64 = 10.0;

/// Width in cells of the sediment plug between an oxbow lake and the river.
pub const PLUG: f64 = 2.0;

/// Widths of course each way over which a bend's curvature is read and the line's yearly shift
/// averaged. A wiggle shorter than the span averages out: read over one width, a wiggle of a few
/// cells had the largest curvature of the course, got the largest diamond and grew every year
/// into a chain of small loops, each cut off as an oxbow lake (`meander(512, 14, 4 m)`, six
/// bends, had 155 lakes after 20 years; 31 with this span). Natural meanders are some 10 to 14
/// widths long, so ±3 widths still sees each of their bends.
pub const BEND_SPAN: f64 = 3.0;

/// Cells beyond the water that a sample's field reaches: the largest diamond's reach and one.
const REACH: f64 = morph::MAX_LEVEL as f64;

/// A meandering river across a `size × size` grid of 1 m cells, for benches, the command line's
/// examples and the demo: a sine course of `anchors` anchors (`3·(anchors − 1) + 1` control
/// points) from the left edge to the right, amplitude a sixth of the grid, `width` m wide (the
/// disc radius) and half as deep.
pub fn meander(size: u32, anchors: usize, width: f64, iterations: u32) -> River {
    let n = f64::from(size);
    let stroke: Vec<DVec2> = (0..=400)
        .map(|k| {
            let t = f64::from(k) / 400.0;
            DVec2::new(
                n * (0.04 + 0.92 * t),
                n * (0.5 + (t * std::f64::consts::TAU * 3.0).sin() / 6.0),
            )
        })
        .collect();
    River {
        points: course::fit(&stroke, anchors).iter().map(|p| [p.x, p.y]).collect(),
        width,
        depth: width / 2.0,
        water: 60.0,
        hardness: 1.0,
        iterations,
    }
}

/// A rectangle of the grid a river works in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// First column.
    pub c0: u32,
    /// First row.
    pub r0: u32,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

impl Window {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether it has no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Its first cell in grid cell coordinates.
    pub fn origin(&self) -> DVec2 {
        DVec2::new(f64::from(self.c0), f64::from(self.r0))
    }

    /// The grid index of window index `i`, for a grid of `cols` columns.
    pub fn grid_index(&self, i: usize, cols: u32) -> usize {
        (self.r0 as usize + i / self.width) * cols as usize + self.c0 as usize + i % self.width
    }
}

/// One course sample as the tools report it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleInfo {
    /// Position in metres.
    pub at: [f64; 2],
    /// Curvature in 1/m.
    pub curvature: f64,
    /// +1 bending left (x right, y up), −1 right, 0 straight; the outer bank is the other side.
    pub turn: i8,
    /// The structuring element's level.
    pub level: u8,
}

/// What one iteration did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Iteration {
    /// River cells after it.
    pub area: usize,
    /// Cells the outer banks lost to the water.
    pub eroded: usize,
    /// Cells the inner banks gained from the water.
    pub deposited: usize,
    /// The areas (cells) of the oxbow lakes it cut off.
    pub oxbows: Vec<usize>,
    /// Oxbow lakes so far, and their cells.
    pub lakes: usize,
    /// Cells of all lakes so far.
    pub lake_area: usize,
}

/// The erosion (cells that would join the water) and deposition (cells that would leave it) of
/// the next iteration, over the window: what the seed's interface shows red and light blue.
#[derive(Debug, Clone, PartialEq)]
pub struct Preview {
    /// Cells the outer banks would lose, 0/1.
    pub erosion: Vec<u8>,
    /// Cells the inner banks would gain, 0/1.
    pub deposition: Vec<u8>,
}

/// A river's processed shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Shape {
    /// Where it is.
    pub window: Window,
    /// Cell size in metres.
    pub cell_size: f64,
    /// The disc radius in cells.
    pub radius: f64,
    /// The centre line, grid cell coordinates (cell centres at integers).
    pub line: Vec<Sample>,
    /// Each sample's level.
    pub levels: Vec<u8>,
    /// Each sample's turn sign.
    pub turns: Vec<i8>,
    /// River water, 0/1 over the window.
    pub mask: Vec<u8>,
    /// Lake cells: 0 none, k for lake k − 1.
    pub lakes: Vec<u16>,
    /// Each lake's neck, where it was cut off (grid cell coordinates).
    pub necks: Vec<DVec2>,
    /// Nearest-sample field of the window.
    pub near: Near,
    /// What each iteration did.
    pub history: Vec<Iteration>,
    river: River,
    constants: Constants,
}

impl Shape {
    /// The river as drawn: the disc sweep of its course, no iteration yet.
    pub fn new(river: &River, grid: &Grid, constants: &Constants) -> Shape {
        let s = grid.cell_size;
        let ctrl: Vec<DVec2> = river
            .points
            .iter()
            .map(|p| DVec2::new(p[0] / s - 0.5, p[1] / s - 0.5))
            .collect();
        let radius = river.width / s;
        // Room for the water, the largest diamond, and the line's migration.
        let grow = radius + REACH + 2.0 + (REACH - 1.0) * f64::from(river.iterations.min(MAX_ITERATIONS) + 1);
        let (lo, hi) = ctrl
            .iter()
            .fold((DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let clip = |v: f64, n: u32| v.clamp(0.0, f64::from(n)) as u32;
        let (c0, c1) = (
            clip((lo.x - grow).floor(), grid.cols),
            clip((hi.x + grow).ceil() + 1.0, grid.cols),
        );
        let (r0, r1) = (
            clip((lo.y - grow).floor(), grid.rows),
            clip((hi.y + grow).ceil() + 1.0, grid.rows),
        );
        let window = Window {
            c0,
            r0,
            width: (c1 - c0) as usize,
            height: (r1 - r0) as usize,
        };
        let line = course::sample(&ctrl, SPACING);
        let mut shape = Shape {
            window,
            cell_size: s,
            radius,
            line: Vec::new(),
            levels: Vec::new(),
            turns: Vec::new(),
            mask: buffers::MASKS.filled(window.len(), 0),
            lakes: buffers::LAKES.filled(window.len(), 0),
            necks: Vec::new(),
            near: Near::in_buffers(
                buffers::OWNERS.unfilled(0, NONE),
                buffers::DISTS.unfilled(0, 0.0),
                buffers::SIDES.unfilled(0, 0),
            ),
            history: Vec::new(),
            river: river.clone(),
            constants: *constants,
        };
        shape.set_line(line);
        for (m, d) in shape.mask.iter_mut().zip(&shape.near.dist) {
            *m = u8::from(f64::from(*d) <= radius);
        }
        shape
    }

    /// The river after its `iterations` (at most [`MAX_ITERATIONS`]).
    pub fn process(river: &River, grid: &Grid, constants: &Constants) -> Shape {
        on_pool(|| {
            let mut shape = Shape::new(river, grid, constants);
            for _ in 0..river.iterations.min(MAX_ITERATIONS) {
                shape.step_here();
            }
            shape
        })
    }

    /// Gives its per-cell buffers back for the next shape (a river processed again and again, as
    /// in a drag's preview, then reuses them).
    pub fn recycle(self) {
        buffers::MASKS.give(self.mask);
        buffers::LAKES.give(self.lakes);
        let (owner, dist, side) = self.near.into_buffers();
        buffers::OWNERS.give(owner);
        buffers::DISTS.give(dist);
        buffers::SIDES.give(side);
    }

    /// The samples with their curvature, turn and level.
    pub fn samples(&self) -> Vec<SampleInfo> {
        let s = self.cell_size;
        self.line
            .iter()
            .zip(self.levels.iter().zip(&self.turns))
            .map(|(p, (&level, &turn))| SampleInfo {
                at: [(p.p.x + 0.5) * s, (p.p.y + 0.5) * s],
                curvature: p.curvature() / s,
                turn,
                level,
            })
            .collect()
    }

    /// Takes `line` as the centre line: levels, turns and the nearest-sample field.
    fn set_line(&mut self, line: Vec<Sample>) {
        let pts: Vec<DVec2> = line.iter().map(|p| p.p).collect();
        let (window, reach) = (self.window, self.radius + REACH);
        let (m, cell) = (self.span(), self.cell_size);
        let levels = level::Levels::new(&self.river, cell, &self.constants);
        let near = &mut self.near;
        // The bends and levels while the other core starts on the field (which does not read
        // them).
        let ((turns, levels), ()) = rayon::join(
            || bends(&line, m, cell, &levels),
            || near::nearest_into(&window, &pts, reach, near),
        );
        self.turns = turns;
        self.levels = levels;
        self.line = line;
    }

    /// Samples each way over which the line's derivatives are taken: a width, at least 2.
    fn stencil(&self) -> usize {
        (self.radius.round() as usize).max(2)
    }

    /// Samples each way over which a bend is read and the line's shift averaged: [`BEND_SPAN`]
    /// widths, at least 2.
    fn span(&self) -> usize {
        ((BEND_SPAN * self.radius).round() as usize).max(2)
    }

    /// The cells the next iteration adds to the water (outer banks) and removes from it (inner
    /// banks), as window indices in increasing order.
    ///
    /// A land cell joins when water is within its sample's reach (`level − 1` city-block steps),
    /// a water cell leaves when land of the window is: the water and the land are dilated by one
    /// cross after another on bit-packed images ([`morph::Bits`]), and only the cells within the
    /// largest reach of the other value (the banks) are looked at.
    fn changes(&self) -> (Vec<usize>, Vec<usize>) {
        let (w, h) = (self.window.width, self.window.height);
        let most = self.levels.iter().max().map_or(0, |&l| usize::from(l.max(1)) - 1);
        if most == 0 || w == 0 {
            return (Vec::new(), Vec::new());
        }
        // Images from kept buffers (each written whole before it is read).
        let image = || morph::Bits::in_buffer(w, h, buffers::WORDS.unfilled(w.div_ceil(64) * h, 0));
        // `near_water[r]`: the cells within r steps of the water; `near_land[r]`: of the land.
        let grow = |first: morph::Bits| {
            let mut all = vec![first];
            for r in 1..=most {
                let mut next = image();
                all[r - 1].cross(&mut next, true);
                all.push(next);
            }
            all
        };
        let mut water = image();
        water.set_from_here(&self.mask, true);
        let mut land = image();
        water.complement(&mut land);
        // The water's crosses and the land's on a core each.
        let (near_water, near_land) = rayon::join(|| grow(water), || grow(land));
        let (water, land) = (&near_water[0], &near_land[0]);
        // The banks of rows `rows`, in order.
        let banks = |rows: std::ops::Range<usize>| {
            let (mut add, mut remove) = (Vec::new(), Vec::new());
            for r in rows {
                let banks = (land.row(r).iter().zip(near_water[most].row(r)))
                    .zip(water.row(r).iter().zip(near_land[most].row(r)))
                    .map(|((l, nw), (wa, nl))| (l & nw) | (wa & nl));
                for (k, mut word) in banks.enumerate() {
                    while word != 0 {
                        let c = k * 64 + word.trailing_zeros() as usize;
                        word &= word - 1;
                        let i = r * w + c;
                        let o = self.near.owner[i];
                        if o == NONE {
                            continue;
                        }
                        let (reach, turn) = (usize::from(self.levels[o as usize]) - 1, self.turns[o as usize]);
                        let side = self.near.side[i];
                        if reach == 0 || turn == 0 || side == 0 {
                            continue;
                        }
                        // Bending left, the centre of the bend is on the left: the outer bank is
                        // the right.
                        let outer = side == -turn;
                        let at = |b: &morph::Bits| b.row(r)[k] >> (c % 64) & 1 != 0;
                        if self.mask[i] == 0 {
                            if outer && at(&near_water[reach]) {
                                add.push(i);
                            }
                        } else if !outer && at(&near_land[reach]) {
                            remove.push(i);
                        }
                    }
                }
            }
            (add, remove)
        };
        // Two bands of rows on a core each, joined in order.
        let ((mut add, mut remove), (add1, remove1)) = rayon::join(|| banks(0..h / 2), || banks(h / 2..h));
        add.extend(add1);
        remove.extend(remove1);
        for bits in near_water.into_iter().chain(near_land) {
            buffers::WORDS.give(bits.into_buffer());
        }
        (add, remove)
    }

    /// The next iteration's erosion and deposition.
    pub fn preview(&self) -> Preview {
        let (add, remove) = self.changes();
        let mut erosion = vec![0; self.window.len()];
        let mut deposition = vec![0; self.window.len()];
        for i in add {
            erosion[i] = 1;
        }
        for i in remove {
            deposition[i] = 1;
        }
        Preview { erosion, deposition }
    }

    /// One iteration (module docs, steps 1–5).
    pub fn step(&mut self) {
        on_pool(|| self.step_here());
    }

    /// [`Shape::step`] on the calling thread.
    fn step_here(&mut self) {
        let (add, remove) = self.changes();
        for &i in &add {
            self.mask[i] = 1;
        }
        for &i in &remove {
            self.mask[i] = 0;
        }
        let mut record = Iteration {
            eroded: add.len(),
            deposited: remove.len(),
            ..Iteration::default()
        };
        let moved = self.migrate();
        let (pts, cuts) = self.cut_necks(moved);
        let line = course::resample(&pts, SPACING, self.stencil());
        // The loops' water, as owned by the line before it moved, becomes lakes.
        let old_owner = std::mem::take(&mut self.near.owner);
        let mut lake_cells: Vec<(usize, u16)> = Vec::new();
        for (i, &o) in old_owner.iter().enumerate() {
            if cuts.is_empty() {
                break;
            }
            if o == NONE || self.mask[i] == 0 {
                continue;
            }
            if let Some(k) = cuts.iter().position(|&(a, b, _)| (a as u32) < o && o < b as u32) {
                lake_cells.push((i, (self.necks.len() + k + 1) as u16));
            }
        }
        for &(i, id) in &lake_cells {
            self.mask[i] = 0;
            self.lakes[i] = id;
        }
        // The buffer back for the new field.
        self.near.owner = old_owner;
        self.set_line(line);
        for &(_, _, neck) in &cuts {
            near::sweep_segment(&self.window, &mut self.mask, neck.0, neck.1, self.radius);
            self.necks.push((neck.0 + neck.1) * 0.5);
        }
        // The plug: lake cells next to the river's new course silt up; in the same pass, the
        // river's area and each lake's.
        let mut lake_area = vec![0usize; self.necks.len() + 1];
        // Counted in bytes by runs of 255 (a byte per lane, 16 lanes to a vector).
        let area: usize = (self.mask.chunks(255))
            .map(|run| usize::from(run.iter().map(|&m| u8::from(m != 0)).sum::<u8>()))
            .sum();
        let plug = self.radius + PLUG;
        // Once a neck has closed, by runs of 64 cells: the lakes are few and small, so most runs
        // have no lake cell.
        if !self.necks.is_empty() {
            let runs = self
                .lakes
                .chunks_mut(64)
                .zip(self.mask.chunks(64))
                .zip(self.near.dist.chunks(64));
            for ((lakes, mask), dist) in runs {
                if lakes.iter().all(|&l| l == 0) {
                    continue;
                }
                for ((l, &m), &d) in lakes.iter_mut().zip(mask).zip(dist) {
                    if *l != 0 && (f64::from(d) <= plug || m != 0) {
                        *l = 0;
                    }
                    lake_area[*l as usize] += 1;
                }
            }
        }
        let first_new = self.necks.len() - cuts.len();
        record.oxbows = lake_area[first_new + 1..].to_vec();
        record.area = area;
        record.lake_area = lake_area[1..].iter().sum();
        record.lakes = lake_area[1..].iter().filter(|&&a| a > 0).count();
        self.history.push(record);
    }

    /// The centre line moved towards the outer banks by each sample's reach, smoothed over a
    /// width along the course, the ends fixed.
    fn migrate(&self) -> Vec<DVec2> {
        let n = self.line.len();
        let m = self.span();
        let raw: Vec<DVec2> = (0..n)
            .map(|i| {
                let turn = f64::from(self.turns[i]);
                let reach = f64::from(self.levels[i]) - 1.0;
                let left = self.line[i].d1.normalize_or_zero().perp();
                -left * turn * reach
            })
            .collect();
        let sums = window_sums(&raw, m, DVec2::ZERO);
        // Each sample on its own (the recentring walks across the water), so on the thread pool:
        // in two halves, one join (each join may wait for the other thread to wake).
        let moved: Vec<DVec2> = (0..n)
            .into_par_iter()
            .with_min_len(n.div_ceil(2).max(256))
            .map(|i| {
                let (a, b) = (i.saturating_sub(m), (i + m).min(n - 1));
                let mean = sums[i] / (b - a + 1) as f64;
                let taper = (i.min(n - 1 - i) as f64 / m as f64).min(1.0);
                let p = self.line[i].p + mean * taper;
                if taper < 1.0 {
                    p
                } else {
                    self.recentre(p, self.line[i].d1)
                }
            })
            .collect();
        // The water's middle moves in whole cells; a light smoothing keeps the line's curvature
        // from seeing the steps.
        let mut smooth = moved;
        for _ in 0..2 {
            let prev = smooth.clone();
            for i in 1..n.saturating_sub(1) {
                smooth[i] = (prev[i - 1] + prev[i] * 2.0 + prev[i + 1]) * 0.25;
            }
        }
        smooth
    }

    /// The middle of the water across the course at `p` (direction `d1`): the mid-point of the
    /// run of water cells along the normal through `p`, or `p` if it is dry.
    fn recentre(&self, p: DVec2, d1: DVec2) -> DVec2 {
        let normal = d1.normalize_or_zero().perp();
        // The cell under p + normal · t for t = k/2: the nearest cell centre, as the floor of
        // the position plus half a cell (a truncation where it is not negative; outside the
        // window where it is).
        let w = self.window.width;
        let size = DVec2::new(w as f64, self.window.height as f64);
        let base = p - self.window.origin() + DVec2::splat(0.5);
        let step = normal * 0.5;
        let wet = |k: f64| -> bool {
            let q = base + step * k;
            // In the window (the floor of q is below the size where q is), then whole cells.
            q.x >= 0.0
                && q.y >= 0.0
                && q.x < size.x
                && q.y < size.y
                && self.mask[q.y as u32 as usize * w + q.x as u32 as usize] != 0
        };
        if normal == DVec2::ZERO || !wet(0.0) {
            return p;
        }
        // Half-cell steps each way while the water lasts.
        let limit = 2.0 * (self.radius + 2.0 * REACH);
        let (mut lo, mut hi) = (0.0, 0.0);
        while lo > -limit && wet(lo - 1.0) {
            lo -= 1.0;
        }
        while hi < limit && wet(hi + 1.0) {
            hi += 1.0;
        }
        p + normal * ((lo + hi) * 0.25)
    }

    /// Closes the necks of `pts`: returns the line with each loop cut out, and per cut the loop's
    /// first and last sample indices in `pts` (exclusive) and the neck segment.
    #[allow(clippy::type_complexity)]
    fn cut_necks(&self, pts: Vec<DVec2>) -> (Vec<DVec2>, Vec<(usize, usize, (DVec2, DVec2))>) {
        let reach = 2.0 * self.radius;
        let gap = ((NECK_ARC * self.radius / SPACING).ceil() as usize).max(3);
        let n = pts.len();
        // Buckets of `reach` cells: a close pair is in the same or neighbouring buckets.
        let b = reach.max(1.0);
        let keys: Vec<(i64, i64)> = pts
            .iter()
            .map(|p| ((p.x / b).floor() as i64, (p.y / b).floor() as i64))
            .collect();
        // The samples by bucket in a table of `slots` (a power of two) hashed from the bucket's
        // key, each slot's in order along the line: slot `h`'s are `order[start[h]..start[h + 1]]`
        // (a slot may hold more than one bucket's samples: a lookup checks the key).
        let slots = (2 * n).next_power_of_two().max(16);
        let slot = |(kx, ky): (i64, i64)| {
            let h = (kx as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (ky as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
            (h >> 32) as usize & (slots - 1)
        };
        let mut start = vec![0u32; slots + 1];
        for &k in &keys {
            start[slot(k) + 1] += 1;
        }
        for h in 0..slots {
            start[h + 1] += start[h];
        }
        let mut order = vec![0u32; n];
        let mut next = start.clone();
        for (i, &k) in keys.iter().enumerate() {
            let h = slot(k);
            order[next[h] as usize] = i as u32;
            next[h] += 1;
        }
        let samples = |k: (i64, i64)| {
            let h = slot(k);
            &order[start[h] as usize..start[h + 1] as usize]
        };
        let mut cuts = Vec::new();
        // The samples of the buckets around `around` (those of the last sample, mostly).
        let (mut near, mut around): ([&[u32]; 9], Option<(i64, i64)>) = ([&[]; 9], None);
        let mut i = 0;
        while i < n {
            let (kx, ky) = keys[i];
            if around != Some((kx, ky)) {
                for (m, bucket) in near.iter_mut().enumerate() {
                    *bucket = samples((kx + m as i64 / 3 - 1, ky + m as i64 % 3 - 1));
                }
                around = Some((kx, ky));
            }
            // The farthest sample along the line beyond the gap within reach: in each bucket the
            // last one that is (slots are in order along the line too).
            let mut far = None;
            for (m, bucket) in near.iter().enumerate() {
                let k = (kx + m as i64 / 3 - 1, ky + m as i64 % 3 - 1);
                for &j in bucket.iter().rev() {
                    let j = j as usize;
                    if j <= i + gap {
                        break;
                    }
                    if keys[j] == k && pts[i].distance(pts[j]) < reach {
                        far = far.max(Some(j));
                        break;
                    }
                }
            }
            match far {
                Some(j) => {
                    cuts.push((i, j, (pts[i], pts[j])));
                    i = j;
                }
                None => i += 1,
            }
        }
        if cuts.is_empty() {
            return (pts, cuts);
        }
        let mut out = Vec::with_capacity(n);
        let mut from = 0;
        for &(a, b, _) in &cuts {
            out.extend_from_slice(&pts[from..=a]);
            from = b;
        }
        out.extend_from_slice(&pts[from..]);
        (out, cuts)
    }
}

/// Each sample's turn sign and level (cells of `cell` metres). A bend is read over `m` samples
/// ([`BEND_SPAN`] widths of the course) each way: the seed's κ with its sign, averaged, so a
/// wiggle shorter than a bend neither swaps the banks nor makes a level of its own.
fn bends(line: &[Sample], m: usize, cell: f64, levels: &level::Levels) -> (Vec<i8>, Vec<u8>) {
    let signed: Vec<f64> = line
        .iter()
        .map(|p| p.d1.perp_dot(p.d2) / p.d1.length().powi(3).max(1e-12))
        .collect();
    // Summed as `Iterator::sum` does: from its neutral element, in order.
    let sums = window_sums(&signed, m, std::iter::empty::<f64>().sum());
    (0..line.len())
        .map(|i| {
            let span = (i + m).min(line.len() - 1) + 1 - i.saturating_sub(m);
            let b = sums[i] / span as f64;
            let turn = if b.abs() < 1e-9 { 0 } else { b.signum() as i8 };
            (turn, levels.at(b.abs() / cell))
        })
        .unzip()
}

/// Each element's sum over the elements within `m` of it (clipped to the slice), in order from
/// the first, starting at `zero`: `zero + v[a] + … + v[b]`. Each sum is a chain of dependent
/// additions, so four are run side by side (one at a time waits out each addition's latency).
fn window_sums<T: Copy + std::ops::Add<Output = T>>(v: &[T], m: usize, zero: T) -> Vec<T> {
    let n = v.len();
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        if i >= m && i + 3 + m < n {
            // Four whole windows, `i − m ..= i + m` to `i + 3 − m ..= i + 3 + m`.
            let mut acc = [zero; 4];
            for j in i - m..=i + m {
                let four = &v[j..j + 4];
                for (a, &x) in acc.iter_mut().zip(four) {
                    *a = *a + x;
                }
            }
            out.extend_from_slice(&acc);
            i += 4;
        } else {
            let (a, b) = (i.saturating_sub(m), (i + m).min(n - 1));
            out.push(v[a..=b].iter().fold(zero, |s, &x| s + x));
            i += 1;
        }
    }
    out
}

/// `f` run on a thread of the pool. A year forks and joins a few times (the field's bands, the
/// crosses, the banks, the recentring); from a thread outside the pool each `rayon::join` hands
/// its work to the pool and blocks the caller on a lock until it is done (some 60 hand-overs and
/// wake-ups per `drag/512/10` call), from a thread of the pool it only queues the second half.
pub(crate) fn on_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}
