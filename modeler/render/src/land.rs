//! The land look's maps of a terrain (issue 20): the ground's colour per cell, by height in
//! metres and by slope, and the light per vertex, with cast shadows and sky light from issue 12's
//! horizons ([`penmodel_terrain::ridge::sun`]).
//!
//! - **Colour** ([`material`]): grass on gentle ground (lush to dry by a noise), alpine meadow
//!   from half the snow line, scree from three quarters of it, snow above it (not on faces steeper
//!   than about 50°, where snow does not lie); rock on faces steeper than [`Style::rock_slope`]
//!   (warm low down, grey high up); a beach up to [`Style::beach_height`] above the water's level
//!   within [`SHORE_METRES`] of water (the sea — heights below 0 — or rivers and lakes), found by a
//!   chamfer distance that carries the nearest water's level (flat ground at exactly 0 far from
//!   water is grass: 0 is the documents' datum, not a shore); below sea level the classic water
//!   ramp (the ground seen through the sea). Every change is a smoothstep, so there are no hard bands, and a deterministic value noise
//!   in world metres (two octaves, 24 m and 96 m, or three and twelve cells when cells are larger)
//!   moves the thresholds and the brightness a little, so large areas are not one flat green.
//!   Heights are true metres (the vertical scale exaggerates the drawing, not the climate): a 70 m
//!   cone gets no snow. Slopes are true slopes too.
//! - **Light per vertex**: `ambient·sky + (1 − ambient)·sun·max(0, n·L)`, `n` from central
//!   differences of the drawn (scaled) heights as in the classic look, `sun` the visibility of the
//!   sun over the cell's horizon in the sun's azimuth (1 lit, 0 in shadow, a 3° penumbra), `sky` the
//!   sky-view factor over [`Style::sky_directions`] azimuths. Both come from the horizon sweeps of
//!   issue 12 on a grid of at most [`Style::light_cells`] cells a side (the drawn heights averaged
//!   in blocks) and are interpolated bilinearly per vertex: at 512² the sweeps on the whole grid
//!   would take longer than a frame.
//! - **When**: the maps are kept between frames and remade when the heights, the vertical scale,
//!   the style or the water change. While the terrain changes frame after frame (a pull), they may
//!   lag it by up to [`Style::light_lag`] frames (2: remade every third frame of a pull, about 50 ms
//!   at 60 frames a second), and when it stops they are remade for its final shape: a pull's frame
//!   would otherwise cost half as much again as a classic one. The renderer compares the heights with the ones it made the
//!   maps from (a copy): the colours are remade only in the changed rectangle (and a cell around
//!   it, for the slopes; all of them when there is water, whose beach a change can move); the
//!   light everywhere, since a change anywhere casts shadows and hides
//!   sky across the grid.

use rayon::prelude::*;

use super::light;
use super::ramp::{self, WATER};
use super::scene::{Scene, Style};
use penmodel_terrain::ridge::sun::{self, Field};

/// Grass, lush.
pub const GRASS: [u8; 3] = [88, 134, 54];
/// Grass, dry.
pub const DRY_GRASS: [u8; 3] = [122, 146, 68];
/// Alpine meadow.
pub const MEADOW: [u8; 3] = [146, 140, 98];
/// Scree below the snow.
pub const SCREE: [u8; 3] = [150, 145, 138];
/// Rock low down.
pub const ROCK: [u8; 3] = [130, 116, 100];
/// Rock high up.
pub const GREY_ROCK: [u8; 3] = [138, 136, 132];
/// Snow.
pub const SNOW: [u8; 3] = [242, 245, 250];
/// Sand of the beach.
pub const SAND: [u8; 3] = [216, 200, 154];

