//! A rock field's level of detail: a rock too small on screen to show its facets is drawn as one
//! quad over its footprint.
//!
//! A field (seed 001) is one mesh of thousands of rocks, about 14 triangles each. Seen from the
//! tracked head at 640 × 360 most of them are under a pixel, and projecting, binning and setting
//! up their 10⁵ triangles took about a third of the view's CPU (issue 16: the view's drawing is
//! what keeps the head's latency over 20 ms). The rocks are runs of the mesh that share nothing
//! ([`parts`]; `penmodel_terrain::rocks::place::Flat` lays a field out rock by rock), so each can
//! be judged on its own: one whose bounding sphere projects within the scene's level-of-detail
//! error (`Scene::terrain_lod`, pixels) of its centre is replaced by its footprint's box, shrunk
//! to the area of the ellipse in it (a rock is a rounded Voronoi cell), at the rock's mean height
//! and lit by its mean normal: 4 vertices and 2 triangles. Both shapes lie inside that circle on
//! screen, so nothing the quad draws is further than twice the error from the rock.

use std::ops::Range;

use rayon::prelude::*;

use penmodel_terrain::export::Mesh;

use crate::raster::clip::ClipVertex;
use crate::raster::transform::Affine;

/// A run of a mesh's vertices and of its triangles that use only them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Part {
    /// Vertex indices.
    pub vertices: Range<usize>,
    /// Triangle indices (three mesh indices each).
    pub triangles: Range<usize>,
}

/// The mesh's parts: the runs of vertices no triangle spans the boundary of, each with the
/// triangles whose vertices it holds. `None` when those triangles are not consecutive in the mesh
/// (a part's triangles come after a later part's), or an index is past the mesh's `vertices`:
/// the mesh is then drawn whole.
pub(crate) fn parts(indices: &[u32], vertices: usize) -> Option<Vec<Part>> {
    // `depth[v]`: how many triangles span from below v to v or above; 0 starts a run at v.
    let mut depth = vec![0i32; vertices + 1];
    for tri in indices.chunks_exact(3) {
        let min = tri.iter().copied().min()? as usize;
        let max = tri.iter().copied().max()? as usize;
        if max >= vertices {
            return None;
        }
        depth[min + 1] += 1;
        depth[max + 1] -= 1;
    }
    let mut sum = 0;
    for d in depth.iter_mut() {
        sum += *d;
        *d = sum;
    }
    // The run holding vertex v starts at the last u ≤ v with depth 0 and ends before the next.
    let run_end = |start: usize| (start + 1..vertices).find(|&v| depth[v] == 0).unwrap_or(vertices);
    let mut parts: Vec<Part> = Vec::new();
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let min = tri.iter().copied().min()? as usize;
        match parts.last_mut() {
            Some(p) if p.vertices.contains(&min) => p.triangles.end = t + 1,
            Some(p) if min < p.vertices.start => return None,
            _ => {
                let start = (0..=min).rev().find(|&v| depth[v] == 0).unwrap_or(0);
                if parts.last().is_some_and(|p| start < p.vertices.end) {
                    return None;
                }
                parts.push(Part {
                    vertices: start..run_end(start),
                    triangles: t..t + 1,
                });
            }
        }
    }
    Some(parts)
}

/// How a part is drawn for one eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Choice {
    /// Every triangle.
    Whole,
    /// The footprint quad's four corners, in order around it.
    Quad([ClipVertex; 4]),
}

/// The clip coordinates' change per metre along the exports' X, Y (up) and Z: the affine's
/// columns, by differences (its own are the grid's, per cell).
fn gradients(affine: &Affine, cell_size: f32) -> [[f32; 3]; 3] {
    let at = |c: f32, r: f32, h: f32| {
        let v = affine.clip_point(c, r, h, 0.0);
        [v.x, v.y, v.w]
    };
    let o = at(0.0, 0.0, 0.0);
    let (dc, dr, dh) = (at(1.0, 0.0, 0.0), at(0.0, 1.0, 0.0), at(0.0, 0.0, 1.0));
    [0, 1, 2].map(|i| [(dc[i] - o[i]) / cell_size, dh[i] - o[i], (dr[i] - o[i]) / cell_size])
}

