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

mod ground;
mod material;
mod sky;

use rayon::prelude::*;

use crate::raster::mips::Mips;
use crate::scene::light;
use crate::scene::{Scene, Style};
use penmodel_terrain::revision::Mark;

pub use ground::FINE_FADE;
pub(crate) use ground::{Corner, Ground, faded};
pub use material::{
    DRY_GRASS, GRASS, GREY_ROCK, MEADOW, ROCK, SAND, SCREE, SHORE_CELLS, SHORE_METRES, SNOW, Shore, ground_colours,
    material, material_parts, value_noise,
};
use material::{colours, fine_wavelength, noise, shore};
use sky::SkyLight;

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
    fn ground_colours_are_the_materials_of_the_cells() {
        // A flat 4 × 4 grid: the left half under the sea, the right half above the snow line.
        let style = Style::land();
        let high = 2.0 * style.snow_line;
        let heights: Vec<f32> = (0..16).map(|i| if i % 4 < 2 { -5.0 } else { high }).collect();
        let map = penmodel_terrain::Heightmap::from_heights(4, 4, 10.0, heights).expect("heights");
        let c = ground_colours(&map, &style);
        assert_eq!(c.len(), 16);
        let sea = material(&style, -5.0, 0.0, 0.5, 0.5, Shore::NONE);
        assert_eq!(c[0], sea, "under the sea: the depth ramp");
        // On top, flat, far from the edge between them: snow, within the fine noise's 7 %.
        for (have, snow) in c[3].iter().zip(material::rgb(SNOW)) {
            assert!((have - snow).abs() <= 0.05 * snow, "{:?}", c[3]);
        }
        assert!(c.iter().flatten().all(|v| (0.0..=255.0).contains(v)));
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