/// Width of the sun's penumbra at a horizon, radians (the sun's disc is 0.5°; a coarse light grid
/// blurs more).
const PENUMBRA: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// What the maps were made for.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    cols: u32,
    rows: u32,
    cell: f64,
    vertical_scale: f32,
    rivers: bool,
    /// A light map was given ([`Scene::light_map`]): the light is remade every frame from it.
    given: bool,
    style: Style,
}

/// The land look's maps, kept between frames.
#[derive(Debug, Default)]
pub struct Land {
    key: Option<Key>,
    /// The heights the maps were made from.
    heights: Vec<f32>,
    /// Whether the scene has water: the terrain below sea level, or rivers and lakes.
    water: bool,
    /// Per cell, how near water is ([`Shore`]); empty without water.
    shore: Vec<Shore>,
    /// Ground colour per cell, sRGB 0–255, before light.
    albedo: Vec<[f32; 3]>,
    /// The broad and fine noise per cell: they depend on the grid alone.
    noise: Vec<[f32; 2]>,
    /// The grid the noise is for: columns, rows, cell size.
    noise_grid: (usize, usize, f64),
    cols: usize,
    rows: usize,
    /// Cell size, metres.
    pub(crate) cell: f32,
    /// Non-finite heights.
    bad: usize,
    /// Times the maps were remade (a test and the bench read it).
    remakes: u64,
    /// Changed frames since the maps were last remade.
    lagging: u32,
    /// The fingerprint of the last frame's heights.
    last_print: u64,
}

/// A rectangle of cells, columns `c0..c1`, rows `r0..r1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Rect {
    c0: usize,
    c1: usize,
    r0: usize,
    r1: usize,
}

impl Land {
    /// Forgets the maps (the renderer drew a classic frame into the light buffer).
    pub fn forget(&mut self) {
        self.key = None;
    }

    /// How many times the maps were remade.
    pub fn remakes(&self) -> u64 {
        self.remakes
    }

    /// Brings the maps up to date with `scene` and writes the light per vertex into `light` when
    /// it changed (it is left alone otherwise: the caller keeps it between frames). Returns how
    /// many heights are not finite.
    pub fn prepare(&mut self, scene: &Scene, light: &mut Vec<f32>) -> usize {
        let map = scene.terrain;
        let h = map.heights();
        let (cols, rows) = (map.cols() as usize, map.rows() as usize);
        let key = Key {
            cols: map.cols(),
            rows: map.rows(),
            cell: map.cell_size(),
            vertical_scale: scene.vertical_scale,
            rivers: scene.water.iter().any(|(_, m)| !m.indices.is_empty()),
            given: scene.light_map.is_some(),
            style: scene.style.clone(),
        };
        let full = Rect {
            c0: 0,
            c1: cols,
            r0: 0,
            r1: rows,
        };
        let same = self.key.as_ref() == Some(&key) && self.heights.len() == h.len() && light.len() == h.len();
        let rect = if same {
            changed(&self.heights, h, cols)
        } else {
            Some(full)
        };
        // A fingerprint of this frame's heights: whether the terrain is still moving.
        let print = fingerprint(h);
        let moving = print != self.last_print;
        self.last_print = print;
        let Some(mut rect) = rect else {
            if let Some(given) = scene.light_map {
                self.bad = light::vertex_light(map, scene.vertical_scale, &scene.style, Some(given), light);
            }
            return self.bad;
        };
        // While the terrain changes frame after frame (a pull), the maps may lag it by up to
        // `light_lag` frames; once it stops they are remade for its final shape.
        if same && moving && self.lagging < scene.style.light_lag && scene.light_map.is_none() {
            self.lagging += 1;
            return self.bad;
        }
        self.lagging = 0;
        self.remakes += 1;
        self.cols = cols;
        self.rows = rows;
        self.cell = map.cell_size() as f32;
        if self.heights.len() != h.len() {
            self.heights = h.to_vec();
        } else {
            let (a, b) = (rect.r0 * cols, rect.r1 * cols);
            self.heights[a..b].copy_from_slice(&h[a..b]);
        }
        let sea = h.par_iter().any(|&v| v < 0.0);
        let water = sea || key.rivers;
        if water || water != self.water {
            // The beach follows the water, which a change can move anywhere: all of it again.
            rect = full;
        }
        self.water = water;
        self.shore = if water { shore(scene) } else { Vec::new() };
        // The slopes read a cell's neighbours.
        let grown = Rect {
            c0: rect.c0.saturating_sub(1),
            c1: (rect.c1 + 1).min(cols),
            r0: rect.r0.saturating_sub(1),
            r1: (rect.r1 + 1).min(rows),
        };
        if self.noise_grid != (cols, rows, map.cell_size()) || self.noise.len() != cols * rows {
            self.noise = noise(cols, rows, map.cell_size());
            self.noise_grid = (cols, rows, map.cell_size());
        }
        self.albedo.resize(cols * rows, [0.0; 3]);
        colours(map, &scene.style, &self.shore, grown, &self.noise, &mut self.albedo);
        self.bad = match scene.light_map {
            Some(given) => light::vertex_light(map, scene.vertical_scale, &scene.style, Some(given), light),
            None => lights(map, scene.vertical_scale, &scene.style, light),
        };
        self.key = Some(key);
        self.bad
    }

