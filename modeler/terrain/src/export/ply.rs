//! Stanford PLY, binary little-endian: one vertex element (`x y z nx ny nz` as floats, and
//! `red green blue` as bytes, sRGB, when the meshes have colours) and one face element (a byte
//! count, 3, and three `uint` indices). Several meshes go into one file, numbered on.

use std::io::Write;

use super::{ExportError, Mesh};

/// Linear RGB (0 to 1) to an 8-bit sRGB channel, as PLY readers show bytes.
fn srgb8(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// Writes `meshes` as one binary PLY; colours are written when every mesh has them.
pub fn write_ply(meshes: &[(&str, &Mesh)], mut out: impl Write) -> Result<(), ExportError> {
    let vertices: usize = meshes.iter().map(|(_, m)| m.positions.len()).sum();
    let faces: usize = meshes.iter().map(|(_, m)| m.indices.len() / 3).sum();
    let colors = meshes.iter().all(|(_, m)| m.colors.len() == m.positions.len());
    let total = u32::try_from(vertices).map_err(|_| ExportError::TooLarge(vertices as u64))?;
    let mut head =
        String::from("ply\nformat binary_little_endian 1.0\ncomment penmodel: X = x, Y = height, Z = y (metres)\n");
    for (name, _) in meshes {
        head.push_str(&format!("comment mesh {name}\n"));
    }
    head.push_str(&format!("element vertex {total}\n"));
    for p in ["x", "y", "z", "nx", "ny", "nz"] {
        head.push_str(&format!("property float {p}\n"));
    }
    if colors {
        for p in ["red", "green", "blue"] {
            head.push_str(&format!("property uchar {p}\n"));
        }
    }
    head.push_str(&format!(
        "element face {faces}\nproperty list uchar uint vertex_indices\nend_header\n"
    ));
    let mut out = std::io::BufWriter::new(&mut out);
    out.write_all(head.as_bytes())?;
    for (_, m) in meshes {
        for (i, p) in m.positions.iter().enumerate() {
            let n = m.normals.get(i).copied().unwrap_or([0.0, 1.0, 0.0]);
            for v in p.iter().chain(&n) {
                out.write_all(&v.to_le_bytes())?;
            }
            if colors {
                out.write_all(&m.colors[i].map(srgb8))?;
            }
        }
    }
    let mut base = 0u32;
    for (_, m) in meshes {
        for t in m.indices.chunks_exact(3) {
            out.write_all(&[3])?;
            for i in t {
                out.write_all(&(i + base).to_le_bytes())?;
            }
        }
        base += m.positions.len() as u32;
    }
    out.flush()?;
    Ok(())
}
