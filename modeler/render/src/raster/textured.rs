//! Textured, alpha-tested polygons: quads with an RGBA texture, drawn into the terrain's depth
//! buffer (the simplified shapes of trees, [`crate::scene::impostor`]).
//!
//! - **Perspective-correct texture coordinates**: a vertex carries `u/w` and `v/w` in the
//!   rasteriser's two interpolated slots (the height's and the light's), which are affine in
//!   screen space like `1/w`; a pixel divides them by its `1/w`. Clipping cuts `u` and `v`
//!   before the division, where they are linear.
//! - **Nearest texel**, not bilinear: the textures are rendered images of branches whose alpha
//!   is 0 or 1, so a filtered alpha would only move the cut-out's edge by under a texel, and
//!   nearest keeps the test's texel exact (the alpha-test test checks the background shows
//!   through every texel of alpha 0).
//! - **Alpha test**: texels with alpha below 128 (0.5) are discarded before the depth buffer is
//!   touched, so they neither hide what lies behind nor write depth; the order in which
//!   polygons are drawn does not matter.
//! - Texels are lit already (rendered with the light, [`crate::scene::impostor::bake`]): a drawn texel
//!   is [`Surface::Colour`] at full light.
//! - **Levels** (mipmaps): a texture keeps box-filtered halvings of itself, each texel the mean
//!   of four (colour weighted by alpha, so transparent texels do not darken the edge), and a quad
//!   drawn smaller than its texels reads the level whose texels are about a pixel
//!   ([`Texture::level_for`], chosen per quad when it is projected). A tree's simplified shapes are
//!   tens of pixels across with 64-texel images: read at level 0, neighbouring pixels fetched
//!   texels rows apart, and that load was 47 % of the textured triangles' time, a third of the
//!   30-tree frame (`perf`, issue 14). The alpha test applies to the mean alpha: a texel of a
//!   level is drawn where at least half of what it covers is.
//! - Quads are drawn from both windings, like the meshes; triangles are binned by bands of rows
//!   as the meshes are.

use std::ops::Range;

use super::binned::{Binned, Faces};
use super::clip::ClipVertex;
use super::rasterise::{self, Bounds, Sample, Sink, Surface};
use super::transform::Affine;
use crate::output::frame::Rgba;

/// Most texels a side of a [`Texture`] has (the texel lookup indexes a side in 16 bits).
pub(crate) const MAX_SIDE: u32 = 1 << 16;

/// An RGBA image, row 0 at the top, and its box-filtered levels.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Texture {
    width: u32,
    height: u32,
    texels: Vec<Rgba>,
    /// Levels 1, 2, …: `(width, height, texels)`, each half the one before (rounding up), down to
    /// a texel a side.
    levels: Vec<(u32, u32, Vec<Rgba>)>,
}

/// The level below `(w, h, texels)`: each texel the mean of the (up to) four it covers, colour
/// weighted by alpha.
fn halve(w: u32, h: u32, texels: &[Rgba]) -> (u32, u32, Vec<Rgba>) {
    let (hw, hh) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = Vec::with_capacity(hw as usize * hh as usize);
    for y in 0..hh {
        for x in 0..hw {
            let mut sum = [0u32; 4];
            let mut n = 0;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (sx, sy) = (2 * x + dx, 2 * y + dy);
                if sx < w && sy < h {
                    let t = texels[(sy * w + sx) as usize];
                    let a = u32::from(t[3]);
                    for (s, c) in sum.iter_mut().zip(&t[..3]) {
                        *s += u32::from(*c) * a;
                    }
                    sum[3] += a;
                    n += 1;
                }
            }
            let colour = |s: u32| (s + sum[3] / 2).checked_div(sum[3]).map_or(0, |c| c as u8);
            out.push([
                colour(sum[0]),
                colour(sum[1]),
                colour(sum[2]),
                ((sum[3] + n / 2) / n) as u8,
            ]);
        }
    }
    (hw, hh, out)
}

impl Texture {
    /// A texture of `width × height` texels, row-major from the top; `None` unless the sizes
    /// agree and each side is 1 to [`MAX_SIDE`] texels.
    pub fn new(width: u32, height: u32, texels: Vec<Rgba>) -> Option<Texture> {
        let sides = 1..=MAX_SIDE;
        if !sides.contains(&width) || !sides.contains(&height) || texels.len() != width as usize * height as usize {
            return None;
        }
        let mut levels: Vec<(u32, u32, Vec<Rgba>)> = Vec::new();
        let (mut w, mut h) = (width, height);
        while w > 1 || h > 1 {
            let next = halve(w, h, levels.last().map_or(&texels, |l| &l.2));
            (w, h) = (next.0, next.1);
            levels.push(next);
        }
        Some(Texture {
            width,
            height,
            texels,
            levels,
        })
    }