    /// The ground's colour (sRGB 0–255, before light) of the cell holding world `(x, z)`
    /// metres: for pixels where a cell is smaller than a pixel, where interpolating between cells
    /// would show nothing more and costs three times as much.
    #[inline]
    pub fn nearest_at(&self, x: f32, z: f32) -> [f32; 3] {
        if self.cols == 0 || self.rows == 0 {
            return [0.0; 3];
        }
        let inv = 1.0 / self.cell;
        // Negative and NaN positions cast to 0.
        let c = ((x * inv) as usize).min(self.cols - 1);
        let r = ((z * inv) as usize).min(self.rows - 1);
        self.albedo[r * self.cols + c]
    }

    /// The ground's colour (sRGB 0–255, before light) at world `(x, z)` metres, bilinear between
    /// the cell centres.
    #[inline]
    pub fn albedo_at(&self, x: f32, z: f32) -> [f32; 3] {
        if self.cols == 0 || self.rows == 0 {
            return [0.0; 3];
        }
        let inv = 1.0 / self.cell;
        let u = (x * inv - 0.5).clamp(0.0, (self.cols - 1) as f32);
        let v = (z * inv - 0.5).clamp(0.0, (self.rows - 1) as f32);
        // NaN (a point from a degenerate view) clamps to NaN: read the first cell instead.
        let (u, v) = if u.is_finite() && v.is_finite() {
            (u, v)
        } else {
            (0.0, 0.0)
        };
        let (c, r) = (u as usize, v as usize);
        let (fu, fv) = (u - c as f32, v - r as f32);
        let c1 = (c + 1).min(self.cols - 1);
        let r1 = (r + 1).min(self.rows - 1);
        let a = &self.albedo;
        let (p00, p10, p01, p11) = (
            a[r * self.cols + c],
            a[r * self.cols + c1],
            a[r1 * self.cols + c],
            a[r1 * self.cols + c1],
        );
        let top = lerp(p00, p10, fu);
        lerp(top, lerp(p01, p11, fu), fv)
    }
}

