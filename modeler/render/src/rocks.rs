//! Placed meshes — the rock fields — drawn into the terrain's depth buffer in their own colour.
//!
//! Each eye projects every mesh vertex once (clip space from the same affine map as the terrain,
//! so a rock's rim vertex and the ground under it land on the same pixel and depth) and lights
//! it by its normal (Lambert with the terrain's light and ambient); triangles are binned by the
//! bands of rows the tiles draw, so a tile looks only at the triangles that reach it. A sample a
//! rock wins is marked, and the resolve step colours it with [`Style::rock_colour`] × light
//! instead of the height ramp. Triangles are drawn from both sides (the meshes are closed on
//! top, open only underneath, where the ground is).

use penmodel_terrain::export::Mesh;

use super::clip::{self, ClipVertex};
use super::rasterise::{self, Bounds, DepthSink, Sample, Surface, Vtx};
use super::scene::Style;
use super::transform::{self, Affine};

/// One eye's projected meshes.
#[derive(Debug, Default)]
pub struct Projected {
    clip: Vec<ClipVertex>,
    screen: Vec<Vtx>,
    /// Whether each vertex is in front of the near plane.
    direct: Vec<bool>,
    /// Triangles (indices into `clip`), all meshes together.
    triangles: Vec<[u32; 3]>,
    /// Triangle indices per band of `band_rows` rows.
    bins: Vec<Vec<u32>>,
    band_rows: usize,
}

impl Projected {
    /// Projects `meshes` (the exports' frame: X, Y up, Z, metres) for one eye.
    pub fn project(
        &mut self,
        meshes: &[(String, Mesh)],
        affine: &Affine,
        cell_size: f64,
        near: f32,
        style: &Style,
        (frame_height, band_rows): (usize, usize),
    ) {
        self.clip.clear();
        self.screen.clear();
        self.direct.clear();
        self.triangles.clear();
        self.band_rows = band_rows.max(1);
        let bands = frame_height.div_ceil(self.band_rows);
        self.bins.resize_with(bands, Vec::new);
        self.bins.iter_mut().for_each(Vec::clear);
        if meshes.is_empty() {
            return;
        }
        let light = super::shade::world_light(style);
        let ambient = style.ambient.clamp(0.0, 1.0);
        let s = cell_size as f32;
        for (_, mesh) in meshes {
            let base = self.clip.len() as u32;
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let lambert = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]).abs();
                let l = ambient + (1.0 - ambient) * lambert;
                let v = affine.clip_point(p[0] / s - 0.5, p[2] / s - 0.5, p[1], l);
                self.direct.push(v.inside(near));
                self.screen.push(transform::project(&v));
                self.clip.push(v);
            }
            self.triangles.extend(
                mesh.indices
                    .chunks_exact(3)
                    .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
            );
        }
        let one = (1 << rasterise::SUBPIXEL) as f32;
        for (i, t) in self.triangles.iter().enumerate() {
            let (lo, hi) = if t.iter().all(|&k| self.direct[k as usize]) {
                let ys = t.map(|k| self.screen[k as usize].y as f32 / one);
                (ys[0].min(ys[1]).min(ys[2]), ys[0].max(ys[1]).max(ys[2]))
            } else if t.iter().any(|&k| self.direct[k as usize]) {
                // Crosses the near plane: every band may see it.
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

    /// Draws the triangles that reach the tile `bounds` (its first row starts a band) into its
    /// samples.
    pub fn draw(&self, bounds: &Bounds, samples: &mut [Sample], width: usize, near: f32, surface: Surface) {
        let Some(bin) = self.bins.get(bounds.y0.max(0) as usize / self.band_rows.max(1)) else {
            return;
        };
        let mut sink = DepthSink {
            samples,
            width,
            y0: bounds.y0,
            surface,
        };
        for &i in bin {
            let t = self.triangles[i as usize];
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
