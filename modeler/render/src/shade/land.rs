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
//!   would otherwise cost half as much again as a classic one.
//! - **What changed**: a scene from an editor carries the terrain's revisions
//!   ([`Scene::revisions`], `penmodel_terrain::revision`): the maps remember the revision they
//!   were made for and ask for the rectangle changed since, so a frame of an unchanged terrain
//!   does no work per cell. Without revisions the heights are compared with a copy (and
//!   fingerprinted, to tell a moving terrain), as before. Then, in the changed rectangle:
//!   - the colours, grown by a cell for the slopes (all of them when there is water, whose beach
//!     a change can move anywhere);
//!   - the light's blocks of the coarse grid it touches; if one of them changed, the sun and sky
//!     sweeps over the whole coarse grid (at most `light_cells`² blocks, whatever the terrain's
//!     size: a shadow reaches as far as the sun's tangent lets the height difference carry it, a
//!     hidden sky as far as the hill is seen, so they are not bounded by the change), and the
//!     vertices where the heights changed (grown by a cell, for the normals) or where a block's
//!     sun or sky changed (the vertices that interpolate it). A hill's sky light reaches most of
//!     the grid, so most vertices are relit when a hill changes; a change the blocks' averages do
//!     not see relights the rectangle alone.
//!
//!   Each cell's colour and each vertex's light is a function of its neighbourhood and the coarse
//!   maps alone, so the maps after any sequence of changes equal fresh ones to the bit.

use rayon::prelude::*;

use super::ramp::{self, WATER};
use crate::raster::mips::{Level, Mips};
use crate::scene::light;
use crate::scene::{Scene, Style};
use penmodel_terrain::revision::Mark;
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
    /// Ground colour per cell, sRGB 0–255, before light and without the fine noise's
    /// brightness, and that brightness as a factor − 1 (see [`material_parts`]): a pixel fades
    /// it by its footprint ([`Ground::fine_fade`]).
    albedo: Vec<[f32; 4]>,
    /// The colours' box-filtered levels, for pixels that span many cells.
    mips: Mips,
    /// The broad and fine noise per cell: they depend on the grid alone.
    noise: Vec<[f32; 2]>,
    /// The grid the noise is for: columns, rows, cell size.
    noise_grid: (usize, usize, f64),
    cols: usize,
    rows: usize,
    /// Cell size, metres.
    pub(crate) cell: f32,
    /// The fine noise's wavelength, metres ([`fine_wavelength`]).
    fine_metres: f32,
    /// Non-finite heights.
    bad: usize,
    /// Times the maps were remade (a test and the bench read it).
    remakes: u64,
    /// Changed frames since the maps were last remade.
    lagging: u32,
    /// The fingerprint of the last frame's heights (scenes without revisions).
    last_print: u64,
    /// The terrain's revision the maps were made for, when the scene gave its revisions.
    made: Option<Mark>,
    /// The last frame's revision.
    last_mark: Option<Mark>,
    /// The shadows and sky light on their coarse grid, kept for the next change.
    sky_light: SkyLight,
    /// Non-finite heights per row.
    bad_rows: Vec<u32>,
    /// What the last remake recomputed (a test reads it).
    remade: Remade,
}

/// What a remake of the maps recomputed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Remade {
    /// Cells whose ground colour was recomputed.
    pub coloured: u64,
    /// Vertices whose light was recomputed.
    pub relit: u64,
}

/// The shadows and sky light on the coarse grid ([`Style::light_cells`]), kept between remakes:
/// a change recomputes the blocks it touches, sweeps the coarse grid again, and relights the
/// vertices where the heights or these maps changed.
#[derive(Debug, Default)]
struct SkyLight {
    /// Block size in cells, columns and rows of blocks.
    f: usize,
    cc: usize,
    rr: usize,
    /// The drawn heights averaged in blocks.
    z: Vec<f32>,
    /// Per block: the sun seen (1 lit, 0 in shadow) and the sky-view factor.
    sun: Vec<f32>,
    sky: Vec<f32>,
    /// Per vertex, the Lambert term `max(0, n·L)` of the last remake.
    lambert: Vec<f32>,
}

/// A rectangle of cells, columns `c0..c1`, rows `r0..r1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Rect {
    c0: usize,
    c1: usize,
    r0: usize,
    r1: usize,
}

