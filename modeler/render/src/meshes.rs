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

use super::clip::{self, ClipVertex};
use super::rasterise::{self, Bounds, DepthSink, Sample, Surface, Vtx};
use super::scene::Style;
use super::transform::{self, Affine};

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
pub struct Projected {
    clip: Vec<ClipVertex>,
    screen: Vec<Vtx>,
    /// Whether each vertex is in front of the near plane.
    direct: Vec<bool>,
    /// Triangles (indices into `clip`) and what they show, all meshes together.
    triangles: Vec<([u32; 3], Surface)>,
    /// Triangle indices per band of `band_rows` rows.
    bins: Vec<Vec<u32>>,
    band_rows: usize,
    frame_height: usize,
}

impl Projected {
    /// Forgets the last frame's meshes, for a frame `frame_height` rows tall drawn in bands of
    /// `band_rows` rows; then [`Projected::add`] the meshes.
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
        let light = super::shade::world_light(style);
        let ambient = style.ambient.clamp(0.0, 1.0);
        let s = cell_size as f32;
        let first = self.triangles.len();
        for mesh in meshes {
            let base = self.clip.len() as u32;
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let lambert = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]).abs();
                let l = ambient + (1.0 - ambient) * lambert;
                let v = affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], l);
                self.direct.push(v.inside(near));
                self.screen.push(transform::project(&v));
                self.clip.push(v);
            }
            let coloured = paint == Paint::Own && mesh.colors.len() == mesh.positions.len();
            self.triangles.extend(mesh.indices.chunks_exact(3).map(|t| {
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
        self.bin(first);
    }

    /// Bins the triangles from `first` on.
    fn bin(&mut self, first: usize) {
        let bands = self.bins.len();
        let one = (1 << rasterise::SUBPIXEL) as f32;
        for (i, (t, _)) in self.triangles.iter().enumerate().skip(first) {
            let (lo, hi) = if t.iter().all(|&k| self.direct[k as usize]) {
                let ys = t.map(|k| self.screen[k as usize].y as f32 / one);
                (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]))
            } else if t.iter().any(|&k| self.direct[k as usize]) {
                // Crosses the near plane: every band may see it.
                (0.0, self.frame_height as f32)
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

    /// How many triangles were added this frame.
    pub fn triangles(&self) -> usize {
        self.triangles.len()
    }

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples.
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32) {
        let Some(bin) = self.bins.get(bounds.y0.max(0) as usize / self.band_rows.max(1)) else {
            return;
        };
        let mut sink = DepthSink {
            samples,
            width,
            y0: bounds.y0,
            surface: Surface::Rock,
        };
        for &i in bin {
            let (t, surface) = self.triangles[i as usize];
            sink.surface = surface;
            if t.iter().all(|&k| self.direct[k as usize]) {
                let [a, b, c] = t.map(|k| &self.screen[k as usize]);
                // Both windings: the rasteriser fills one.
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
