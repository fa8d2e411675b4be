//! Fractal detail (issue 20): seeded gradient-noise fBm added to the regions' terrain, its
//! amplitude following the ground.
//!
//! A cell's detail is `amount · gate · relief · fbm`:
//!
//! - `fbm` ∈ [−1, 1]: `octaves` octaves of 2D gradient noise at the cell's centre in metres, the
//!   first of wavelength `scale`, each next one half the wavelength and half the amplitude,
//!   divided by the sum of the amplitudes. A pure function of the position and the seed (integer
//!   hashing, a fixed table of gradients, no trigonometry), so the same on every machine.
//! - `relief = |h| + (scale / 4)·|∇h|`, `h` the terrain before detail (eq. 1–4), `∇h` by central
//!   differences: more on high ground and more on steep ground (a slope of 1 counts as a quarter
//!   of the longest wavelength in height).
//! - `gate = 4·w·(1 − w)` with `w = df/(df + dp)` (eq. 1) for the nearest figure: 0 on the
//!   figures' own cells (a pull lands where the pen is) and at the regions' edges (no step to
//!   the ground outside or to an enclosing plateau), 1 halfway between.
//!
//! The noise is kept per cell (computed once); the gate is painted by the regions when their
//! shapes change; the detail of a cell reads the terrain of its 3 × 3 neighbourhood, so a change
//! of the terrain in a rectangle changes the detail in that rectangle grown by one cell, and only
//! there it is recomputed ([`Layer::apply`]). The result is a pure function of the terrain, the
//! gates and the noise, so an incremental update equals a full rebuild to the bit.

use crate::document::{Detail, Grid};
use crate::heightmap::Heightmap;
use crate::rect::Rect;

/// Eq. 1's weight of the nearest figure, as the gate's `w`, turned into the gate.
pub fn gate(df: f32, dp_min: f32) -> f32 {
    if !dp_min.is_finite() || dp_min == 0.0 {
        return 0.0;
    }
    let w = f64::from(df) / (f64::from(df) + f64::from(dp_min));
    (4.0 * w * (1.0 - w)) as f32
}

