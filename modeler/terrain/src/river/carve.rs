//! A processed river carved into a heightmap: a bed under its water, lakes, blended banks.
//!
//! - **Water surface** along the course: the ground under each centre-line sample, as its running
//!   minimum from the first sample (water never flows uphill: where the terrain rises the river
//!   cuts through it), [`FREEBOARD`] × depth below it.
//! - **Bed**: under a water cell, the surface of its sample minus `depth × profile(u)`, `u` the
//!   cell's distance from the centre line in widths (clamped to 1): `1 − u²` towards the outer
//!   bank (a steep cut bank), `(1 − u)²` towards the inner bank (a shallow point bar), and at
//!   least [`WET`] so every water cell holds water. The cells under the centre line then descend
//!   along the course (the thalweg: each is lowered to the lowest before it if needed).
//! - **Lakes**: their surface is the river's at the neck that cut them off, their bed
//!   [`LAKE_DEPTH`] × depth below it.
//! - **Banks**: land cells within a width (at least 2 cells) of water are lowered towards the
//!   water's edge linearly with their Euclidean distance to it ([`edt`]); nothing is raised.
//!
//! The result is a target height per cell; the terrain is the lower of the ground and every
//! river's target, so rivers over the same ground combine in any order.

use super::edt;
use super::near::NONE;
use super::{Shape, Window};
use crate::heightmap::Heightmap;

/// How far below the lowest ground upstream the water surface lies, × depth.
pub const FREEBOARD: f64 = 0.2;
/// The least water depth of a river cell, × depth.
pub const WET: f64 = 0.1;
/// An oxbow lake's depth, × the river's depth.
pub const LAKE_DEPTH: f64 = 0.6;

/// A river's carving over its window.
#[derive(Debug, Clone, PartialEq)]
pub struct Carve {
    /// Where.
    pub window: Window,
    /// The height the river lowers each cell to (∞ where it leaves the ground alone).
    pub target: Vec<f32>,
    /// The water surface over each cell (NaN where dry).
    pub water: Vec<f32>,
    /// Whether a wet cell is lake (standing water).
    pub lake: Vec<bool>,
}

/// The ground height under a grid-coordinate point (its cell, clamped to the grid).
fn ground_at(ground: &Heightmap, p: glam::DVec2) -> f64 {
    let c = p.x.round().clamp(0.0, f64::from(ground.cols() - 1)) as u32;
    let r = p.y.round().clamp(0.0, f64::from(ground.rows() - 1)) as u32;
    f64::from(ground.get(c, r))
}

/// Carves `shape` (of a river `depth` metres deep and `width` wide) into `ground`.
pub fn carve(shape: &Shape, width: f64, depth: f64, ground: &Heightmap) -> Carve {
    let win = shape.window;
    // The water surface along the course.
    let mut low = f64::INFINITY;
    let surface: Vec<f64> = shape
        .line
        .iter()
        .map(|s| {
            low = low.min(ground_at(ground, s.p));
            low - FREEBOARD * depth
        })
        .collect();
    let lake_surface: Vec<f64> = shape
        .necks
        .iter()
        .map(|n| {
            let k = shape
                .line
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.p.distance_squared(*n).total_cmp(&b.1.p.distance_squared(*n)))
                .map_or(0, |(k, _)| k);
            surface.get(k).copied().unwrap_or(0.0)
        })
        .collect();
    let n = win.len();
    let mut target = vec![f32::INFINITY; n];
    let mut water = vec![f32::NAN; n];
    let mut lake = vec![false; n];
    let wet: Vec<u8> = (0..n)
        .map(|i| u8::from(shape.mask[i] != 0 || shape.lakes[i] != 0))
        .collect();
    // Euclidean, so the banks' contours are round rather than the diamonds' stairs.
    let to_water = edt::euclidean(&wet, win.width, win.height);
    let bank = (width / shape.cell_size).round().max(2.0);
    for i in 0..n {
        let o = shape.near.owner[i];
        if shape.lakes[i] != 0 {
            let level = lake_surface[shape.lakes[i] as usize - 1];
            target[i] = (level - LAKE_DEPTH * depth) as f32;
            water[i] = level as f32;
            lake[i] = true;
        } else if o == NONE {
            continue;
        } else if shape.mask[i] != 0 {
            let level = surface[o as usize];
            let u = (f64::from(shape.near.dist[i]) * shape.cell_size / width).clamp(0.0, 1.0);
            let turn = shape.turns[o as usize];
            let inner = turn != 0 && shape.near.side[i] == turn;
            let profile = if inner { (1.0 - u) * (1.0 - u) } else { 1.0 - u * u };
            target[i] = (level - depth * profile.max(WET)) as f32;
            water[i] = level as f32;
        } else if f64::from(to_water[i]) <= bank {
            let edge = surface[o as usize] + FREEBOARD * depth;
            let g = f64::from(ground.get(win.c0 + (i % win.width) as u32, win.r0 + (i / win.width) as u32));
            let t = f64::from(to_water[i]) / (bank + 1.0);
            target[i] = (edge + t * (g - edge)) as f32;
        }
    }
    // The thalweg descends along the course: each centre cell at most the one before it. A cell
    // the line visits twice (a line along a cell diagonal) can undo an earlier pass, so passes
    // repeat until none lowers anything.
    let origin = win.origin();
    let cells: Vec<usize> = shape
        .line
        .iter()
        .filter_map(|s| {
            let q = (s.p - origin).round();
            let inside = q.x >= 0.0 && q.y >= 0.0 && q.x < win.width as f64 && q.y < win.height as f64;
            inside.then(|| q.y as usize * win.width + q.x as usize)
        })
        .collect();
    for &i in &cells {
        let g = ground.heights()[win.grid_index(i, ground.cols())];
        target[i] = target[i].min(g);
    }
    for _ in 0..cells.len() {
        let mut lowered = false;
        for k in 1..cells.len() {
            let (a, b) = (target[cells[k - 1]], target[cells[k]]);
            if b > a {
                target[cells[k]] = a;
                lowered = true;
            }
        }
        if !lowered {
            break;
        }
    }
    Carve {
        window: win,
        target,
        water,
        lake,
    }
}

impl Carve {
    /// Lowers `map` (the ground this was carved from, or a map already carved by other rivers
    /// over the same ground) to the targets.
    pub fn apply(&self, map: &mut Heightmap) {
        let win = self.window;
        let cols = map.cols();
        let heights = map.heights_mut();
        for (i, &t) in self.target.iter().enumerate() {
            let h = &mut heights[win.grid_index(i, cols)];
            if *h > t {
                *h = t;
            }
        }
    }
}
