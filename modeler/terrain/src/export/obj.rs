//! Wavefront OBJ: `v` positions, `vn` normals, `f v//vn` triangles (1-based).

use std::io::Write;

use super::{ExportError, Mesh};
use crate::heightmap::Heightmap;

/// Writes the heightmap's mesh as OBJ text.
pub fn write_obj(map: &Heightmap, out: impl Write) -> Result<(), ExportError> {
    let mesh = Mesh::of(map)?;
    let mut out = std::io::BufWriter::new(out);
    writeln!(
        out,
        "# penmodel terrain: {} x {} cells of {} m; X = x, Y = height, Z = y (metres)",
        map.cols(),
        map.rows(),
        map.cell_size()
    )?;
    writeln!(out, "o terrain")?;
    for [x, y, z] in &mesh.positions {
        writeln!(out, "v {x} {y} {z}")?;
    }
    for [x, y, z] in &mesh.normals {
        writeln!(out, "vn {x} {y} {z}")?;
    }
    for t in mesh.indices.chunks_exact(3) {
        let (a, b, c) = (t[0] + 1, t[1] + 1, t[2] + 1);
        writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
    }
    out.flush()?;
    Ok(())
}
