//! Fluvial erosion (issue 39): a landscape-evolution model that carves the sketched land into
//! valleys and spurs, after the sketch layers (regions, detail, thermal erosion, ridgelines)
//! and before the rivers are carved and the rocks and trees seated (`docs/erosion.md`).
//!
//! The sketch is the land's *target*: each step the land is raised back toward it and worn by
//! running water and soil creep,
//!
//! `∂h/∂t = (h_s − h)/T − K·A^m·S^n + D·∇²h`,
//!
//! where `h_s` is the sketched height, `T` the response time (how fast the sketch re-asserts
//! itself: peaks stay where the user pulled them), `A` the drainage area (m²), `S` the slope to
//! the cell's receiver. A step:
//!
//! 1. routes water ([`route`]): depressions filled by Priority-Flood+ε, D8 receivers, the
//!    stack, drainage areas;
//! 2. solves the raise and the stream-power law together, implicitly, cell after cell along the
//!    stack from the outlets up (Braun & Willett 2013): for `n = 1` in closed form, otherwise by
//!    Newton's method on a convex function, so any `K·dt` is stable and heights stay between
//!    their receiver's and the raised height (no overshoot, no NaN);
//! 3. diffuses ([`diffuse`]): implicit along rows, then columns.
//!
//! The grid's edge is the base level: its cells keep the sketch's heights and take the water
//! out. The first surface is the sketch with a little seeded noise (`noise` metres, uniform, on
//! the cells above the sketch's lowest level), which breaks the symmetry of sketched cones, so their flanks branch instead of running in
//! parallel.
//!
//! **Deterministic**: the same sketch and settings give the same bits, on any number of
//! threads: what runs in parallel (receivers, the diffusion's rows and strips of columns, the
//! stream-power step and the areas on runs of whole edge basins) works on each cell alone or
//! in the stack's own order. **Not incremental**: drainage area makes every cell depend on its whole catchment,
//! so any change of the sketch re-erodes the whole grid (the engine says so:
//! `TerrainEngine::update` returns the whole grid).

pub mod diffuse;
pub mod measure;
pub mod route;

use rayon::prelude::*;

use crate::document::Fluvial;
use crate::heightmap::Heightmap;

/// Bytes of memory per cell while eroding: ten `f64` arrays (heights, sketch, fill, distances,
/// areas, the diffusion's three scratch rows, the stack's heights and areas), one pair of `f64`
/// (the stack's coefficients), seven `u32` (receivers, stack, places in it, receivers' places,
/// donors and two donor offsets) and the priority queue at its largest.
pub const BYTES_PER_CELL: usize = 10 * 8 + 16 + 7 * 4 + 16;

/// The state of an erosion run on one grid.
pub struct Model {
    settings: Fluvial,
    cell: f64,
    /// The land being eroded.
    h: Vec<f64>,
    /// The sketch it is raised toward.
    target: Vec<f64>,
    routing: route::Routing,
    /// By place in the stack: heights while the stream-power step solves them.
    stack_h: Vec<f64>,
    /// By place in the stack: the raised height and the water's coefficient.
    coefficients: Vec<(f64, f64)>,
    diffusion: diffuse::Diffusion,
    /// `(a·dx²)^m` for drainage areas of `a` cells below the table's length.
    area_pow: Vec<f64>,
    /// Cells held at the sketch's height: the control figures' ([`held_cells`]).
    held: Vec<bool>,
    done: u32,
}

/// The cells the document's raised point and polyline figures stand on (a height above their
/// region's base), nested ones too: the erosion holds them at the sketch's height, so a pulled
/// peak or ridge stays where the user put it and the land around it is carved. Closed figures
/// are not held (a plateau's or a crater's rim wears and may be breached, as real ones do), nor
/// are figures at or below their base (a valley line, a crater's floor), which water may fill.
pub fn held_cells(doc: &crate::document::Document) -> Vec<bool> {
    fn walk(grid: &crate::document::Grid, figures: &[crate::document::Figure], base: f64, out: &mut [bool]) {
        for f in figures {
            let cells = match f.kind {
                crate::document::FigureKind::Closed => Vec::new(),
                _ if f.height <= base => Vec::new(),
                _ => crate::cells::polyline_cells(grid, &f.points),
            };
            for (c, r) in cells {
                out[r as usize * grid.cols as usize + c as usize] = true;
            }
            walk(grid, &f.figures, f.height, out);
        }
    }
    let mut held = vec![false; doc.grid.cells()];
    for region in &doc.regions {
        walk(&doc.grid, &region.figures, 0.0, &mut held);
    }
    held
}

