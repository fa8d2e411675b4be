//! The triangle mesh of a heightmap, shared by the OBJ and glTF writers.

use super::ExportError;
use crate::heightmap::Heightmap;

/// Vertices at the cell centres (Y up), normals, and triangles as vertex indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// `[X, Y, Z]` = `[x, height, y]` per cell, row-major.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per vertex.
    pub normals: Vec<[f32; 3]>,
    /// Three vertex indices per triangle, counter-clockwise seen from +Y.
    pub indices: Vec<u32>,
    /// Linear RGB (0 to 1) per vertex, or empty: the mesh has no colours of its own (the
    /// terrain, rocks) and the renderer and exports use theirs. Trees colour bark and leaves
    /// (`crate::trees`).
    pub colors: Vec<[f32; 3]>,
}

impl Mesh {
    /// The mesh of `map`; it needs at least 2 × 2 cells.
    pub fn of(map: &Heightmap) -> Result<Mesh, ExportError> {
        let (cols, rows) = (map.cols(), map.rows());
        if cols < 2 || rows < 2 {
            return Err(ExportError::TooSmallForMesh { cols, rows });
        }
        super::check_finite(map)?;
        let s = map.cell_size();
        let h = |c: u32, r: u32| f64::from(map.get(c, r));
        let mut positions = Vec::with_capacity(map.heights().len());
        let mut normals = Vec::with_capacity(map.heights().len());
        for r in 0..rows {
            for c in 0..cols {
                positions.push([
                    ((f64::from(c) + 0.5) * s) as f32,
                    map.get(c, r),
                    ((f64::from(r) + 0.5) * s) as f32,
                ]);
                // Central differences, one-sided at the edges.
                let (c0, c1) = (c.saturating_sub(1), (c + 1).min(cols - 1));
                let (r0, r1) = (r.saturating_sub(1), (r + 1).min(rows - 1));
                let dx = (h(c1, r) - h(c0, r)) / (f64::from(c1 - c0) * s);
                let dz = (h(c, r1) - h(c, r0)) / (f64::from(r1 - r0) * s);
                let len = (dx * dx + 1.0 + dz * dz).sqrt();
                normals.push([(-dx / len) as f32, (1.0 / len) as f32, (-dz / len) as f32]);
            }
        }
        let mut indices = Vec::with_capacity((cols as usize - 1) * (rows as usize - 1) * 6);
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let a = r * cols + c;
                let (b, d, e) = (a + 1, a + cols, a + cols + 1);
                indices.extend_from_slice(&[a, d, b, b, d, e]);
            }
        }
        Ok(Mesh {
            positions,
            normals,
            indices,
            colors: Vec::new(),
        })
    }
}
