//! Wavefront OBJ: `v` positions, `vn` normals, `f v//vn` triangles (1-based), one `o` object per
//! mesh (the terrain, then each rock field's rocks, then the trees). A mesh with colours writes
//! them after each position, `v x y z r g b` (linear RGB, 0 to 1).

use std::io::Write;

use super::{ExportError, Mesh};
use crate::heightmap::Heightmap;

/// Writes the heightmap's mesh as OBJ text.
pub fn write_obj(map: &Heightmap, out: impl Write) -> Result<(), ExportError> {
    write_obj_with(map, &[], out)
}

/// Writes the heightmap's mesh and `placed` meshes (name, mesh; in the same frame) as OBJ text.
pub fn write_obj_with(map: &Heightmap, placed: &[(String, Mesh)], out: impl Write) -> Result<(), ExportError> {
    let mesh = Mesh::of(map)?;
    let mut out = std::io::BufWriter::new(out);
    writeln!(
        out,
        "# penmodel terrain: {} x {} cells of {} m; X = x, Y = height, Z = y (metres)",
        map.cols(),
        map.rows(),
        map.cell_size()
    )?;
    let all = std::iter::once(("terrain", &mesh)).chain(placed.iter().map(|(n, m)| (n.as_str(), m)));
    write_meshes(all, &mut out)?;
    out.flush()?;
    Ok(())
}

/// Writes `meshes` as OBJ objects, numbering vertices on from one object to the next.
pub fn write_meshes<'a>(
    meshes: impl Iterator<Item = (&'a str, &'a Mesh)>,
    out: &mut impl Write,
) -> Result<(), ExportError> {
    let mut base = 1u64;
    for (name, mesh) in meshes {
        writeln!(out, "o {name}")?;
        if mesh.colors.len() == mesh.positions.len() {
            // Vertex colours after the position (the extension Blender, MeshLab and others read).
            for ([x, y, z], [r, g, b]) in mesh.positions.iter().zip(&mesh.colors) {
                writeln!(out, "v {x} {y} {z} {r} {g} {b}")?;
            }
        } else {
            for [x, y, z] in &mesh.positions {
                writeln!(out, "v {x} {y} {z}")?;
            }
        }
        for [x, y, z] in &mesh.normals {
            writeln!(out, "vn {x} {y} {z}")?;
        }
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| u64::from(i) + base);
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        base += mesh.positions.len() as u64;
    }
    Ok(())
}