/// A fingerprint of the heights' bits (a multiply-xor hash per row, rows combined in order).
fn fingerprint(h: &[f32]) -> u64 {
    h.par_chunks(4096)
        .map(|chunk| {
            chunk.iter().fold(0x9E37_79B9_7F4A_7C15u64, |acc, v| {
                (acc ^ u64::from(v.to_bits())).wrapping_mul(0x1000_0000_01B3)
            })
        })
        .collect::<Vec<u64>>()
        .into_iter()
        .fold(h.len() as u64, |acc, v| {
            (acc.rotate_left(5) ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        })
}

/// The rectangle of cells where `new` differs from `old` (bit for bit, so a NaN that stays is no
/// change), `None` when nothing changed.
fn changed(old: &[f32], new: &[f32], cols: usize) -> Option<Rect> {
    old.par_chunks(cols.max(1))
        .zip(new.par_chunks(cols.max(1)))
        .enumerate()
        .filter_map(|(r, (a, b))| {
            let first = a.iter().zip(b).position(|(x, y)| x.to_bits() != y.to_bits())?;
            let last = a.iter().zip(b).rposition(|(x, y)| x.to_bits() != y.to_bits())?;
            Some(Rect {
                c0: first,
                c1: last + 1,
                r0: r,
                r1: r + 1,
            })
        })
        .reduce_with(|a, b| Rect {
            c0: a.c0.min(b.c0),
            c1: a.c1.max(b.c1),
            r0: a.r0.min(b.r0),
            r1: a.r1.max(b.r1),
        })
}

/// `t` from 0 at `a` to 1 at `b`, smoothly (Hermite); a step at `a` when `a = b`.
#[inline]
fn smoothstep(a: f32, b: f32, t: f32) -> f32 {
    if b <= a {
        return if t >= a { 1.0 } else { 0.0 };
    }
    let x = ((t - a) / (b - a)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

use super::atmosphere::lerp as mix;
use super::atmosphere::lerp;

fn rgb(c: [u8; 3]) -> [f32; 3] {
    c.map(f32::from)
}

/// A hash of a lattice point to `[0, 1)`.
#[inline]
fn lattice(x: i64, y: i64, seed: u32) -> f32 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= u64::from(seed).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// Value noise at `(x, y)` in lattice units, `[0, 1)`: the lattice's hashes blended smoothly.
pub fn value_noise(x: f64, y: f64, seed: u32) -> f32 {
    let (xf, yf) = (x.floor(), y.floor());
    let (xi, yi) = (xf as i64, yf as i64);
    let s = |t: f64| (t * t * (3.0 - 2.0 * t)) as f32;
    let (fx, fy) = (s(x - xf), s(y - yf));
    let a = lattice(xi, yi, seed) + fx * (lattice(xi + 1, yi, seed) - lattice(xi, yi, seed));
    let b = lattice(xi, yi + 1, seed) + fx * (lattice(xi + 1, yi + 1, seed) - lattice(xi, yi + 1, seed));
    a + fy * (b - a)
}

/// How near a cell is to water, for the beach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shore {
    /// 1 at the water's edge, falling to 0 at [`SHORE_METRES`] (at least [`SHORE_CELLS`] cells).
    pub near: f32,
    /// The nearest water's level, metres (0 for the sea).
    pub level: f32,
}

impl Shore {
    /// No water near.
    pub const NONE: Shore = Shore { near: 0.0, level: 0.0 };
}

/// How far from water a beach reaches, metres ...
pub const SHORE_METRES: f32 = 12.0;
/// ... and cells.
pub const SHORE_CELLS: f32 = 3.0;

/// The ground's colour (sRGB 0–255, before light) at true height `h` metres, slope `slope`
/// degrees, with noises `broad` and `fine` in `[0, 1)`, and `shore` for the beach.
pub fn material(style: &Style, h: f32, slope: f32, broad: f32, fine: f32, shore: Shore) -> [f32; 3] {
    if h < 0.0 {
        let depth = style.ramp_depth.max(f32::MIN_POSITIVE);
        return rgb(ramp::interpolate(&WATER, -h / depth));
    }
    let snow_line = style.snow_line.max(f32::MIN_POSITIVE);
    let jitter = broad - 0.5;
    let mut c = mix(rgb(GRASS), rgb(DRY_GRASS), smoothstep(0.2, 0.8, broad));
    // Up the mountain: meadow, then scree, then snow; the limits wander by ±5 % of the snow line.
    let hj = h + jitter * 0.1 * snow_line;
    c = mix(c, rgb(MEADOW), smoothstep(0.45 * snow_line, 0.65 * snow_line, hj));
    c = mix(c, rgb(SCREE), smoothstep(0.78 * snow_line, 0.95 * snow_line, hj));
    let rock = mix(
        rgb(ROCK),
        rgb(GREY_ROCK),
        smoothstep(0.3 * snow_line, 0.9 * snow_line, h),
    );
    let [lo, hi] = style.rock_slope;
    let steep = smoothstep(lo + 6.0 * jitter, hi.max(lo) + 6.0 * jitter, slope);
    c = mix(c, rock, steep);
    let snow = smoothstep(0.97 * snow_line, 1.03 * snow_line, hj) * (1.0 - smoothstep(42.0, 58.0, slope));
    c = mix(c, rgb(SNOW), snow);
    if shore.near > 0.0 {
        let top = style.beach_height.max(0.0);
        let above = h - shore.level;
        // Just above the water's level (ground below a river's level beside it is its bed).
        let band = (1.0 - smoothstep(0.6 * top, 1.4 * top, above)) * smoothstep(-1.4 * top, -0.6 * top, above);
        let beach = shore.near * band * (1.0 - smoothstep(14.0, 24.0, slope));
        c = mix(c, rgb(SAND), beach);
    }
    // Brightness varies by ±7 % on the fine scale (less on snow).
    let k = 1.0 + (fine - 0.5) * 0.14 * (1.0 - 0.7 * snow);
    c.map(|v| (v * k).clamp(0.0, 255.0))
}

/// How near each cell is to water: the sea (heights below 0, level 0) and the cells under the
/// scene's water meshes (rivers and lakes, at their vertices' level), by a two-pass chamfer
/// distance (1 and √2 cells) that carries the nearest water's level along.
fn shore(scene: &Scene) -> Vec<Shore> {
    let map = scene.terrain;
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let s = map.cell_size() as f32;
    let h = map.heights();
    // (distance in cells, level)
    let mut d: Vec<(f32, f32)> = h
        .iter()
        .map(|&v| if v < 0.0 { (0.0, 0.0) } else { (f32::INFINITY, 0.0) })
        .collect();
    for (_, mesh) in scene.water {
        for p in &mesh.positions {
            let (c, r) = ((p[0] / s).floor(), (p[2] / s).floor());
            if c >= 0.0 && r >= 0.0 && (c as usize) < cols && (r as usize) < rows && p[1].is_finite() {
                d[r as usize * cols + c as usize] = (0.0, p[1]);
            }
        }
    }
    const DIAGONAL: f32 = std::f32::consts::SQRT_2;
    let relax = |d: &mut Vec<(f32, f32)>, i: usize, j: usize, step: f32| {
        let cand = d[j].0 + step;
        if cand < d[i].0 {
            d[i] = (cand, d[j].1);
        }
    };
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            if c > 0 {
                relax(&mut d, i, i - 1, 1.0);
            }
            if r > 0 {
                relax(&mut d, i, i - cols, 1.0);
                if c > 0 {
                    relax(&mut d, i, i - cols - 1, DIAGONAL);
                }
                if c + 1 < cols {
                    relax(&mut d, i, i - cols + 1, DIAGONAL);
                }
            }
        }
    }
    for r in (0..rows).rev() {
        for c in (0..cols).rev() {
            let i = r * cols + c;
            if c + 1 < cols {
                relax(&mut d, i, i + 1, 1.0);
            }
            if r + 1 < rows {
                relax(&mut d, i, i + cols, 1.0);
                if c + 1 < cols {
                    relax(&mut d, i, i + cols + 1, DIAGONAL);
                }
                if c > 0 {
                    relax(&mut d, i, i + cols - 1, DIAGONAL);
                }
            }
        }
    }
    let reach = SHORE_METRES.max(SHORE_CELLS * s);
    d.into_iter()
        .map(|(cells, level)| Shore {
            near: 1.0 - smoothstep(0.5 * reach, reach, cells * s),
            level,
        })
        .collect()
}

