//! The ground's colour per cell: the palette, the material by height, slope, noise and shore, the
//! value noise, and the chamfer distance to water for the beach.

use rayon::prelude::*;

use super::Rect;
use crate::scene::light;
use crate::scene::{Scene, Style};
use crate::shade::atmosphere::lerp as mix;
use crate::shade::ramp::{self, WATER};

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

/// `t` from 0 at `a` to 1 at `b`, smoothly (Hermite); a step at `a` when `a = b`.
#[inline]
pub(super) fn smoothstep(a: f32, b: f32, t: f32) -> f32 {
    if b <= a {
        return if t >= a { 1.0 } else { 0.0 };
    }
    let x = ((t - a) / (b - a)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

pub(super) fn rgb(c: [u8; 3]) -> [f32; 3] {
    c.map(f32::from)
}

/// A hash of a lattice point to `[0, 1)`.
#[inline]
pub(super) fn lattice(x: i64, y: i64, seed: u32) -> f32 {
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
/// degrees, with noises `broad` and `fine` in `[0, 1)`, and `shore` for the beach: its
/// [`material_parts`] with all of the fine noise.
pub fn material(style: &Style, h: f32, slope: f32, broad: f32, fine: f32, shore: Shore) -> [f32; 3] {
    let (c, k) = material_parts(style, h, slope, broad, fine, shore);
    c.map(|v| v * (1.0 + k))
}

/// [`material`] in two parts: the colour without the fine noise's brightness (its mean), and that
/// brightness as a factor − 1, at most what keeps every channel ≤ 255: a pixel shows
/// `colour × (1 + fade·k)`, the fade by its footprint ([`FINE_FADE`](super::FINE_FADE)).
pub fn material_parts(style: &Style, h: f32, slope: f32, broad: f32, fine: f32, shore: Shore) -> ([f32; 3], f32) {
    if h < 0.0 {
        let depth = style.ramp_depth.max(f32::MIN_POSITIVE);
        return (rgb(ramp::interpolate(&WATER, -h / depth)), 0.0);
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
    let k = (fine - 0.5) * 0.14 * (1.0 - 0.7 * snow);
    let top = c[0].max(c[1]).max(c[2]).max(f32::MIN_POSITIVE);
    (c, k.min(255.0 / top - 1.0))
}

/// How near each cell is to water: the sea (heights below 0, level 0) and the cells under the
/// scene's water meshes (rivers and lakes, at their vertices' level), by a two-pass chamfer
/// distance (1 and √2 cells) that carries the nearest water's level along.
pub(super) fn shore(scene: &Scene) -> Vec<Shore> {
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
pub(super) fn atan_degrees(g: f32) -> f32 {
    let (t, flip) = if g > 1.0 { (1.0 / g, true) } else { (g, false) };
    // atan t ≈ t·(0.9998660 − 0.3302995 t² + 0.1801410 t⁴ − 0.0851330 t⁶ + 0.0208351 t⁸)
    let t2 = t * t;
    let a = t * (0.999_866 + t2 * (-0.330_299_5 + t2 * (0.180_141 + t2 * (-0.085_133 + t2 * 0.020_835_1))));
    let d = a.to_degrees();
    if flip { 90.0 - d } else { d }
}

/// The fine noise's wavelength on cells of `s` metres: 24 m, at least 3 cells.
pub(super) fn fine_wavelength(s: f64) -> f64 {
    24f64.max(3.0 * s)
}

/// The broad and fine noise at each cell's centre.
pub(super) fn noise(cols: usize, rows: usize, s: f64) -> Vec<[f32; 2]> {
    // The noises' wavelengths in metres, at least a few cells.
    let fine_l = fine_wavelength(s);
    let broad_l = 96f64.max(12.0 * s);
    let mut out = vec![[0.0; 2]; cols * rows];
    out.par_chunks_mut(cols.max(1)).enumerate().for_each(|(r, line)| {
        for (c, o) in line.iter_mut().enumerate() {
            let (x, y) = ((c as f64 + 0.5) * s, (r as f64 + 0.5) * s);
            // The broad noise: two octaves on lattices turned from the grid's axes and from
            // each other. One octave on the grid's own lattice showed its squares as blocks of
            // grass once the fine noise faded out at a distance.
            let turned = |(cos, sin): (f64, f64), l: f64| ((x * cos - y * sin) / l, (x * sin + y * cos) / l);
            let (u1, v1) = turned((0.866_025_4, 0.5), broad_l);
            let (u2, v2) = turned((0.939_692_6, -0.342_020_1), 0.45 * broad_l);
            let broad = 0.75 * (value_noise(u1, v1, 1) - 0.5) + 0.35 * (value_noise(u2, v2, 3) - 0.5);
            *o = [
                (0.5 + 1.2 * broad).clamp(0.0, 0.999),
                value_noise(x / fine_l, y / fine_l, 2),
            ];
        }
    });
    out
}

/// The land look's ground colour of every cell (sRGB 0–255, before light, row-major) with its
/// fine noise's brightness, as the display draws it close up, but without the beach (which needs
/// the scene's water): for exports' vertex colours.
pub fn ground_colours(map: &penmodel_terrain::Heightmap, style: &Style) -> Vec<[f32; 3]> {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    let noise = noise(cols, rows, map.cell_size());
    let mut out = vec![[0.0; 4]; cols * rows];
    let all = Rect {
        c0: 0,
        c1: cols,
        r0: 0,
        r1: rows,
    };
    colours(map, style, &[], all, &noise, &mut out);
    out.iter()
        .map(|&[r, g, b, k]| [r, g, b].map(|v| (v * (1.0 + k)).clamp(0.0, 255.0)))
        .collect()
}

/// The colours of the cells in `rect`.
pub(super) fn colours(
    map: &penmodel_terrain::Heightmap,
    style: &Style,
    shore: &[Shore],
    rect: Rect,
    noise: &[[f32; 2]],
    out: &mut [[f32; 4]],
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
                    *o = [0.0; 4];
                    continue;
                }
                // The true slope: heights unscaled.
                let [dx, dz] = light::gradient(h, (cols, rows), (c, r), (r0, r1), (1.0, s as f32));
                let slope = atan_degrees((dx * dx + dz * dz).sqrt());
                let [broad, fine] = noise[r * cols + c];
                let near = shore.get(r * cols + c).copied().unwrap_or(Shore::NONE);
                let ([r, g, b], k) = material_parts(style, centre, slope, broad, fine, near);
                *o = [r, g, b, k];
            }
        });
}