    /// How many levels above the image it keeps.
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// The level to read where a pixel spans `texels` texels: `⌊log₂ texels⌋` (0 below 2),
    /// at most the last.
    pub fn level_for(&self, texels: f32) -> u8 {
        // Levels stop at one texel, so there are fewer than 32 of them.
        super::mips::level_for(texels, self.levels.len()) as u8
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major from the top.
    pub fn texels(&self) -> &[Rgba] {
        &self.texels
    }

    /// The texel nearest `(u, v)`, both 0 to 1 across the texture (v down), clamped at the edges.
    #[inline]
    pub fn nearest(&self, u: f32, v: f32) -> Rgba {
        self.nearest_in(0, u, v)
    }

    /// [`Texture::nearest`] in `level` (0: the image; past the last: the last).
    #[inline]
    pub fn nearest_in(&self, level: u8, u: f32, v: f32) -> Rgba {
        self.level(level).nearest(u, v)
    }

    /// `level` (0: the image; past the last: the last) as a pixel reads it.
    #[inline]
    fn level(&self, level: u8) -> Level<'_> {
        let (w, h, texels) = match (level as usize).min(self.levels.len()) {
            0 => (self.width, self.height, &self.texels),
            l => {
                let (w, h, t) = &self.levels[l - 1];
                (*w, *h, t)
            }
        };
        Level {
            texels,
            size: [w as f32, h as f32],
            // Sides are at most `MAX_SIDE`, so the last texel's index fits.
            last: [(w - 1) as u16, (h - 1) as u16],
            stride: w as usize,
        }
    }
}

/// One level of a [`Texture`], its sizes kept as the texel lookup uses them: a textured
/// triangle's pixels all read the same level, so it is looked up once per triangle
/// ([`TexelSink`]), not per pixel (that match and the conversions were a fifth of the textured
/// pixels' instructions).
#[derive(Clone, Copy)]
struct Level<'a> {
    texels: &'a [Rgba],
    size: [f32; 2],
    last: [u16; 2],
    stride: usize,
}

impl Level<'_> {
    /// The texel nearest `(u, v)`, both 0 to 1 across the texture (v down), clamped at the edges.
    #[inline(always)]
    fn nearest(&self, u: f32, v: f32) -> Rgba {
        // Truncated towards zero and clamped, as `as i32` then `clamp(0, last)` would (below 0
        // and NaN: 0; past the last: the last, which is under `u16::MAX`): a cast to 16 bits
        // saturates in floating point, three instructions where 32 bits took a dozen.
        let x = ((u * self.size[0]) as u16).min(self.last[0]);
        let y = ((v * self.size[1]) as u16).min(self.last[1]);
        self.texels[usize::from(y) * self.stride + usize::from(x)]
    }
}

/// A textured quad in the exports' frame (X, Y up, Z; metres): corners in order round it, the
/// texture coordinates of each (0 to 1, v down) and the texture's index in the table the draw is
/// given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quad {
    /// The corners, in order round the quad.
    pub corners: [[f32; 3]; 4],
    /// `(u, v)` of each corner.
    pub uv: [[f32; 2]; 4],
    /// Which texture.
    pub texture: u32,
}

/// One eye's projected quads, each tagged with its texture's index and level.
#[derive(Debug, Default)]
pub(crate) struct Projected(Binned<(u32, u8), 4>);

impl Projected {
    /// Forgets the last frame's quads, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the quads.
    pub(crate) fn clear(&mut self, bands: (usize, usize)) {
        self.0.clear(bands);
    }