/// `atan(g)` in degrees for `g ≥ 0`, to within 0.06° (a rational approximation on [0, 1] and
/// `90° − atan(1/g)` above): libm's `atanf` took a twentieth of a land frame's CPU time.
#[inline]
fn atan_degrees(g: f32) -> f32 {
    let (t, flip) = if g > 1.0 { (1.0 / g, true) } else { (g, false) };
    // atan t ≈ t·(0.9998660 − 0.3302995 t² + 0.1801410 t⁴ − 0.0851330 t⁶ + 0.0208351 t⁸)
    let t2 = t * t;
    let a = t * (0.999_866 + t2 * (-0.330_299_5 + t2 * (0.180_141 + t2 * (-0.085_133 + t2 * 0.020_835_1))));
    let d = a.to_degrees();
    if flip { 90.0 - d } else { d }
}

/// The broad and fine noise at each cell's centre.
fn noise(cols: usize, rows: usize, s: f64) -> Vec<[f32; 2]> {
    // The noises' wavelengths in metres, at least a few cells.
    let fine_l = 24f64.max(3.0 * s);
    let broad_l = 96f64.max(12.0 * s);
    let mut out = vec![[0.0; 2]; cols * rows];
    out.par_chunks_mut(cols.max(1)).enumerate().for_each(|(r, line)| {
        for (c, o) in line.iter_mut().enumerate() {
            let (x, y) = ((c as f64 + 0.5) * s, (r as f64 + 0.5) * s);
            *o = [
                value_noise(x / broad_l, y / broad_l, 1),
                value_noise(x / fine_l, y / fine_l, 2),
            ];
        }
    });
    out
}

