//! Rocks set on the ground: a field's rock meshes moved into the document's frame and stood on a
//! surface, as one mesh for the exports and the renderer.
//!
//! Every vertex keeps its height above the ground (0 for a cell's own vertices, eq. 3's `t_z`
//! for the added points) and takes the ground's height under it, so a rock follows the terrain
//! when the terrain changes and nothing else about it is recomputed.

use crate::export::Mesh;

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
pub fn mesh(scatter: &Scatter, at: Placement, ground: impl Fn(f64, f64) -> f64) -> Mesh {
    let vertices: usize = scatter.rocks.iter().map(|r| r.mesh.vertices.len()).sum();
    let triangles: usize = scatter.rocks.iter().map(|r| r.mesh.triangles.len()).sum();
    let mut positions = Vec::with_capacity(vertices);
    let mut indices = Vec::with_capacity(triangles * 3);
    for rock in &scatter.rocks {
        let base = positions.len() as u32;
        for v in &rock.mesh.vertices {
            let (x, y) = (at.origin[0] + v[0] * at.cell_size, at.origin[1] + v[1] * at.cell_size);
            positions.push([x as f32, (ground(x, y) + v[2] * at.cell_size) as f32, y as f32]);
        }
        for t in &rock.mesh.triangles {
            indices.extend(t.iter().map(|i| base + i));
        }
    }
    let normals = normals(&positions, &indices);
    Mesh {
        positions,
        normals,
        indices,
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