    /// Projects `quads` for one eye (with the terrain's `affine` map and `cell_size`) and bins
    /// their triangles; their texture indices (into `textures`, which [`Projected::draw`] will
    /// be given) are offset by `first_texture`, and each quad reads the level of its texture
    /// whose texels are about its pixels.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn add(
        &mut self,
        quads: &[Quad],
        first_texture: u32,
        textures: &[&Texture],
        affine: &Affine,
        cell_size: f64,
        near: f32,
    ) {
        let first = self.0.triangles();
        let s = cell_size as f32;
        for q in quads {
            let base = self.0.vertices();
            let mut corners = [ClipVertex {
                x: 0.0,
                y: 0.0,
                w: 0.0,
                h: 0.0,
                l: 0.0,
            }; 4];
            for ((p, uv), corner) in q.corners.iter().zip(&q.uv).zip(&mut corners) {
                // u and v ride in the height and light slots: interpolated as u/w, v/w.
                let v = affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], 0.0);
                *corner = ClipVertex {
                    h: uv[0],
                    l: uv[1],
                    ..v
                };
                self.0.vertex(*corner, near);
            }
            let texture = q.texture.saturating_add(first_texture);
            let level = textures
                .get(texture as usize)
                .map_or(0, |t| t.level_for(texels_per_pixel(&corners, t, near)));
            self.0
                .extend([([base, base + 1, base + 2, base + 3], (texture, level))]);
        }
        self.0.bin(first);
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples, each with its texture from `textures` (a quad naming none is skipped).
    pub(crate) fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32, textures: &[&Texture]) {
        let Some(&first) = textures.first() else {
            return;
        };
        let mut sink = TexelSink {
            samples,
            width,
            y0: bounds.y0,
            level: first.level(0),
        };
        self.0.draw(bounds, near, &mut sink, |sink, (k, level)| {
            match textures.get(k as usize) {
                Some(&texture) => {
                    sink.level = texture.level(level);
                    Some(Faces::Both)
                }
                None => None,
            }
        });
    }
}

/// Texels of `texture` per pixel across the quad `corners` (its longer side's ratio, as GPUs
/// choose a level without anisotropic filtering): the texels its sides span over the pixels they
/// span on screen, from the corners' pixel positions. 0 (level 0) when a corner is at or behind
/// the near plane, where the quad is large on screen anyway.
fn texels_per_pixel(corners: &[ClipVertex; 4], texture: &Texture, near: f32) -> f32 {
    // A NaN depth counts as behind.
    if corners.iter().any(|c| c.w.is_nan() || c.w <= near) {
        return 0.0;
    }
    let px = corners.map(|c| [c.x / c.w, c.y / c.w]);
    let (tw, th) = (texture.width as f32, texture.height as f32);
    let mut most = 0.0f32;
    for i in 0..4 {
        let (a, b) = (i, (i + 1) % 4);
        let screen = ((px[b][0] - px[a][0]).powi(2) + (px[b][1] - px[a][1]).powi(2)).sqrt();
        let texels =
            (((corners[b].h - corners[a].h) * tw).powi(2) + ((corners[b].l - corners[a].l) * th).powi(2)).sqrt();
        if screen > 0.0 {
            most = most.max(texels / screen);
        }
    }
    most
}

/// The sample a drawn texel of colour `rgb` at depth `invw` leaves: its colour at full light —
/// twice it, so that rounding in `lw / invw` cannot dim it (the resolve clamps the light to 1).
#[inline(always)]
fn texel_sample(invw: f32, rgb: [u8; 3]) -> Sample {
    Sample {
        invw,
        hw: 0.0,
        lw: 2.0 * invw,
        surface: Surface::Colour(rgb),
    }
}

/// The depth test for textured triangles: the interpolated "height" and "light" are `u/w` and
/// `v/w`; a texel of alpha under one half is discarded.
struct TexelSink<'a> {
    samples: &'a mut [Sample],
    width: usize,
    y0: i32,
    level: Level<'a>,
}

