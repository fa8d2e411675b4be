//! Shading: per-vertex light from normals, and the elevation colour ramp per pixel.
//!
//! - **Light per vertex** (Gouraud): the normal from central differences of the heights (with
//!   the vertical scale), `light = ambient + (1 − ambient)·max(0, n·L)` with `L` fixed to the
//!   terrain, so tilting the ground or moving the eye does not change it. It is computed once per
//!   frame for both eyes.
//! - **Colour per pixel**: the rasteriser leaves the interpolated height and light in each sample;
//!   the colour is `ramp(height) × light`. Per pixel rather than per vertex, so the ramp's bands
//!   stay sharp on triangles that are large on screen (a close camera), at one table look-up per
//!   pixel: the ramp is a [`RAMP_ENTRIES`]-entry table over `[−ramp_depth, ramp_top]`.
//! - The ramp: water below sea level (height 0) from shallow to deep blue, so a depression is
//!   never mistaken for land; then sand, grass, forest, rock and snow up to `ramp_top`.
//! - Empty samples show the sky, a vertical gradient.
//! - The land look ([`crate::scene::Look::Land`]) colours a terrain sample by the ground colour at
//!   its world point ([`crate::land`]) instead of the ramp, hazes every surface by its distance
//!   and shows the sky, the table and the land beyond where nothing was drawn
//!   ([`crate::atmosphere`]).

use rayon::prelude::*;

use super::atmosphere::Atmosphere;
use super::frame::Rgba;
use super::land::Land;
use super::rasterise::{Sample, Surface};
use super::scene::Style;
use penmodel_terrain::Heightmap;

/// Entries of the colour table.
pub const RAMP_ENTRIES: usize = 1024;

/// Land colours at fractions of `ramp_top`.
pub const LAND: [(f32, [u8; 3]); 7] = [
    (0.0, [214, 200, 146]),  // sand at the shore
    (0.04, [120, 168, 82]),  // grass
    (0.35, [66, 120, 58]),   // forest
    (0.55, [128, 116, 96]),  // rock
    (0.75, [150, 146, 142]), // grey rock
    (0.88, [236, 238, 242]), // snow
    (1.0, [255, 255, 255]),
];

/// Water colours at fractions of `ramp_depth` below sea level.
pub const WATER: [(f32, [u8; 3]); 2] = [(0.0, [78, 150, 212]), (1.0, [16, 40, 104])];

pub(crate) fn interpolate(stops: &[(f32, [u8; 3])], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    for pair in stops.windows(2) {
        let ((t0, c0), (t1, c1)) = (pair[0], pair[1]);
        if t <= t1 {
            let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            return [0, 1, 2].map(|i| (f32::from(c0[i]) + f * (f32::from(c1[i]) - f32::from(c0[i]))).round() as u8);
        }
    }
    stops[stops.len() - 1].1
}

/// The colour of height `h` metres before lighting.
pub fn ramp_colour(style: &Style, h: f32) -> [u8; 3] {
    if h < 0.0 {
        interpolate(&WATER, -h / style.ramp_depth.max(f32::MIN_POSITIVE))
    } else {
        interpolate(&LAND, h / style.ramp_top.max(f32::MIN_POSITIVE))
    }
}

/// The colour tables: land over `[0, ramp_top]`, water over `[−ramp_depth, 0)`, so that sea level
/// is an exact boundary (height 0 is land, any height below it water).
#[derive(Debug, Clone)]
pub struct Ramp {
    land: Vec<[f32; 3]>,
    water: Vec<[f32; 3]>,
    land_scale: f32,
    water_scale: f32,
}

impl Ramp {
    /// The tables for `style`.
    pub fn new(style: &Style) -> Ramp {
        let top = style.ramp_top.max(f32::MIN_POSITIVE);
        let depth = style.ramp_depth.max(f32::MIN_POSITIVE);
        let last = (RAMP_ENTRIES - 1) as f32;
        let table = |stops: &[(f32, [u8; 3])]| -> Vec<[f32; 3]> {
            (0..RAMP_ENTRIES)
                .map(|i| interpolate(stops, i as f32 / last).map(f32::from))
                .collect()
        };
        Ramp {
            land: table(&LAND),
            water: table(&WATER),
            land_scale: last / top,
            water_scale: last / depth,
        }
    }

