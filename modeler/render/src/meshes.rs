//! Placed meshes — rock fields, water, trees — drawn into the terrain's depth buffer.
//!
//! Each eye projects every mesh vertex once (clip space from the same affine map as the terrain,
//! so a rock's rim vertex and the ground under it land on the same pixel and depth) and lights
//! it by its normal (`ambient + (1 − ambient)·|n·L|` with the terrain's light: two-sided, since
//! leaves and the undersides of branches are seen from both sides); triangles are binned by the
//! bands of rows the tiles draw, so a tile looks only at the triangles that reach it. Triangles
//! are drawn from both windings (rocks are closed on top and open underneath, where the ground
//! is; leaves are single quads).
//!
//! What a won sample shows is its [`Paint`]: a whole mesh in one of the style's colours (rocks in
//! [`Style::rock_colour`], water in [`Style::water_colour`]), or per triangle the mean of the
//! mesh's own vertex colours ([`Mesh::colors`], linear RGB, turned to sRGB here). Flat per
//! triangle rather than interpolated per pixel: the depth buffer's sample keeps one colour and
//! two interpolated values (height and light), and a tree's triangles are each bark or leaf.

use penmodel_terrain::export::Mesh;

use super::binned::Binned;
use super::rasterise::{Bounds, DepthSink, Sample, Surface};
use super::scene::Style;
use super::transform::Affine;

/// How a mesh is coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Paint {
    /// Every triangle shows this surface (rocks, water).
    Whole(Surface),
    /// Each triangle in the mean of its vertices' own colours ([`Mesh::colors`]); a mesh
    /// without colours falls back to the rock colour.
    Own,
}

/// sRGB byte of linear intensity `i / (LINEAR_STEPS − 1)`: a table, so that colouring a tree's
/// 10⁵ triangles per frame costs no `powf`.
const LINEAR_STEPS: usize = 1024;

fn srgb_table() -> &'static [u8; LINEAR_STEPS] {
    static TABLE: std::sync::OnceLock<[u8; LINEAR_STEPS]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = i as f32 / (LINEAR_STEPS - 1) as f32;
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0).round().clamp(0.0, 255.0) as u8
        })
    })
}

/// Linear RGB (0 to 1) → sRGB bytes.
pub fn srgb(linear: [f32; 3]) -> [u8; 3] {
    let table = srgb_table();
    let last = (LINEAR_STEPS - 1) as f32;
    linear.map(|c| {
        let c = if c.is_finite() { c.clamp(0.0, 1.0) } else { 0.0 };
        table[(c * last + 0.5) as usize]
    })
}

/// One eye's projected meshes.
#[derive(Debug, Default)]
pub struct Projected(Binned<Surface>);

impl Projected {
    /// Forgets the last frame's meshes, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the meshes.
    pub fn clear(&mut self, bands: (usize, usize)) {
        self.0.clear(bands);
    }

    /// Projects `meshes` (the exports' frame: X, Y up, Z, metres) for one eye, painted `paint`,
    /// and bins their triangles. Meshes added later win ties of depth against earlier ones.
    pub fn add<'m>(
        &mut self,
        meshes: impl IntoIterator<Item = &'m Mesh>,
        paint: Paint,
        affine: &Affine,
        cell_size: f64,
        near: f32,
        style: &Style,
    ) {
        let light = super::light::world_light(style);
        let ambient = style.ambient.clamp(0.0, 1.0);
        let s = cell_size as f32;
        let first = self.0.triangles();
        for mesh in meshes {
            let n = mesh.positions.len().min(mesh.normals.len());
            let base = self.0.vertices_from(n, near, |i| {
                let (p, n) = (mesh.positions[i], mesh.normals[i]);
                let lambert = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]).abs();
                let l = ambient + (1.0 - ambient) * lambert;
                affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], l)
            });
            let coloured = paint == Paint::Own && mesh.colors.len() == mesh.positions.len();
            self.0.extend(mesh.indices.chunks_exact(3).map(|t| {
                let surface = match paint {
                    Paint::Whole(s) => s,
                    Paint::Own if coloured => {
                        let [a, b, c] = [0, 1, 2].map(|k| mesh.colors[t[k] as usize]);
                        let third = 1.0 / 3.0;
                        Surface::Colour(srgb([0, 1, 2].map(|i| (a[i] + b[i] + c[i]) * third)))
                    }
                    Paint::Own => Surface::Rock,
                };
                ([t[0] + base, t[1] + base, t[2] + base], surface)
            }));
        }
        self.0.bin(first);
    }

    /// How many triangles were added this frame.
    pub fn triangles(&self) -> usize {
        self.0.triangles()
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples.
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32) {
        let mut sink = DepthSink {
            samples,
            width,
            y0: bounds.y0,
            surface: Surface::Rock,
        };
        self.0.draw(bounds, near, &mut sink, |sink, surface| {
            sink.surface = surface;
            true
        });
    }
}
