//! Rocks set on the ground: a field's rock meshes moved into the document's frame and stood on a
//! surface, as one mesh for the exports and the renderer.
//!
//! Every vertex keeps its height above the ground (0 for a cell's own vertices, eq. 3's `t_z`
//! for the added points) and takes the ground's height under it, so a rock follows the terrain
//! when the terrain changes and nothing else about it is recomputed.

use rayon::prelude::*;

use crate::export::Mesh;
use crate::heightmap::Heightmap;

use super::Scatter;

/// Where a field lies: field cell `(x, y)` is at `origin + (x, y)·cell_size` metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// The field image's corner `(0, 0)` in the document, metres.
    pub origin: [f64; 2],
    /// Metres per field cell (heights above the ground scale the same).
    pub cell_size: f64,
}

/// All rocks of `scatter` as one mesh in the exports' frame (`X = x`, `Y` up, `Z = y`, metres),
/// on the ground `ground(x, y)`; normals averaged over each vertex's triangles, by area.
pub fn mesh(scatter: &Scatter, at: Placement, ground: impl Fn(f64, f64) -> f64 + Sync) -> Mesh {
    // Each rock's vertices and triangles, on both cores; then one list.
    let parts: Vec<Mesh> = scatter
        .rocks
        .par_iter()
        .map(|rock| {
            let positions: Vec<[f32; 3]> = rock
                .mesh
                .vertices
                .iter()
                .map(|v| {
                    let (x, y) = (at.origin[0] + v[0] * at.cell_size, at.origin[1] + v[1] * at.cell_size);
                    [x as f32, (ground(x, y) + v[2] * at.cell_size) as f32, y as f32]
                })
                .collect();
            let indices: Vec<u32> = rock.mesh.triangles.iter().flatten().copied().collect();
            let normals = normals(&positions, &indices);
            Mesh {
                positions,
                normals,
                indices,
            }
        })
        .collect();
    let vertices: usize = parts.iter().map(|p| p.positions.len()).sum();
    let triangles: usize = parts.iter().map(|p| p.indices.len()).sum();
    let mut mesh = Mesh {
        positions: Vec::with_capacity(vertices),
        normals: Vec::with_capacity(vertices),
        indices: Vec::with_capacity(triangles),
    };
    for part in parts {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(part.positions);
        mesh.normals.extend(part.normals);
        mesh.indices.extend(part.indices.into_iter().map(|i| base + i));
    }
    mesh
}

/// The terrain's height at `(x, y)` metres, on the surface its mesh draws: heights at cell
/// centres, two triangles per square of four centres split along the diagonal from the upper
/// right to the lower left centre (as [`crate::export::Mesh`]); held flat beyond the outer
/// centres.
pub fn ground(map: &Heightmap) -> impl Fn(f64, f64) -> f64 + Sync + '_ {
    let (cols, rows, s) = (map.cols(), map.rows(), map.cell_size());
    let h = map.heights();
    move |x: f64, y: f64| {
        let fx = (x / s - 0.5).clamp(0.0, f64::from(cols - 1));
        let fy = (y / s - 0.5).clamp(0.0, f64::from(rows - 1));
        let (c, r) = (
            (fx as u32).min(cols.saturating_sub(2)),
            (fy as u32).min(rows.saturating_sub(2)),
        );
        let (u, v) = (fx - f64::from(c), fy - f64::from(r));
        let at = |c: u32, r: u32| f64::from(h[(r.min(rows - 1) * cols + c.min(cols - 1)) as usize]);
        let (a, b, d, e) = (at(c, r), at(c + 1, r), at(c, r + 1), at(c + 1, r + 1));
        if u + v <= 1.0 {
            a + u * (b - a) + v * (d - a)
        } else {
            e + (1.0 - u) * (d - e) + (1.0 - v) * (b - e)
        }
    }
}

/// Area-weighted vertex normals of a triangle list (counter-clockwise seen from +Y).
pub fn normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    let mut sum = vec![[0.0f64; 3]; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize].map(f64::from));
        let (u, v) = (
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for &i in t {
            let s = &mut sum[i as usize];
            s[0] += n[0];
            s[1] += n[1];
            s[2] += n[2];
        }
    }
    sum.into_iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 {
                [(n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32]
            } else {
                [0.0, 1.0, 0.0]
            }
        })
        .collect()
}