    /// The colour of height `h` before lighting.
    #[inline]
    pub fn get(&self, h: f32) -> [f32; 3] {
        let last = (RAMP_ENTRIES - 1) as f32;
        if h >= 0.0 {
            self.land[(h * self.land_scale + 0.5).min(last) as usize]
        } else {
            self.water[(-h * self.water_scale + 0.5).min(last) as usize]
        }
    }
}

/// The drawn surface's gradient `[∂y/∂x, ∂y/∂z]` at vertex `(c, r)` of the `cols × rows`
/// heights `h` (finite at the vertex), by central differences (one-sided at the edges); rows
/// `r0`, `r1` are the vertex's neighbours above and below (clamped); heights are drawn times
/// `vertical_scale` on cells `cell` wide. A non-finite neighbour counts as level with the vertex.
#[inline]
pub(crate) fn gradient(
    h: &[f32],
    (cols, rows): (usize, usize),
    (c, r): (usize, usize),
    (r0, r1): (usize, usize),
    (vertical_scale, cell): (f32, f32),
) -> [f32; 2] {
    debug_assert!(r1 < rows);
    let centre = h[r * cols + c];
    let at = |cc: usize, rr: usize| {
        let v = h[rr * cols + cc];
        if v.is_finite() { v } else { centre }
    };
    let (c0, c1) = (c.saturating_sub(1), (c + 1).min(cols - 1));
    let dx = if c1 > c0 {
        (at(c1, r) - at(c0, r)) * vertical_scale / ((c1 - c0) as f32 * cell)
    } else {
        0.0
    };
    let dz = if r1 > r0 {
        (at(c, r1) - at(c, r0)) * vertical_scale / ((r1 - r0) as f32 * cell)
    } else {
        0.0
    };
    [dx, dz]
}

/// Per-vertex light, row-major like the heights; `NaN` where the height is not finite. Returns
/// how many heights are not finite. With `given` (one value per cell, 0 to 1: see
/// [`Scene::light_map`](super::scene::Scene::light_map)) the light is `ambient + (1 − ambient)·given`
/// instead of Lambert's.
pub fn vertex_light(
    map: &Heightmap,
    vertical_scale: f32,
    style: &Style,
    given: Option<&[f32]>,
    out: &mut Vec<f32>,
) -> usize {
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    out.resize(cols * rows, 0.0);
    if cols == 0 || rows == 0 {
        return 0;
    }
    let h = map.heights();
    let s = map.cell_size() as f32;
    let light = world_light(style);
    let ambient = style.ambient.clamp(0.0, 1.0);
    out.par_chunks_mut(cols)
        .enumerate()
        .map(|(r, line)| {
            let mut bad = 0;
            let r0 = r.saturating_sub(1);
            let r1 = (r + 1).min(rows - 1);
            for (c, o) in line.iter_mut().enumerate() {
                let centre = h[r * cols + c];
                if !centre.is_finite() {
                    *o = f32::NAN;
                    bad += 1;
                    continue;
                }
                let [dx, dz] = gradient(h, (cols, rows), (c, r), (r0, r1), (vertical_scale, s));
                if let Some(g) = given.filter(|g| g.len() == cols * rows) {
                    let v = g[r * cols + c];
                    *o = ambient + (1.0 - ambient) * if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 };
                    continue;
                }
                // n = (−dx, 1, −dz)/|…|
                let inv = 1.0 / (dx * dx + 1.0 + dz * dz).sqrt();
                let lambert = ((-dx * light[0] + light[1] - dz * light[2]) * inv).max(0.0);
                *o = ambient + (1.0 - ambient) * lambert;
            }
            bad
        })
        .sum()
}

fn mix(a: Rgba, b: Rgba, t: f32) -> Rgba {
    [0, 1, 2, 3].map(|i| (f32::from(a[i]) + t * (f32::from(b[i]) - f32::from(a[i]))).round() as u8)
}

/// How one eye's samples become colours: the classic ramp, or the land look's ground colours and
/// atmosphere.
pub struct Shading<'a> {
    /// The classic look's colour table (unused by the land look).
    pub ramp: &'a Ramp,
    /// The land look's maps of the terrain, this eye's atmosphere and its background (row-major
    /// over the frame: [`crate::atmosphere::Backdrop`]).
    pub land: Option<(&'a Land, &'a Atmosphere, &'a [[u8; 3]])>,
}

