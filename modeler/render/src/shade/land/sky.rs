//! The shadows and sky light: issue 12's horizon sweeps on a coarse grid of blocks, kept between
//! remakes and interpolated per vertex.

use rayon::prelude::*;

use super::Rect;
use crate::scene::Style;
use crate::scene::light;
use penmodel_terrain::ridge::sun::{self, Field};

/// Width of the sun's penumbra at a horizon, radians (the sun's disc is 0.5°; a coarse light grid
/// blurs more).
pub(super) const PENUMBRA: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// The shadows and sky light on the coarse grid ([`Style::light_cells`]), kept between remakes:
/// a change recomputes the blocks it touches, sweeps the coarse grid again, and relights the
/// vertices where the heights or these maps changed.
#[derive(Debug, Default)]
pub(super) struct SkyLight {
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

/// Block `(i, j)` of `f × f` cells of the `cols × rows` heights `h`, averaged and × `scale`
/// (non-finite heights count as 0: their triangles are holes anyway).
#[inline]
pub(super) fn block(h: &[f32], (cols, rows): (usize, usize), f: usize, (i, j): (usize, usize), scale: f32) -> f32 {
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
pub(super) fn sun_angles(style: &Style) -> (f64, f64) {
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
    pub(super) fn relight(
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
pub(super) fn sweeps(z: &[f32], (cc, rr): (usize, usize), cell: f64, style: &Style) -> (Vec<f32>, Vec<f32>) {
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
pub(super) fn footprint(b: Rect, f: usize, (cc, rr): (usize, usize), (cols, rows): (usize, usize)) -> Rect {
    let lo = |i: usize| if i == 0 { 0 } else { ((i - 1) * f).saturating_sub(1) };
    let hi = |i: usize, n: usize, len: usize| if i + 1 >= n { len } else { ((i + 2) * f + 1).min(len) };
    Rect {
        c0: lo(b.c0),
        c1: hi(b.c1 - 1, cc, cols),
        r0: lo(b.r0),
        r1: hi(b.r1 - 1, rr, rows),
    }
}