/// Drainage areas (in cells) whose `A^m` is looked up rather than computed.
const AREA_TABLE: usize = 4096;

/// A 64-bit mix (splitmix64's finaliser): the noise of cell `i` for `seed`.
fn mix(seed: u64, i: u64) -> u64 {
    let mut z = seed ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Model {
    /// A run that starts from `sketch` (plus the settings' noise inside the edge).
    pub fn new(settings: Fluvial, sketch: &Heightmap) -> Model {
        let (cols, rows) = (sketch.cols() as usize, sketch.rows() as usize);
        let cell = sketch.cell_size();
        let target: Vec<f64> = sketch
            .heights()
            .iter()
            .map(|&v| if v.is_finite() { f64::from(v) } else { 0.0 })
            .collect();
        let mut h = target.clone();
        // Noise on the raised land only: a plain at the lowest level stays flat, so it floods
        // by the plain queue, not the heap.
        let lowest = target.iter().copied().fold(f64::INFINITY, f64::min);
        for (i, v) in h.iter_mut().enumerate() {
            let (c, r) = (i % cols, i / cols);
            if c > 0 && r > 0 && c + 1 < cols && r + 1 < rows && target[i] > lowest {
                let u = (mix(settings.seed, i as u64) >> 11) as f64 / (1u64 << 53) as f64;
                *v += settings.noise * u;
            }
        }
        let area_pow = (0..AREA_TABLE)
            .map(|a| (a as f64 * cell * cell).powf(settings.m))
            .collect();
        // A sketch with nothing raised (a new document) is its own steady state: no water runs,
        // nothing to carve; the run is done before it starts.
        let flat = target.iter().all(|&v| v <= lowest);
        Model {
            settings,
            cell,
            h,
            target,
            routing: route::Routing::new(cols, rows),
            stack_h: vec![0.0; cols * rows],
            coefficients: vec![(0.0, 0.0); cols * rows],
            diffusion: diffuse::Diffusion::new(cols, rows),
            area_pow,
            held: Vec::new(),
            done: if flat { settings.steps } else { 0 },
        }
    }

    /// Holds the cells `held` marks (row-major, one per cell) at the sketch's height.
    pub fn holding(mut self, held: Vec<bool>) -> Model {
        for (i, &on) in held.iter().enumerate() {
            if on && let Some(v) = self.h.get_mut(i) {
                *v = self.target[i];
            }
        }
        self.held = held;
        self
    }

    /// Steps run so far.
    pub fn done(&self) -> u32 {
        self.done
    }

    /// Whether every step of the settings has run.
    pub fn finished(&self) -> bool {
        self.done >= self.settings.steps
    }

    /// Runs up to `n` more steps (never beyond the settings' `steps`); returns how many ran.
    pub fn advance(&mut self, n: u32) -> u32 {
        let n = n.min(self.settings.steps.saturating_sub(self.done));
        for _ in 0..n {
            self.step();
        }
        n
    }

    /// The land now, rounded to `f32`, written into `out` (a map of the same grid).
    pub fn write(&self, out: &mut Heightmap) {
        for (o, &v) in out.heights_mut().iter_mut().zip(&self.h) {
            *o = v as f32;
        }
    }

    /// The drainage of the land as of the last step (or of the first surface before any).
    pub fn routing(&self) -> &route::Routing {
        &self.routing
    }

    fn step(&mut self) {
        let s = self.settings;
        let dt = s.dt;
        let a = if s.response > 0.0 { dt / s.response } else { 0.0 };
        self.routing.route(&self.h);
        let w = &self.routing;
        let kdt = s.k * dt;
        let cell = self.cell;
        let (h, target, held, area_pow) = (&self.h, &self.target, &self.held, &self.area_pow);
        // By place in the stack, in parallel: each cell's height, the height it is raised to and
        // the water's coefficient `f` in `(1 + a)·x + f·x^n = b` (negative: the cell is left as
        // it is, an outlet or held).
        self.stack_h
            .par_iter_mut()
            .zip(self.coefficients.par_iter_mut())
            .zip(w.stack.par_iter().zip(w.receiver_pos.par_iter()))
            .enumerate()
            .for_each(|(p, ((hs, co), (&i, &q)))| {
                let i = i as usize;
                *hs = h[i];
                if q as usize == p || held.get(i).copied().unwrap_or(false) {
                    *co = (0.0, -1.0);
                    return;
                }
                let area = w.stack_area[p];
                let am = match area_pow.get(area as usize) {
                    Some(&v) => v,
                    None => (area * cell * cell).powf(s.m),
                };
                let d = w.dist[i] * cell;
                let f = kdt * am / if s.n == 1.0 { d } else { d.powf(s.n) };
                *co = (h[i] + a * target[i], f);
            });
        // Then up the stack from the outlets, each run of basins on its own thread (a cell's
        // receiver is in its run), then the flooded cells, which may drain into any run.
        let (co, rpos) = (&self.coefficients, &w.receiver_pos);
        let flooded = w.flooded_from();
        route::split_runs(&mut self.stack_h[..flooded], w.runs())
            .into_par_iter()
            .for_each(|(start, run)| {
                for k in 0..run.len() {
                    let q = rpos[start + k] as usize;
                    if let Some(v) = solve(co[start + k], run[q - start], a, s.n) {
                        run[k] = v;
                    }
                }
            });
        for p in flooded..self.stack_h.len() {
            if let Some(v) = solve(co[p], self.stack_h[rpos[p] as usize], a, s.n) {
                self.stack_h[p] = v;
            }
        }
        let stack_h = &self.stack_h;
        self.h
            .par_iter_mut()
            .zip(w.pos.par_iter())
            .for_each(|(v, &p)| *v = stack_h[p as usize]);
        let r = s.diffusivity(self.cell) * dt / (self.cell * self.cell);
        self.diffusion.step(&mut self.h, r);
        for (i, &on) in self.held.iter().enumerate() {
            if on {
                self.h[i] = self.target[i];
            }
        }
        self.done += 1;
    }
}

/// A cell's new height from its coefficients `(raised, f)` and its receiver's new height `hr`
/// (none for a cell left as it is): the implicit step in `x = h − h_r`,
/// `(1 + a)·x + f·x^n = b`, with `b` the height above the receiver the cell would have without
/// the water's work.
fn solve((raised, f): (f64, f64), hr: f64, a: f64, n: f64) -> Option<f64> {
    if f < 0.0 {
        return None;
    }
    let b = raised - (1.0 + a) * hr;
    if b <= 0.0 {
        // At or below its receiver (a filled depression): only raised.
        return Some(raised / (1.0 + a));
    }
    let x = if n == 1.0 {
        b / (1.0 + a + f)
    } else {
        newton(b, 1.0 + a, f, n)
    };
    Some(hr + x)
}

/// The root `x` in `[0, b/c]` of `c·x + f·x^n = b` (b > 0, c ≥ 1, f ≥ 0, n > 0): Newton's method
/// kept inside a shrinking bracket (a step that would leave it bisects instead), so it
/// converges for every `n`, convex or not.
fn newton(b: f64, c: f64, f: f64, n: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, b / c);
    if f == 0.0 {
        return hi;
    }
    if !f.is_finite() {
        return 0.0;
    }
    let mut x = hi;
    for _ in 0..64 {
        let xn = x.powf(n);
        let g = c * x + f * xn - b;
        if g > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let dg = c + f * n * if x > 0.0 { xn / x } else { 0.0 };
        let mut next = x - g / dg;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 1e-12 * (b / c) {
            return next;
        }
        x = next;
    }
    x
}

/// The land after the whole run: `sketch` eroded by `settings`, the cells `held` marks (if any)
/// kept at the sketch's height.
pub fn erode(settings: Fluvial, sketch: &Heightmap, held: Option<Vec<bool>>) -> Heightmap {
    let mut model = Model::new(settings, sketch);
    if let Some(held) = held {
        model = model.holding(held);
    }
    model.advance(settings.steps);
    let mut out = sketch.clone();
    model.write(&mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newton_finds_the_root() {
        for &(b, c, f, n) in &[(10.0, 1.1, 0.5, 2.0), (3.0, 1.0, 40.0, 0.5), (1e3, 1.0, 1e9, 1.5)] {
            let x = newton(b, c, f, n);
            let g = c * x + f * x.powf(n) - b;
            assert!(g.abs() < 1e-6 * b, "b {b} c {c} f {f} n {n}: x {x}, residual {g}");
        }
    }
}