impl Rect {
    /// The cells of the terrain's rectangle `r` on a `cols × rows` grid; `None` when empty.
    fn within(r: penmodel_terrain::rect::Rect, cols: usize, rows: usize) -> Option<Rect> {
        let (c0, r0) = ((r.c0 as usize).min(cols), (r.r0 as usize).min(rows));
        let rect = Rect {
            c0,
            c1: (c0 + r.width as usize).min(cols),
            r0,
            r1: (r0 + r.height as usize).min(rows),
        };
        (rect.c1 > rect.c0 && rect.r1 > rect.r0).then_some(rect)
    }

    /// Grown by `n` cells on every side, clamped to the grid.
    fn grown(self, n: usize, cols: usize, rows: usize) -> Rect {
        Rect {
            c0: self.c0.saturating_sub(n),
            c1: (self.c1 + n).min(cols),
            r0: self.r0.saturating_sub(n),
            r1: (self.r1 + n).min(rows),
        }
    }

    /// The smallest rectangle holding both; `other` may be empty.
    fn union(self, other: Rect) -> Rect {
        if other.c1 <= other.c0 || other.r1 <= other.r0 {
            return self;
        }
        Rect {
            c0: self.c0.min(other.c0),
            c1: self.c1.max(other.c1),
            r0: self.r0.min(other.r0),
            r1: self.r1.max(other.r1),
        }
    }
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

    /// The ground's colour per cell (sRGB 0–255, before light, without the fine noise's
    /// brightness) and that brightness − 1, row-major like the heights.
    pub fn albedo(&self) -> &[[f32; 4]] {
        &self.albedo
    }

    /// What the last remake recomputed (everything when the terrain was new).
    pub fn remade(&self) -> Remade {
        self.remade
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
        // What changed since the maps were made, and whether the terrain moved since the last
        // frame: from the terrain's revisions when the scene has them (no work per cell), else by
        // comparing the heights with the copy and a fingerprint of the last frame's.
        let (rect, moving) = match scene.revisions {
            Some(revisions) => {
                let now = revisions.mark();
                let moving = self.last_mark != Some(now);
                self.last_mark = Some(now);
                let since = self.made.filter(|_| same).and_then(|m| revisions.since(m));
                let rect = match since {
                    None => Some(full),
                    Some(r) => Rect::within(r, cols, rows),
                };
                (rect, moving)
            }
            None => {
                self.last_mark = None;
                let rect = if same {
                    changed(&self.heights, h, cols)
                } else {
                    Some(full)
                };
                let print = fingerprint(h);
                let moving = print != self.last_print;
                self.last_print = print;
                (rect, moving)
            }
        };
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
        self.made = scene.revisions.map(|r| r.mark());
        self.cols = cols;
        self.rows = rows;
        self.cell = map.cell_size() as f32;
        self.fine_metres = fine_wavelength(map.cell_size()) as f32;
        if !same {
            rect = full;
        }
        if self.heights.len() != h.len() {
            self.heights = h.to_vec();
        } else {
            let (a, b) = (rect.r0 * cols, rect.r1 * cols);
            self.heights[a..b].copy_from_slice(&h[a..b]);
        }
        // The sea can only have appeared in the changed rectangle, unless there was water.
        let seen = if self.water || rect == full { full } else { rect };
        let sea = h[seen.r0 * cols..seen.r1 * cols]
            .par_chunks(cols.max(1))
            .any(|line| line[seen.c0..seen.c1].iter().any(|&v| v < 0.0));
        let water = sea || key.rivers;
        if water || water != self.water {
            // The beach follows the water, which a change can move anywhere: all of it again.
            rect = full;
        }
        self.water = water;
        self.shore = if water { shore(scene) } else { Vec::new() };
        // The slopes read a cell's neighbours.
        let grown = rect.grown(1, cols, rows);
        if self.noise_grid != (cols, rows, map.cell_size()) || self.noise.len() != cols * rows {
            self.noise = noise(cols, rows, map.cell_size());
            self.noise_grid = (cols, rows, map.cell_size());
        }
        self.albedo.resize(cols * rows, [0.0; 4]);
        colours(map, &scene.style, &self.shore, grown, &self.noise, &mut self.albedo);
        self.mips
            .update(&self.albedo, (cols, rows), [grown.c0, grown.c1, grown.r0, grown.r1]);
        self.remade.coloured = ((grown.c1 - grown.c0) * (grown.r1 - grown.r0)) as u64;
        // Non-finite heights, counted again in the changed rows.
        self.bad_rows.resize(rows, 0);
        for (r, n) in self.bad_rows.iter_mut().enumerate().take(rect.r1).skip(rect.r0) {
            *n = h[r * cols..(r + 1) * cols].iter().filter(|v| !v.is_finite()).count() as u32;
        }
        self.bad = match scene.light_map {
            Some(given) => {
                self.sky_light = SkyLight::default();
                self.remade.relit = (cols * rows) as u64;
                light::vertex_light(map, scene.vertical_scale, &scene.style, Some(given), light)
            }
            None => {
                let whole = rect == full || light.len() != cols * rows;
                self.remade.relit = self
                    .sky_light
                    .relight(map, scene.vertical_scale, &scene.style, rect, whole, light);
                self.bad_rows.iter().map(|&n| n as usize).sum()
            }
        };
        self.key = Some(key);
        self.bad
    }