/// A sample's colour before light, for surfaces other than the terrain.
#[inline]
fn surface_colour(surface: Surface, style: &Style) -> Option<[f32; 3]> {
    let flat = |r: Rgba| [f32::from(r[0]), f32::from(r[1]), f32::from(r[2])];
    match surface {
        Surface::Rock => Some(flat(style.rock_colour)),
        Surface::Water => Some(flat(style.water_colour)),
        Surface::Colour([r, g, b]) => Some([f32::from(r), f32::from(g), f32::from(b)]),
        Surface::Terrain => None,
    }
}

/// Resolves a tile of samples into colours: terrain where covered, sky elsewhere. `y0` is the
/// tile's first row in a frame of `frame_height` rows; only columns `x0..x1` are written.
#[allow(clippy::too_many_arguments)]
pub fn resolve(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    (x0, x1): (usize, usize),
    y0: usize,
    frame_height: usize,
    shading: &Shading,
    style: &Style,
) {
    if let Some((land, air, back)) = shading.land {
        let back = &back[(y0 * width).min(back.len())..];
        resolve_land(samples, pixels, width, (x0, x1), y0, (land, air, back), style);
        return;
    }
    let ramp = shading.ramp;
    for (row, (srow, prow)) in samples.chunks(width).zip(pixels.chunks_mut(width)).enumerate() {
        let t = (y0 + row) as f32 / frame_height.max(1) as f32;
        let sky = mix(style.sky_top, style.sky_bottom, t);
        for (s, p) in srow[x0..x1].iter().zip(&mut prow[x0..x1]) {
            if s.invw > 0.0 {
                let w = 1.0 / s.invw;
                let c = surface_colour(s.surface, style).unwrap_or_else(|| ramp.get(s.hw * w));
                let l = (s.lw * w).clamp(0.0, 1.0);
                *p = [(c[0] * l) as u8, (c[1] * l) as u8, (c[2] * l) as u8, 255];
            } else {
                *p = sky;
            }
        }
    }
}

/// [`resolve`] in the land look: a terrain sample's ground colour where its world point lies
/// ([`Land::albedo_at`]), every surface hazed by its distance, the atmosphere behind.
#[allow(clippy::too_many_arguments)]
fn resolve_land(
    samples: &[Sample],
    pixels: &mut [Rgba],
    width: usize,
    (x0, x1): (usize, usize),
    y0: usize,
    (land, air, back): (&Land, &Atmosphere, &[[u8; 3]]),
    style: &Style,
) {
    let step = air.step();
    // Where a cell spans less than a pixel (1/w below this), the nearest cell's colour.
    let fine = 1.0 / air.pixels(land.cell, 1.0).max(f32::MIN_POSITIVE);
    let rows = samples
        .chunks(width)
        .zip(pixels.chunks_mut(width))
        .zip(back.chunks(width));
    for (row, ((srow, prow), brow)) in rows.enumerate() {
        let mut ray = air.ray(x0 as f32 + 0.5, (y0 + row) as f32 + 0.5);
        for ((s, p), b) in srow[x0..x1].iter().zip(&mut prow[x0..x1]).zip(&brow[x0..x1]) {
            let c = if s.invw > 0.0 {
                let w = 1.0 / s.invw;
                let (at, d) = air.point(ray, w);
                let c = surface_colour(s.surface, style).unwrap_or_else(|| {
                    if s.invw < fine {
                        land.nearest_at(at[0], at[1])
                    } else {
                        land.albedo_at(at[0], at[1])
                    }
                });
                let l = (s.lw * w).clamp(0.0, 1.0);
                let c = air.hazed([c[0] * l, c[1] * l, c[2] * l], d);
                [c[0] as u8, c[1] as u8, c[2] as u8]
            } else {
                *b
            };
            *p = [c[0], c[1], c[2], 255];
            ray = [ray[0] + step[0], ray[1] + step[1], ray[2] + step[2]];
        }
    }
}

/// The style's light in the world frame (X = x, Y = up, Z = y), unit length; straight down when
/// the style's light has no direction.
pub(crate) fn world_light(style: &Style) -> [f32; 3] {
    let [lx, ly, lz] = style.light;
    let len = (lx * lx + ly * ly + lz * lz).sqrt();
    if len > 0.0 && len.is_finite() {
        [lx / len, lz / len, ly / len]
    } else {
        [0.0, 1.0, 0.0]
    }
}
