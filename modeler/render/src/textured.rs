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

use super::binned::Binned;
use super::clip::ClipVertex;
use super::frame::Rgba;
use super::rasterise::{Bounds, Sample, Sink, Surface};
use super::transform::Affine;

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

/// One eye's projected quads: two triangles each, tagged with their texture's index.
#[derive(Debug, Default)]
pub struct Projected(Binned<u32>);

impl Projected {
    /// Forgets the last frame's quads, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the quads.
    pub fn clear(&mut self, bands: (usize, usize)) {
        self.0.clear(bands);
    }

    /// Projects `quads` for one eye (with the terrain's `affine` map and `cell_size`) and bins
    /// their triangles; their texture indices are offset by `first_texture`.
    pub fn add(&mut self, quads: &[Quad], first_texture: u32, affine: &Affine, cell_size: f64, near: f32) {
        let first = self.0.triangles();
        let s = cell_size as f32;
        for q in quads {
            let base = self.0.vertices();
            for (p, uv) in q.corners.iter().zip(&q.uv) {
                // u and v ride in the height and light slots: interpolated as u/w, v/w.
                let v = affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], 0.0);
                let v = ClipVertex {
                    h: uv[0],
                    l: uv[1],
                    ..v
                };
                self.0.vertex(v, near);
            }
            let texture = q.texture.saturating_add(first_texture);
            self.0.extend([
                ([base, base + 1, base + 2], texture),
                ([base, base + 2, base + 3], texture),
            ]);
        }
        self.0.bin(first);
    }

    /// How many quads were projected.
    pub fn quads(&self) -> usize {
        self.0.triangles() / 2
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples, each with its texture from `textures` (a quad naming none is skipped).
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32, textures: &[&Texture]) {
        let Some(&first) = textures.first() else {
            return;
        };
        let mut sink = TexelSink {
            samples,
            width,
            y0: bounds.y0,
            texture: first,
        };
        self.0
            .draw(bounds, near, &mut sink, |sink, k| match textures.get(k as usize) {
                Some(&texture) => {
                    sink.texture = texture;
                    true
                }
                None => false,
            });
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