    /// What a tile's pixels read of the maps: the colours and the grid, kept in locals.
    pub(crate) fn ground(&self) -> Ground<'_> {
        const NOTHING: [[f32; 4]; 1] = [[0.0; 4]];
        if self.cols == 0 || self.rows == 0 || self.albedo.len() < self.cols * self.rows {
            return Ground {
                albedo: &NOTHING,
                mips: &[],
                cols: 1,
                inv: 0.0,
                last: [0.0, 0.0],
                fine_metres: 0.0,
            };
        }
        Ground {
            albedo: &self.albedo,
            mips: self.mips.levels(),
            cols: self.cols,
            inv: 1.0 / self.cell,
            last: [(self.cols - 1) as f32, (self.rows - 1) as f32],
            fine_metres: self.fine_metres,
        }
    }
}

/// The land look's maps as a pixel reads them ([`Land::ground`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ground<'a> {
    albedo: &'a [[f32; 4]],
    /// Levels 1, 2, … of `albedo`, box-filtered ([`crate::raster::mips`]).
    mips: &'a [Level],
    cols: usize,
    /// 1 / cell size.
    inv: f32,
    /// The last column and row.
    last: [f32; 2],
    fine_metres: f32,
}

/// Where the fine noise fades, in pixels per wavelength along the ground's shorter side on
/// screen: its mean below the first, all of it above the second (smooth between). With the
/// noise's 3-cell wavelength on coarse grids that is a cell under 2 px on screen (the mean) to
/// over 4 px (all of it): finer, the noise would alias — shimmer as the view moves, and every
/// pixel of a moving frame changed.
pub const FINE_FADE: [f32; 2] = [6.0, 12.0];