impl Sink for TexelSink<'_> {
    #[inline(always)]
    fn pixel(&mut self, x: i32, y: i32, invw: f32, uw: f32, vw: f32) {
        let i = (y - self.y0) as usize * self.width + x as usize;
        let s = &mut self.samples[i];
        if invw <= s.invw {
            return;
        }
        let w = 1.0 / invw;
        let [r, g, b, a] = self.level.nearest(uw * w, vw * w);
        if a < 128 {
            return;
        }
        *s = texel_sample(invw, [r, g, b]);
    }

    /// A run's pixels each with its offset times the step (not stepped one addition at a time:
    /// the values the textured polygons were drawn with when an AVX2 path took eight pixels at
    /// once, kept to the bit).
    #[inline(always)]
    fn run(&mut self, y: i32, px0: i32, ks: Range<i32>, row: [f32; 3], step: [f32; 3]) {
        rasterise::each_in_run(self, y, px0, ks, row, step);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_weights_colour_by_alpha_and_averages_alpha() {
        // One opaque red texel and three transparent black ones: the mean is red, a quarter
        // covered (the black of empty texels does not darken it).
        let t = Texture::new(2, 2, vec![[255, 0, 0, 255], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]]).expect("texture");
        assert_eq!(t.levels(), 1);
        assert_eq!(t.nearest_in(1, 0.9, 0.9), [255, 0, 0, 64]);
        // Two opaque texels of different colours: their mean, opaque.
        let t = Texture::new(2, 1, vec![[200, 100, 0, 255], [100, 0, 50, 255]]).expect("texture");
        assert_eq!(t.nearest_in(1, 0.0, 0.0), [150, 50, 25, 255]);
        // Level 0 is the image; a level past the last reads the last.
        assert_eq!(t.nearest_in(0, 0.9, 0.0), [100, 0, 50, 255]);
        assert_eq!(t.nearest_in(9, 0.9, 0.0), [150, 50, 25, 255]);
    }

    #[test]
    fn lookups_clamp_to_the_edge_texels() {
        // A 3 × 2 image whose texels are numbered 0..6 in their red channel.
        let t = Texture::new(3, 2, (0..6).map(|i| [i, 0, 0, 255]).collect()).expect("texture");
        let red = |u: f32, v: f32| t.nearest(u, v)[0];
        // Inside: the texel holding (u·3, v·2).
        assert_eq!(red(0.5, 0.25), 1);
        assert_eq!(red(0.99, 0.99), 5);
        // Before the first texel, NaN and past the last: the edge texels.
        for (u, v, edge) in [
            (-0.5, 0.0, 0),
            (-1e30, -1e30, 0),
            (f32::NAN, f32::NAN, 0),
            (1.0, 1.0, 5),
            (7.0, 0.0, 2),
            (1e30, 1e30, 5),
            (f32::INFINITY, 0.0, 2),
            (f32::NEG_INFINITY, 1.0, 3),
        ] {
            assert_eq!(red(u, v), edge, "({u}, {v})");
        }
        // Sides past MAX_SIDE are refused.
        assert!(Texture::new(MAX_SIDE + 1, 1, vec![[0; 4]; MAX_SIDE as usize + 1]).is_none());
    }

    #[test]
    fn levels_halve_down_to_one_texel() {
        let t = Texture::new(5, 3, vec![[1, 2, 3, 255]; 15]).expect("texture");
        let sizes: Vec<(u32, u32)> = t.levels.iter().map(|l| (l.0, l.1)).collect();
        assert_eq!(sizes, [(3, 2), (2, 1), (1, 1)]);
        // A uniform image stays uniform at every level, edges included.
        assert!(t.levels.iter().all(|l| l.2.iter().all(|&x| x == [1, 2, 3, 255])));
        let t = Texture::new(64, 64, vec![[0; 4]; 64 * 64]).expect("texture");
        assert_eq!(t.levels(), 6);
    }

    #[test]
    fn a_quad_drawn_smaller_than_its_texels_reads_a_coarser_level() {
        let t = Texture::new(64, 64, vec![[0; 4]; 64 * 64]).expect("texture");
        // A square quad of `px` pixels at depth 2, the whole texture across it.
        let quad = |px: f32| {
            let corner = |x: f32, y: f32, u: f32, v: f32| ClipVertex {
                x: 2.0 * x,
                y: 2.0 * y,
                w: 2.0,
                h: u,
                l: v,
            };
            [
                corner(100.0, 100.0, 0.0, 0.0),
                corner(100.0 + px, 100.0, 1.0, 0.0),
                corner(100.0 + px, 100.0 + px, 1.0, 1.0),
                corner(100.0, 100.0 + px, 0.0, 1.0),
            ]
        };
        for (px, level) in [
            (128.0, 0),
            (64.0, 0),
            (33.0, 0),
            (32.0, 1),
            (16.0, 2),
            (9.0, 2),
            (1.0, 6),
            (0.1, 6),
        ] {
            let tpp = texels_per_pixel(&quad(px), &t, 0.1);
            assert!((tpp - 64.0 / px).abs() < 1e-3 * tpp, "{px} px: {tpp}");
            assert_eq!(t.level_for(tpp), level, "{px} px");
        }
        // A corner behind the near plane: level 0.
        let mut q = quad(4.0);
        q[2].w = 0.05;
        assert_eq!(texels_per_pixel(&q, &t, 0.1), 0.0);
    }
}