/// The colours of the cells in `rect`.
fn colours(
    map: &penmodel_terrain::Heightmap,
    style: &Style,
    shore: &[Shore],
    rect: Rect,
    noise: &[[f32; 2]],
    out: &mut [[f32; 3]],
) {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    if cols == 0 || rows == 0 || rect.c1 <= rect.c0 {
        return;
    }
    let h = map.heights();
    let s = map.cell_size();
    out[rect.r0 * cols..rect.r1 * cols]
        .par_chunks_mut(cols)
        .enumerate()
        .for_each(|(i, line)| {
            let r = rect.r0 + i;
            let (r0, r1) = (r.saturating_sub(1), (r + 1).min(rows - 1));
            for (c, o) in line.iter_mut().enumerate().take(rect.c1).skip(rect.c0) {
                let centre = h[r * cols + c];
                if !centre.is_finite() {
                    *o = [0.0; 3];
                    continue;
                }
                // The true slope: heights unscaled.
                let [dx, dz] = light::gradient(h, (cols, rows), (c, r), (r0, r1), (1.0, s as f32));
                let slope = atan_degrees((dx * dx + dz * dz).sqrt());
                let [broad, fine] = noise[r * cols + c];
                let near = shore.get(r * cols + c).copied().unwrap_or(Shore::NONE);
                *o = material(style, centre, slope, broad, fine, near);
            }
        });
}

/// The terrain's heights × `scale`, averaged in blocks of `f × f` cells (non-finite heights count
/// as 0: their triangles are holes anyway): `(heights, cols, rows)`.
fn coarse(map: &penmodel_terrain::Heightmap, scale: f32, f: usize) -> (Vec<f32>, usize, usize) {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let (cc, rr) = (cols.div_ceil(f), rows.div_ceil(f));
    let h = map.heights();
    let mut out = vec![0.0f32; cc * rr];
    out.par_chunks_mut(cc).enumerate().for_each(|(j, line)| {
        for (i, o) in line.iter_mut().enumerate() {
            let (mut sum, mut n) = (0.0f32, 0u32);
            for r in j * f..((j + 1) * f).min(rows) {
                for &v in &h[r * cols + i * f..r * cols + ((i + 1) * f).min(cols)] {
                    if v.is_finite() {
                        sum += v;
                    }
                    n += 1;
                }
            }
            *o = sum / n.max(1) as f32 * scale;
        }
    });
    (out, cc, rr)
}