impl Ground<'_> {
    /// How much of the fine noise a pixel shows (0 to 1): `pixels_per_metre` the screen's
    /// pixels per metre across the view at the sample's depth, `sin` the sine of the view ray's
    /// elevation (flat ground seen at a grazing angle is foreshortened by it along the ray).
    #[inline(always)]
    pub(crate) fn fine_fade(&self, pixels_per_metre: f32, sin: f32) -> f32 {
        let px = self.fine_metres * pixels_per_metre * sin;
        let t = ((px - FINE_FADE[0]) * (1.0 / (FINE_FADE[1] - FINE_FADE[0]))).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// The cell position `(x, z)` metres falls in, clamped to the grid; a NaN (a point from a
    /// degenerate view) gives the first cell (`f32::max` returns the other operand).
    #[inline(always)]
    fn place(&self, x: f32, z: f32, half: f32) -> (f32, f32) {
        (
            within(x * self.inv - half, self.last[0]),
            within(z * self.inv - half, self.last[1]),
        )
    }

    /// The box-filtered levels above the colours ([`crate::raster::mips`]).
    #[inline]
    pub(crate) fn levels(&self) -> usize {
        self.mips.len()
    }

    /// The ground's colour (sRGB 0–255, before light) of the cell of `level` (0: the map's own
    /// cells; `L`: the mean of `2^L × 2^L` of them) holding world `(x, z)` metres, with `fade` of
    /// the fine noise: for pixels where a cell is smaller than a pixel, where interpolating
    /// between cells would show nothing more and costs three times as much. A level past the
    /// last one kept reads the last. (The resolve applies the fade itself, in vector lanes:
    /// [`Ground::nearest_parts`] and [`faded`].)
    #[cfg(test)]
    pub(crate) fn nearest_at(&self, level: usize, x: f32, z: f32, fade: f32) -> [f32; 3] {
        faded(self.nearest_parts(level, x, z), fade)
    }

    /// [`Ground::nearest_at`] before the fade: the colour and the fine noise's factor.
    #[inline(always)]
    pub(crate) fn nearest_parts(&self, level: usize, x: f32, z: f32) -> [f32; 4] {
        match level.min(self.mips.len()) {
            0 => {
                let (u, v) = self.place(x, z, 0.0);
                self.albedo[v as u32 as usize * self.cols + u as u32 as usize]
            }
            l => {
                let m = &self.mips[l - 1];
                let inv = self.inv / (1u32 << l) as f32;
                let u = within(x * inv, (m.cols - 1) as f32);
                let v = within(z * inv, (m.rows - 1) as f32);
                m.cells[v as u32 as usize * m.cols + u as u32 as usize].unpack()
            }
        }
    }

    /// The ground's colour (sRGB 0–255, before light) at world `(x, z)` metres, bilinear between
    /// the cell centres, with `fade` of the fine noise: [`Ground::corner`], [`Ground::bilinear`]
    /// and [`faded`], which the resolve calls in its passes.
    #[cfg(test)]
    pub(crate) fn albedo_at(&self, x: f32, z: f32, fade: f32) -> [f32; 3] {
        faded(self.bilinear(self.corner(x, z)), fade)
    }

    /// Whether [`Ground::corner`] is exact for every point: the grid is under 2²³ cells a side
    /// (so is any grid that fits in memory, short of a line of cells).
    #[inline]
    pub(crate) fn corners_computed(&self) -> bool {
        self.last[0] < SMALL && self.last[1] < SMALL
    }

    /// Where [`Ground::albedo_at`] reads `(x, z)`: arithmetic only, without a branch, a lookup
    /// or a float-to-integer cast (which the compiler keeps scalar), so that the resolve
    /// computes it for a stretch of pixels in vector lanes ([`crate::shade`]); exact where
    /// [`Ground::corners_computed`], [`Ground::corner_cast`] else. [`Ground::bilinear`] reads
    /// the cells.
    #[inline(always)]
    pub(crate) fn corner(&self, x: f32, z: f32) -> Corner {
        let (u, v) = self.place(x, z, 0.5);
        // `u` and `v` are in `[0, last]` (a NaN became 0).
        self.corner_at(u, v, floor_small(u), floor_small(v))
    }

    /// [`Ground::corner`] by casts, for any grid.
    #[inline(always)]
    pub(crate) fn corner_cast(&self, x: f32, z: f32) -> Corner {
        let (u, v) = self.place(x, z, 0.5);
        let (c, r) = (u as u32, v as u32);
        self.corner_at(u, v, (c, c as f32), (r, r as f32))
    }

    /// The [`Corner`] of the cell position `(u, v)` whose floors are `(c, cf)` and `(r, rf)`
    /// (as an integer and as a float), however [`Ground::corner`] or [`Ground::corner_cast`]
    /// found them.
    #[inline(always)]
    fn corner_at(&self, u: f32, v: f32, (c, cf): (u32, f32), (r, rf): (u32, f32)) -> Corner {
        Corner {
            index: r.wrapping_mul(self.cols as u32).wrapping_add(c),
            fu: u - cf,
            fv: v - rf,
            // The next column and row, or these on the last.
            dc: u32::from(u < self.last[0]),
            dr: if v < self.last[1] { self.cols as u32 } else { 0 },
        }
    }

    /// The colour and the fine noise's factor bilinear between the four cells at `corner`.
    #[inline(always)]
    pub(crate) fn bilinear(&self, corner: Corner) -> [f32; 4] {
        let Corner { index, fu, fv, dc, dr } = corner;
        let (i, dc, dr) = (index as usize, dc as usize, dr as usize);
        let a = self.albedo;
        let top = lerp4(a[i].into(), a[i + dc].into(), fu);
        lerp4(top, lerp4(a[i + dr].into(), a[i + dr + dc].into(), fu), fv).to_array()
    }
}