fn norm(v: [f32; 3]) -> f32 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// What each of `parts` of `mesh` is drawn as, for an eye whose clip coordinates are `affine`'s
/// (grid cells of `cell_size` metres), whose near plane is at depth `near`, lit from `light`
/// with `ambient`: a quad when its bounding sphere projects within `pixels` of its centre and
/// lies wholly in front of the near plane. The choices replace what `out` held, one per part.
#[allow(clippy::too_many_arguments)] // an eye's projection, its light and the list kept between frames.
pub(crate) fn choose(
    mesh: &Mesh,
    parts: &[Part],
    affine: &Affine,
    cell_size: f32,
    near: f32,
    pixels: f32,
    (light, ambient): ([f32; 3], f32),
    out: &mut Vec<Choice>,
) {
    let [gx, gy, gw] = gradients(affine, cell_size);
    let gw_norm = norm(gw);
    let s = cell_size;
    let choose = |part: &Part| {
        let positions = &mesh.positions[part.vertices.clone()];
        let normals = &mesh.normals[part.vertices.clone()];
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let (mut mean_y, mut n) = (0.0f32, [0.0f32; 3]);
        for (p, q) in positions.iter().zip(normals) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
                n[k] += q[k];
            }
            mean_y += p[1];
        }
        mean_y /= positions.len().max(1) as f32;
        let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let radius = 0.5 * norm([0, 1, 2].map(|k| hi[k] - lo[k]));
        let c = affine.clip_point(centre[0] / s - 0.5, centre[2] / s - 0.5, centre[1], 0.0);
        // The sphere's nearest depth, and the most a point of it moves from the centre on screen:
        // δ(X/w) = (∇X − (X/w)·∇w)·δ / (w + ∇w·δ), for |δ| ≤ radius.
        let w_min = c.w - radius * gw_norm;
        if w_min.is_nan() || w_min <= near || !radius.is_finite() {
            return Choice::Whole;
        }
        let (x, y) = (c.x / c.w, c.y / c.w);
        let across = |g: [f32; 3], at: f32| norm([0, 1, 2].map(|k| g[k] - at * gw[k]));
        let spread = radius * across(gx, x).max(across(gy, y)) / w_min;
        // A spread that is not a number (a degenerate affine) keeps the rock whole too.
        if spread.is_nan() || spread > pixels {
            return Choice::Whole;
        }
        let len = norm(n);
        let n = if len > 0.0 { n.map(|v| v / len) } else { [0.0, 1.0, 0.0] };
        let l = super::light::two_sided(n, light, ambient);
        // The ellipse inscribed in the box has π/4 of its area: each side by √(π/4).
        let k = 0.5 * (std::f32::consts::PI / 4.0).sqrt();
        let (hx, hz) = (k * (hi[0] - lo[0]), k * (hi[2] - lo[2]));
        let corner =
            |dx: f32, dz: f32| affine.clip_point((centre[0] + dx) / s - 0.5, (centre[2] + dz) / s - 0.5, mean_y, l);
        Choice::Quad([corner(-hx, -hz), corner(hx, -hz), corner(hx, hz), corner(-hx, hz)])
    };
    out.clear();
    out.par_extend(parts.par_iter().with_min_len(512).map(choose));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separate_runs_are_parts_and_shared_vertices_are_not() {
        // Two triangles on 0..4, then two on 4..7.
        let two = [0, 1, 2, 2, 3, 0, 4, 5, 6, 6, 5, 4];
        assert_eq!(
            parts(&two, 7),
            Some(vec![
                Part {
                    vertices: 0..4,
                    triangles: 0..2
                },
                Part {
                    vertices: 4..7,
                    triangles: 2..4
                },
            ])
        );
        // A later triangle joins vertices 1 and 4: one part, though not in the triangles' order.
        assert_eq!(
            parts(&[0, 1, 2, 3, 4, 5, 5, 1, 4], 6),
            Some(vec![Part {
                vertices: 0..6,
                triangles: 0..3
            }])
        );
        // The first part's triangles resume after the second's: not consecutive.
        assert_eq!(parts(&[0, 1, 2, 3, 4, 5, 0, 2, 1], 6), None);
        // An index past the vertices.
        assert_eq!(parts(&[0, 1, 2, 3, 4, 9], 6), None);
        // Triangles of one rock that share no vertex with the ones before it yet: one part.
        assert_eq!(parts(&[0, 1, 2, 4, 5, 6, 3, 4, 2], 7).map(|p| p.len()), Some(1));
        // A vertex no triangle uses is in no part.
        assert_eq!(
            parts(&[0, 1, 2, 4, 5, 6], 7),
            Some(vec![
                Part {
                    vertices: 0..3,
                    triangles: 0..1
                },
                Part {
                    vertices: 4..7,
                    triangles: 1..2
                },
            ])
        );
        assert_eq!(parts(&[], 0), Some(Vec::new()));
    }
}