/// The sun's azimuth (from +x towards +y) and elevation, radians, of the style's light.
fn sun_angles(style: &Style) -> (f64, f64) {
    let [x, y, up] = style.light.map(f64::from);
    (y.atan2(x), up.atan2(x.hypot(y)))
}

/// The light per vertex (see the module's notes); returns how many heights are not finite.
fn lights(map: &penmodel_terrain::Heightmap, vertical_scale: f32, style: &Style, out: &mut Vec<f32>) -> usize {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    out.resize(cols * rows, 0.0);
    if cols == 0 || rows == 0 {
        return 0;
    }
    let side = cols.max(rows);
    let f = if style.light_cells == 0 {
        1
    } else {
        side.div_ceil(style.light_cells as usize).max(1)
    };
    let (z, cc, rr) = coarse(map, vertical_scale, f);
    let field = Field {
        z: &z,
        cols: cc as u32,
        rows: rr as u32,
        cell: map.cell_size() * f as f64,
    };
    let (azimuth, elevation) = sun_angles(style);
    let mut sun_seen = vec![0.0f32; z.len()];
    if elevation > 0.0 {
        sun::horizons(field, azimuth, |i, t| {
            let above = elevation - t.atan();
            sun_seen[i] = (above / PENUMBRA + 0.5).clamp(0.0, 1.0) as f32;
        });
    }
    let sky = sun::sky_view(field, style.sky_directions.max(1));
    let h = map.heights();
    let s = map.cell_size() as f32;
    let light = light::world_light(style);
    let ambient = style.ambient.clamp(0.0, 1.0);
    // A vertex's place on the coarse grid: block centres at (i + ½)f − ½ cells.
    let half = (f as f32 - 1.0) * 0.5;
    let inv_f = 1.0 / f as f32;
    let bilinear = |m: &[f32], c: usize, r: usize| {
        let u = ((c as f32 - half) * inv_f).clamp(0.0, (cc - 1) as f32);
        let v = ((r as f32 - half) * inv_f).clamp(0.0, (rr - 1) as f32);
        let (i, j) = (u as usize, v as usize);
        let (fu, fv) = (u - i as f32, v - j as f32);
        let (i1, j1) = ((i + 1).min(cc - 1), (j + 1).min(rr - 1));
        let top = m[j * cc + i] + fu * (m[j * cc + i1] - m[j * cc + i]);
        let bottom = m[j1 * cc + i] + fu * (m[j1 * cc + i1] - m[j1 * cc + i]);
        top + fv * (bottom - top)
    };
    out.par_chunks_mut(cols)
        .enumerate()
        .map(|(r, line)| {
            let mut bad = 0;
            let (r0, r1) = (r.saturating_sub(1), (r + 1).min(rows - 1));
            for (c, o) in line.iter_mut().enumerate() {
                let centre = h[r * cols + c];
                if !centre.is_finite() {
                    *o = f32::NAN;
                    bad += 1;
                    continue;
                }
                let [dx, dz] = light::gradient(h, (cols, rows), (c, r), (r0, r1), (vertical_scale, s));
                let inv = 1.0 / (dx * dx + 1.0 + dz * dz).sqrt();
                let lambert = ((-dx * light[0] + light[1] - dz * light[2]) * inv).max(0.0);
                let seen = bilinear(&sun_seen, c, r);
                let open = bilinear(&sky, c, r);
                *o = ambient * open + (1.0 - ambient) * seen * lambert;
            }
            bad
        })
        .sum()
}