/// The cell at or before a point in both directions (row-major `index`), the point's fractions
/// `fu`, `fv` past it, and the offsets of the next column (`dc`: 1, or 0 on the last) and row
/// (`dr`: a row of cells, or 0 on the last): [`Ground::corner`]. (32 bits: a colour map of 2³²
/// cells would be 64 GB.)
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Corner {
    pub(crate) index: u32,
    pub(crate) fu: f32,
    pub(crate) fv: f32,
    pub(crate) dc: u32,
    pub(crate) dr: u32,
}

/// A colour with its fine noise's factor ([`Ground::bilinear`]) as a pixel shows it with `fade`
/// of the noise: `colour × (1 + fade·factor)`.
#[inline(always)]
pub(crate) fn faded(p: [f32; 4], fade: f32) -> [f32; 3] {
    let k = 1.0 + fade * p[3];
    [p[0] * k, p[1] * k, p[2] * k]
}

/// `v` clamped to `[0, last]`, a NaN to 0: `v.max(0.0).min(last)` as two compares (a NaN fails
/// the first), without the NaN handling `f32::max` and `min` compile to (a tenth of a ground
/// pixel's instructions). `last` is never NaN.
#[inline(always)]
fn within(v: f32, last: f32) -> f32 {
    let v = if v > 0.0 { v } else { 0.0 };
    if v < last { v } else { last }
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
use crate::simd::floor::{SMALL, floor_small};
use crate::simd::lanes::lerp4;

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
/// degrees, with noises `broad` and `fine` in `[0, 1)`, and `shore` for the beach: its
/// [`material_parts`] with all of the fine noise.
pub fn material(style: &Style, h: f32, slope: f32, broad: f32, fine: f32, shore: Shore) -> [f32; 3] {
    let (c, k) = material_parts(style, h, slope, broad, fine, shore);
    c.map(|v| v * (1.0 + k))
}

/// [`material`] in two parts: the colour without the fine noise's brightness (its mean), and that
/// brightness as a factor − 1, at most what keeps every channel ≤ 255: a pixel shows
/// `colour × (1 + fade·k)`, the fade by its footprint ([`FINE_FADE`]).
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

/// The fine noise's wavelength on cells of `s` metres: 24 m, at least 3 cells.
fn fine_wavelength(s: f64) -> f64 {
    24f64.max(3.0 * s)
}

/// The broad and fine noise at each cell's centre.
fn noise(cols: usize, rows: usize, s: f64) -> Vec<[f32; 2]> {
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

/// The colours of the cells in `rect`.
fn colours(
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

/// Block `(i, j)` of `f × f` cells of the `cols × rows` heights `h`, averaged and × `scale`
/// (non-finite heights count as 0: their triangles are holes anyway).
#[inline]
fn block(h: &[f32], (cols, rows): (usize, usize), f: usize, (i, j): (usize, usize), scale: f32) -> f32 {
    let (mut sum, mut n) = (0.0f32, 0u32);
    for r in j * f..((j + 1) * f).min(rows) {
        for &v in &h[r * cols + i * f..r * cols + ((i + 1) * f).min(cols)] {
            if v.is_finite() {
                sum += v;
            }
            n += 1;
        }
    }
    sum / n.max(1) as f32 * scale
}

/// The sun's azimuth (from +x towards +y) and elevation, radians, of the style's light.
fn sun_angles(style: &Style) -> (f64, f64) {
    let [x, y, up] = style.light.map(f64::from);
    (y.atan2(x), up.atan2(x.hypot(y)))
}

impl SkyLight {
    /// Brings the coarse maps up to date after the heights changed in `rect` (all of them when
    /// `whole`) and writes the light of every vertex it may have changed into `out` (see the
    /// module's notes): the blocks `rect` touches are averaged again; if one changed, the sun and
    /// sky sweeps run over the whole coarse grid again (a shadow or a hidden sky can reach any
    /// distance) and the vertices are relit where the heights changed (grown by a cell, for the
    /// normals) and where the sun or sky of a block changed (its bilinear footprint). Returns
    /// how many vertices were relit. A vertex's light is a function of its 3 × 3 heights and
    /// the coarse maps alone, so this equals relighting them all.
    fn relight(
        &mut self,
        map: &penmodel_terrain::Heightmap,
        vertical_scale: f32,
        style: &Style,
        rect: Rect,
        whole: bool,
        out: &mut Vec<f32>,
    ) -> u64 {
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
        let (cc, rr) = (cols.div_ceil(f), rows.div_ceil(f));
        let whole = whole || (self.f, self.cc, self.rr) != (f, cc, rr) || self.z.len() != cc * rr;
        let h = map.heights();
        let everything = Rect {
            c0: 0,
            c1: cols,
            r0: 0,
            r1: rows,
        };
        let mut relit = rect.grown(1, cols, rows);
        // Where the normals change.
        let mut moved = relit;
        if whole {
            self.f = f;
            self.cc = cc;
            self.rr = rr;
            self.z = vec![0.0f32; cc * rr];
            self.z.par_chunks_mut(cc).enumerate().for_each(|(j, line)| {
                for (i, o) in line.iter_mut().enumerate() {
                    *o = block(h, (cols, rows), f, (i, j), vertical_scale);
                }
            });
            let (sun, sky) = sweeps(&self.z, (cc, rr), map.cell_size() * f as f64, style);
            self.sun = sun;
            self.sky = sky;
            relit = everything;
            moved = everything;
        } else {
            // The blocks the change touches.
            let mut moved = false;
            for j in rect.r0 / f..rect.r1.div_ceil(f).min(rr) {
                for i in rect.c0 / f..rect.c1.div_ceil(f).min(cc) {
                    let v = block(h, (cols, rows), f, (i, j), vertical_scale);
                    moved |= v.to_bits() != self.z[j * cc + i].to_bits();
                    self.z[j * cc + i] = v;
                }
            }
            if moved {
                let (sun, sky) = sweeps(&self.z, (cc, rr), map.cell_size() * f as f64, style);
                // The blocks whose sun or sky changed, and the vertices that read them.
                let mut blocks: Option<Rect> = None;
                for (k, ((a, b), (c, d))) in sun.iter().zip(&self.sun).zip(sky.iter().zip(&self.sky)).enumerate() {
                    if a.to_bits() != b.to_bits() || c.to_bits() != d.to_bits() {
                        let (i, j) = (k % cc, k / cc);
                        let one = Rect {
                            c0: i,
                            c1: i + 1,
                            r0: j,
                            r1: j + 1,
                        };
                        blocks = Some(blocks.map_or(one, |b| b.union(one)));
                    }
                }
                if let Some(b) = blocks {
                    relit = relit.union(footprint(b, f, (cc, rr), (cols, rows)));
                }
                self.sun = sun;
                self.sky = sky;
            }
        }
        self.vertices(map, vertical_scale, style, (relit, moved), out);
        ((relit.c1 - relit.c0) * (relit.r1 - relit.r0)) as u64
    }

    /// The light of the vertices in `rect` (see the module's notes); their Lambert term is
    /// recomputed in `moved` (where the heights changed, grown by a cell) and read from the last
    /// remake elsewhere, the same `f32`.
    fn vertices(
        &mut self,
        map: &penmodel_terrain::Heightmap,
        vertical_scale: f32,
        style: &Style,
        (rect, moved): (Rect, Rect),
        out: &mut [f32],
    ) {
        let (cols, rows) = (map.cols() as usize, map.rows() as usize);
        let (f, cc, rr) = (self.f, self.cc, self.rr);
        self.lambert.resize(cols * rows, 0.0);
        let h = map.heights();
        let s = map.cell_size() as f32;
        let light = light::world_light(style);
        let ambient = style.ambient.clamp(0.0, 1.0);
        // A vertex's place on the coarse grid: block centres at (i + ½)f − ½ cells; the same
        // for a whole column or row, so worked out once for each.
        let half = (f as f32 - 1.0) * 0.5;
        let inv_f = 1.0 / f as f32;
        let place = |c: usize, n: usize| {
            let u = ((c as f32 - half) * inv_f).clamp(0.0, (n - 1) as f32);
            let i = u as usize;
            (i, (i + 1).min(n - 1), u - i as f32)
        };
        let across: Vec<(usize, usize, f32)> = (rect.c0..rect.c1).map(|c| place(c, cc)).collect();
        let (sun, sky) = (&self.sun, &self.sky);
        let lines = out[rect.r0 * cols..rect.r1 * cols]
            .par_chunks_mut(cols)
            .zip(self.lambert[rect.r0 * cols..rect.r1 * cols].par_chunks_mut(cols));
        lines.enumerate().for_each(|(k, (line, lamberts))| {
            let r = rect.r0 + k;
            let (r0, r1) = (r.saturating_sub(1), (r + 1).min(rows - 1));
            let (j, j1, fv) = place(r, rr);
            let bilinear = |m: &[f32], (i, i1, fu): (usize, usize, f32)| {
                let top = m[j * cc + i] + fu * (m[j * cc + i1] - m[j * cc + i]);
                let bottom = m[j1 * cc + i] + fu * (m[j1 * cc + i1] - m[j1 * cc + i]);
                top + fv * (bottom - top)
            };
            let normals = (moved.r0..moved.r1).contains(&r);
            for (c, at) in (rect.c0..rect.c1).zip(&across) {
                let centre = h[r * cols + c];
                if !centre.is_finite() {
                    line[c] = f32::NAN;
                    continue;
                }
                if normals && (moved.c0..moved.c1).contains(&c) {
                    let [dx, dz] = light::gradient(h, (cols, rows), (c, r), (r0, r1), (vertical_scale, s));
                    let inv = 1.0 / (dx * dx + 1.0 + dz * dz).sqrt();
                    lamberts[c] = ((-dx * light[0] + light[1] - dz * light[2]) * inv).max(0.0);
                }
                let seen = bilinear(sun, *at);
                let open = bilinear(sky, *at);
                line[c] = ambient * open + (1.0 - ambient) * seen * lamberts[c];
            }
        });
    }
}

/// The sun seen and the sky-view factor per cell of the coarse heights `z` (`cc × rr` blocks
/// `cell` metres wide), by issue 12's horizon sweeps.
fn sweeps(z: &[f32], (cc, rr): (usize, usize), cell: f64, style: &Style) -> (Vec<f32>, Vec<f32>) {
    let field = Field {
        z,
        cols: cc as u32,
        rows: rr as u32,
        cell,
    };
    let (azimuth, elevation) = sun_angles(style);
    let mut sun_seen = vec![0.0f32; z.len()];
    if elevation > 0.0 {
        sun::horizons(field, azimuth, |i, t| {
            let above = elevation - t.atan();
            sun_seen[i] = (above / PENUMBRA + 0.5).clamp(0.0, 1.0) as f32;
        });
    }
    (sun_seen, sun::sky_view(field, style.sky_directions.max(1)))
}

/// The vertices that read blocks `b` (of `f × f` cells, `cc × rr` of them) when they interpolate
/// the coarse maps: a vertex reads the block its place falls in and the next one, so a block's
/// readers reach from the previous block's centre to the next one's; a cell more on each side for
/// the rounding of that place.
fn footprint(b: Rect, f: usize, (cc, rr): (usize, usize), (cols, rows): (usize, usize)) -> Rect {
    let lo = |i: usize| if i == 0 { 0 } else { ((i - 1) * f).saturating_sub(1) };
    let hi = |i: usize, n: usize, len: usize| if i + 1 >= n { len } else { ((i + 2) * f + 1).min(len) };
    Rect {
        c0: lo(b.c0),
        c1: hi(b.c1 - 1, cc, cols),
        r0: lo(b.r0),
        r1: hi(b.r1 - 1, rr, rows),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 grid of 10 m cells: colours and fine terms chosen by the test.
    fn ground(albedo: &[[f32; 4]]) -> Ground<'_> {
        Ground {
            albedo,
            mips: &[],
            cols: 2,
            inv: 0.1,
            last: [1.0, 1.0],
            fine_metres: 30.0,
        }
    }

    #[test]
    fn the_fine_noise_fades_with_its_footprint() {
        let cells = [
            [100.0, 80.0, 60.0, 0.05],
            [200.0, 180.0, 160.0, -0.05],
            [0.0; 4],
            [0.0; 4],
        ];
        let g = ground(&cells);
        // Pixels per metre that put a wavelength (30 m) at `px` pixels seen from straight above.
        let fade = |px: f32, sin: f32| g.fine_fade(px / 30.0, sin);
        assert_eq!(fade(FINE_FADE[0], 1.0), 0.0);
        assert_eq!(fade(0.5 * FINE_FADE[0], 1.0), 0.0);
        assert_eq!(fade(FINE_FADE[1], 1.0), 1.0);
        assert_eq!(fade(10.0 * FINE_FADE[1], 1.0), 1.0);
        // Foreshortened: the same distance at a grazing angle shows less of it.
        assert_eq!(fade(FINE_FADE[1], 0.4), 0.0);
        let mut last = 0.0;
        for i in 0..=100 {
            let f = fade(FINE_FADE[0] + (FINE_FADE[1] - FINE_FADE[0]) * i as f32 / 100.0, 1.0);
            assert!(f >= last && f <= 1.0);
            last = f;
        }
        // Faded out, a pixel sees the cells' colour without the noise; in full, × (1 + k).
        let mid = g.albedo_at(10.0, 5.0, 0.0);
        for (m, (a, b)) in mid.iter().zip(cells[0].iter().zip(&cells[1])) {
            assert!((m - 0.5 * (a + b)).abs() < 1e-3);
        }
        let near = g.nearest_at(0, 4.0, 4.0, 1.0);
        for (n, want) in near.iter().zip([105.0, 84.0, 63.0]) {
            assert!((n - want).abs() < 1e-3);
        }
        assert_eq!(g.nearest_at(0, 4.0, 4.0, 0.0), [100.0, 80.0, 60.0]);
        // A NaN point reads the first cell.
        assert_eq!(g.nearest_at(0, f32::NAN, f32::NAN, 0.0), [100.0, 80.0, 60.0]);
    }

    #[test]
    fn a_pixel_spanning_many_cells_reads_their_mean() {
        let cells = [
            [100.0, 80.0, 60.0, 0.05],
            [200.0, 180.0, 160.0, -0.05],
            [10.0, 20.0, 30.0, 0.0],
            [50.0, 40.0, 30.0, 0.02],
        ];
        let mut mips = Mips::default();
        mips.update(&cells, (2, 2), [0, 2, 0, 2]);
        let g = Ground {
            mips: mips.levels(),
            ..ground(&cells)
        };
        assert_eq!(g.levels(), 1);
        // Level 0 is the cell itself; level 1 (and any level past the last) the mean of the four.
        assert_eq!(g.nearest_at(0, 14.0, 4.0, 0.0), [200.0, 180.0, 160.0]);
        let mean = [90.0, 80.0, 70.0];
        for level in [1, 5] {
            for (x, z) in [(4.0, 4.0), (14.0, 14.0), (-3.0, 30.0)] {
                let got = g.nearest_at(level, x, z, 0.0);
                for (g, m) in got.iter().zip(mean) {
                    assert!((g - m).abs() < 1e-3, "level {level} at ({x}, {z}): {got:?}");
                }
            }
        }
        // The fine noise's factor is averaged too: (0.05 − 0.05 + 0 + 0.02) / 4, to a step of
        // 1/1024.
        let faded = g.nearest_at(1, 4.0, 4.0, 1.0);
        assert!((faded[0] - 90.0 * 1.005).abs() <= 90.0 * 0.5 / 1024.0 + 1e-3);
    }

    #[test]
    fn the_computed_corner_is_the_casts() {
        // (The floor it uses is checked against the cast in `floor`.)
        let cells = [[1.0, 2.0, 3.0, 0.0]; 12];
        let g = Ground {
            cols: 4,
            last: [3.0, 2.0],
            ..ground(&cells)
        };
        assert!(g.corners_computed());
        for x in -20..60 {
            for z in -20..40 {
                let (x, z) = (x as f32 * 0.7, z as f32 * 0.9);
                let (a, b) = (g.corner(x, z), g.corner_cast(x, z));
                assert_eq!(
                    (a.index, a.fu, a.fv, a.dc, a.dr),
                    (b.index, b.fu, b.fv, b.dc, b.dr),
                    "at ({x}, {z})"
                );
            }
        }
        let wide = Ground { last: [9e6, 0.0], ..g };
        assert!(!wide.corners_computed());
    }

    #[test]
    fn the_parts_make_the_material() {
        let style = Style::land();
        for (h, slope, fine) in [
            (20.0, 3.0, 0.9),
            (2500.0, 10.0, 0.99),
            (900.0, 40.0, 0.1),
            (-3.0, 0.0, 0.7),
        ] {
            let (c, k) = material_parts(&style, h, slope, 0.4, fine, Shore::NONE);
            assert!(k.abs() <= 0.07 + 1e-6);
            let full = material(&style, h, slope, 0.4, fine, Shore::NONE);
            for (f, c) in full.iter().zip(c) {
                assert!((f - c * (1.0 + k)).abs() < 1e-3 && *f <= 255.0 + 1e-3);
            }
        }
    }
}
