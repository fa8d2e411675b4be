//! Light per vertex (Gouraud): the normal from central differences of the heights (with the
//! vertical scale), `light = ambient + (1 − ambient)·max(0, n·L)` with `L` fixed to the terrain,
//! so tilting the ground or moving the eye does not change it; computed once per frame for both
//! eyes. The land look gives its own light per cell instead ([`crate::shade::land`]).

use rayon::prelude::*;

use super::Style;
use penmodel_terrain::Heightmap;

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
/// [`Scene::light_map`](super::Scene::light_map)) the light is `ambient + (1 − ambient)·given`
/// instead of Lambert's.
pub(crate) fn vertex_light(
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

/// The light of a surface with unit normal `n` lit from both sides: `ambient + (1 − ambient)·|n·L|`
/// for the world light `light` ([`world_light`]); meshes (rocks, water, trees) and their simplified
/// shapes.
#[inline]
pub(crate) fn two_sided(n: [f32; 3], light: [f32; 3], ambient: f32) -> f32 {
    let lambert = (n[0] * light[0] + n[1] * light[1] + n[2] * light[2]).abs();
    ambient + (1.0 - ambient) * lambert
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
