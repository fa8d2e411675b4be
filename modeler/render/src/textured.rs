//! Textured, alpha-tested polygons: quads with an RGBA texture, drawn into the terrain's depth
//! buffer (the simplified shapes of trees, [`crate::impostor`]).
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
//! - Texels are lit already (rendered with the light, [`crate::impostor::bake`]): a drawn texel
//!   is [`Surface::Colour`] at full light.
//! - Quads are drawn from both windings, like the meshes; triangles are binned by bands of rows
//!   as the meshes are.

use super::clip::{self, ClipVertex};
use super::frame::Rgba;
use super::rasterise::{self, Bounds, Sample, Sink, Surface, Vtx};
use super::transform::{self, Affine};

/// An RGBA image, row 0 at the top.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Texture {
    width: u32,
    height: u32,
    texels: Vec<Rgba>,
}

impl Texture {
    /// A texture of `width × height` texels, row-major from the top; `None` unless the sizes
    /// agree and neither side is zero.
    pub fn new(width: u32, height: u32, texels: Vec<Rgba>) -> Option<Texture> {
        (width > 0 && height > 0 && texels.len() == width as usize * height as usize).then_some(Texture {
            width,
            height,
            texels,
        })
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
        let x = ((u * self.width as f32) as i32).clamp(0, self.width as i32 - 1);
        let y = ((v * self.height as f32) as i32).clamp(0, self.height as i32 - 1);
        self.texels[y as usize * self.width as usize + x as usize]
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

/// One eye's projected quads.
#[derive(Debug, Default)]
pub struct Projected {
    clip: Vec<ClipVertex>,
    screen: Vec<Vtx>,
    direct: Vec<bool>,
    /// Triangles (indices into `clip`) and their texture.
    triangles: Vec<([u32; 3], u32)>,
    bins: Vec<Vec<u32>>,
    band_rows: usize,
    frame_height: usize,
}

impl Projected {
    /// Forgets the last frame's quads, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the quads.
    pub fn clear(&mut self, (frame_height, band_rows): (usize, usize)) {
        self.clip.clear();
        self.screen.clear();
        self.direct.clear();
        self.triangles.clear();
        self.band_rows = band_rows.max(1);
        self.frame_height = frame_height;
        let bands = frame_height.div_ceil(self.band_rows);
        self.bins.resize_with(bands, Vec::new);
        self.bins.iter_mut().for_each(Vec::clear);
    }

    /// Projects `quads` for one eye (with the terrain's `affine` map and `cell_size`) and bins
    /// their triangles; their texture indices are offset by `first_texture`.
    pub fn add(&mut self, quads: &[Quad], first_texture: u32, affine: &Affine, cell_size: f64, near: f32) {
        let first = self.triangles.len();
        let s = cell_size as f32;
        for q in quads {
            let base = self.clip.len() as u32;
            for (p, uv) in q.corners.iter().zip(&q.uv) {
                // u and v ride in the height and light slots: interpolated as u/w, v/w.
                let v = affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], 0.0);
                let v = ClipVertex {
                    h: uv[0],
                    l: uv[1],
                    ..v
                };
                self.direct.push(v.inside(near));
                self.screen.push(transform::project(&v));
                self.clip.push(v);
            }
            let texture = q.texture.saturating_add(first_texture);
            self.triangles.push(([base, base + 1, base + 2], texture));
            self.triangles.push(([base, base + 2, base + 3], texture));
        }
        let (bands, frame_height) = (self.bins.len(), self.frame_height);
        let one = (1 << rasterise::SUBPIXEL) as f32;
        for (i, (t, _)) in self.triangles.iter().enumerate().skip(first) {
            let (lo, hi) = if t.iter().all(|&k| self.direct[k as usize]) {
                let ys = t.map(|k| self.screen[k as usize].y as f32 / one);
                (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]))
            } else if t.iter().any(|&k| self.direct[k as usize]) {
                (0.0, frame_height as f32)
            } else {
                continue;
            };
            let first = (lo.max(0.0) as usize) / self.band_rows;
            let last = ((hi.max(0.0) as usize) / self.band_rows).min(bands.saturating_sub(1));
            for bin in self.bins.iter_mut().take(last + 1).skip(first) {
                bin.push(i as u32);
            }
        }
    }

    /// How many quads were projected.
    pub fn quads(&self) -> usize {
        self.triangles.len() / 2
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples, each with its texture from `textures` (a quad naming none is skipped).
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32, textures: &[&Texture]) {
        let Some(bin) = self.bins.get(bounds.y0.max(0) as usize / self.band_rows.max(1)) else {
            return;
        };
        for &i in bin {
            let (t, k) = self.triangles[i as usize];
            let Some(&texture) = textures.get(k as usize) else {
                continue;
            };
            let mut sink = TexelSink {
                samples: &mut *samples,
                width,
                y0: bounds.y0,
                texture,
            };
            if t.iter().all(|&k| self.direct[k as usize]) {
                let [a, b, c] = t.map(|k| &self.screen[k as usize]);
                rasterise::triangle(a, b, c, bounds, &mut sink);
                rasterise::triangle(a, c, b, bounds, &mut sink);
            } else {
                let poly = clip::triangle(t.map(|k| self.clip[k as usize]), near);
                if poly.len < 3 {
                    continue;
                }
                let v: Vec<Vtx> = poly.vertices[..poly.len].iter().map(transform::project).collect();
                for k in 1..poly.len - 1 {
                    rasterise::triangle(&v[0], &v[k], &v[k + 1], bounds, &mut sink);
                    rasterise::triangle(&v[0], &v[k + 1], &v[k], bounds, &mut sink);
                }
            }
        }
    }
}

/// The depth test for textured triangles: the interpolated "height" and "light" are `u/w` and
/// `v/w`; a texel of alpha under one half is discarded.
struct TexelSink<'a> {
    samples: &'a mut [Sample],
    width: usize,
    y0: i32,
    texture: &'a Texture,
}

impl Sink for TexelSink<'_> {
    #[inline]
    fn pixel(&mut self, x: i32, y: i32, invw: f32, uw: f32, vw: f32) {
        let i = (y - self.y0) as usize * self.width + x as usize;
        let s = &mut self.samples[i];
        if invw <= s.invw {
            return;
        }
        let w = 1.0 / invw;
        let [r, g, b, a] = self.texture.nearest(uw * w, vw * w);
        if a < 128 {
            return;
        }
        *s = Sample {
            invw,
            hw: 0.0,
            // Full light: twice it, so that rounding in `lw / invw` cannot dim it (the resolve
            // clamps the light to 1).
            lw: 2.0 * invw,
            surface: Surface::Colour([r, g, b]),
        };
    }
}