/// A 64-bit mix (SplitMix64's finaliser): lattice corners to gradients.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// cos 45°.
const H: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Sixteen unit gradients, evenly spaced (cos and sin of k·22.5°, written out so that no libm
/// enters the numbers).
const GRADIENTS: [(f64, f64); 16] = [
    (1.0, 0.0),
    (0.923_879_532_511_286_7, 0.382_683_432_365_089_8),
    (H, H),
    (0.382_683_432_365_089_8, 0.923_879_532_511_286_7),
    (0.0, 1.0),
    (-0.382_683_432_365_089_8, 0.923_879_532_511_286_7),
    (-H, H),
    (-0.923_879_532_511_286_7, 0.382_683_432_365_089_8),
    (-1.0, 0.0),
    (-0.923_879_532_511_286_7, -0.382_683_432_365_089_8),
    (-H, -H),
    (-0.382_683_432_365_089_8, -0.923_879_532_511_286_7),
    (0.0, -1.0),
    (0.382_683_432_365_089_8, -0.923_879_532_511_286_7),
    (H, -H),
    (0.923_879_532_511_286_7, -0.382_683_432_365_089_8),
];

/// The gradient of lattice corner `(ix, iy)` for `seed`.
fn corner_gradient(ix: i64, iy: i64, seed: u64) -> (f64, f64) {
    let h = mix(seed ^ mix((ix as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ iy as u64));
    GRADIENTS[(h & 15) as usize]
}

/// Quintic fade: the noise's slope is continuous across lattice lines.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// The noise inside one lattice square from its corners' gradients `[g00, g10, g01, g11]` at
/// offsets `(fx, fy)` from its lower corner.
fn blend(g: &[(f64, f64); 4], fx: f64, fy: f64) -> f64 {
    let dot = |(gx, gy): (f64, f64), dx: f64, dy: f64| gx * (fx - dx) + gy * (fy - dy);
    let (c00, c10, c01, c11) = (
        dot(g[0], 0.0, 0.0),
        dot(g[1], 1.0, 0.0),
        dot(g[2], 0.0, 1.0),
        dot(g[3], 1.0, 1.0),
    );
    let (u, v) = (fade(fx), fade(fy));
    let a = c00 + u * (c10 - c00);
    let b = c01 + u * (c11 - c01);
    a + v * (b - a)
}

/// The corner gradients of lattice square `(ix, iy)`.
fn square(ix: i64, iy: i64, seed: u64) -> [(f64, f64); 4] {
    [
        corner_gradient(ix, iy, seed),
        corner_gradient(ix + 1, iy, seed),
        corner_gradient(ix, iy + 1, seed),
        corner_gradient(ix + 1, iy + 1, seed),
    ]
}

/// 2D gradient noise at `(x, y)` in lattice units for `seed`, about [−0.7, 0.7], 0 on the lattice.
pub fn gradient_noise(x: f64, y: f64, seed: u64) -> f64 {
    let (x0, y0) = (x.floor(), y.floor());
    blend(&square(x0 as i64, y0 as i64, seed), x - x0, y - y0)
}

/// fBm of `d`'s octaves at `(x, y)` metres, within [−1, 1].
pub fn fbm(d: &Detail, x: f64, y: f64) -> f64 {
    let (mut sum, mut norm, mut amp, mut freq) = (0.0, 0.0, 1.0, 1.0 / d.scale);
    for o in 0..u64::from(d.octaves) {
        sum += amp * gradient_noise(x * freq, y * freq, mix(d.seed.wrapping_add(o)));
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    finish(sum, norm)
}

/// Gradient noise stays within ±√½; scaled so the sum stays within ±1.
fn finish(sum: f64, norm: f64) -> f64 {
    (sum / (norm * std::f64::consts::FRAC_1_SQRT_2)).clamp(-1.0, 1.0)
}

/// [`fbm`] at the cell centres `((k + ½)·cell, y)`, `k` = 0, 1, … into `out`, the same numbers
/// to the bit: along a row a lattice square's corner gradients are hashed once, not at every
/// point (an octave's lattice is several cells wide; a 512² map took 41–43 ms point by point and
/// 32–35 ms so, at load 6–9).
pub fn fbm_row(d: &Detail, cell: f64, y: f64, out: &mut [f64]) {
    let (mut amp, mut freq) = (1.0, 1.0 / d.scale);
    let mut sum = vec![0.0f64; out.len()];
    let mut norm = 0.0;
    for o in 0..u64::from(d.octaves) {
        let seed = mix(d.seed.wrapping_add(o));
        let ys = y * freq;
        let y0 = ys.floor();
        let (iy, fy) = (y0 as i64, ys - y0);
        let mut held: Option<(i64, [(f64, f64); 4])> = None;
        for (k, s) in sum.iter_mut().enumerate() {
            let xs = (k as f64 + 0.5) * cell * freq;
            let xf = xs.floor();
            let ix = xf as i64;
            let g = match held {
                Some((at, g)) if at == ix => g,
                _ => {
                    let g = square(ix, iy, seed);
                    held = Some((ix, g));
                    g
                }
            };
            *s += amp * blend(&g, xs - xf, fy);
        }
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    for (o, s) in out.iter_mut().zip(sum) {
        *o = finish(s, norm);
    }
}

/// The detail of a document's terrain: its settings, the noise per cell, the gates the regions
/// paint, and the terrain before detail.
pub struct Layer {
    settings: Detail,
    noise: Vec<f32>,
    /// Per cell, [`gate`] of the region that decides the cell (0 outside every region).
    pub(crate) gate: Vec<f32>,
    /// The regions' terrain before detail.
    pub(crate) smooth: Heightmap,
}

impl Layer {
    /// The layer for `settings` on `grid`, with no terrain yet (all gates 0).
    pub fn new(grid: &Grid, settings: Detail) -> Layer {
        let cols = grid.cols as usize;
        let s = grid.cell_size;
        let mut noise = vec![0.0f32; grid.cells()];
        // Rows on both cores: the noise is the layer's one cost that does not follow a change.
        use rayon::prelude::*;
        noise.par_chunks_mut(cols.max(1)).enumerate().for_each(|(r, row)| {
            let mut line = vec![0.0; row.len()];
            fbm_row(&settings, s, (r as f64 + 0.5) * s, &mut line);
            for (n, v) in row.iter_mut().zip(line) {
                *n = v as f32;
            }
        });
        Layer {
            settings,
            noise,
            gate: vec![0.0; grid.cells()],
            smooth: Heightmap::new(grid),
        }
    }

    /// The settings this layer was made for.
    pub fn settings(&self) -> &Detail {
        &self.settings
    }

    /// Writes terrain with detail into `out` over `rect` grown by one cell (clamped to the grid),
    /// from the terrain before detail; returns the rectangle written.
    pub fn apply(&self, rect: Rect, out: &mut Heightmap) -> Rect {
        let (cols, rows) = (self.smooth.cols(), self.smooth.rows());
        if rect.width == 0 || rect.height == 0 || cols == 0 || rows == 0 {
            return Rect::EMPTY;
        }
        let c0 = rect.c0.saturating_sub(1);
        let r0 = rect.r0.saturating_sub(1);
        let c1 = (rect.c0 + rect.width + 1).min(cols);
        let r1 = (rect.r0 + rect.height + 1).min(rows);
        let h = self.smooth.heights();
        let cell = self.smooth.cell_size();
        let reach = self.settings.scale / 4.0;
        let amount = self.settings.amount;
        let w = cols as usize;
        let dst = out.heights_mut();
        for r in r0..r1 {
            let (up, down) = (r.saturating_sub(1) as usize, (r + 1).min(rows - 1) as usize);
            let dy = (down - up) as f64 * cell;
            for c in c0..c1 {
                let i = r as usize * w + c as usize;
                let g = self.gate[i];
                if g == 0.0 {
                    dst[i] = h[i];
                    continue;
                }
                let (left, right) = (c.saturating_sub(1) as usize, (c + 1).min(cols - 1) as usize);
                let dx = (right - left) as f64 * cell;
                let row = r as usize * w;
                // One row or column: no slope across it.
                let gx = if dx > 0.0 {
                    (f64::from(h[row + right]) - f64::from(h[row + left])) / dx
                } else {
                    0.0
                };
                let gy = if dy > 0.0 {
                    (f64::from(h[down * w + c as usize]) - f64::from(h[up * w + c as usize])) / dy
                } else {
                    0.0
                };
                let relief = f64::from(h[i]).abs() + reach * gx.hypot(gy);
                dst[i] = (f64::from(h[i]) + amount * f64::from(g) * relief * f64::from(self.noise[i])) as f32;
            }
        }
        Rect {
            c0,
            r0,
            width: c1 - c0,
            height: r1 - r0,
        }
    }
}
