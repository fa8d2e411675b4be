//! Binary glTF 2.0 (`.glb`), written directly: a 12-byte header (`glTF`, version 2, total
//! length), a JSON chunk (the scene: one node per mesh, each one triangle primitive with POSITION,
//! NORMAL, COLOR_0 when the mesh has colours, and 32-bit indices) padded with spaces to 4 bytes,
//! and a BIN chunk (positions, normals, colours, indices, each 4-byte aligned).

use std::io::Write;

use serde_json::json;

use super::{ExportError, Mesh};
use crate::heightmap::Heightmap;

const MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;

fn pad(bytes: &mut Vec<u8>, with: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(with);
    }
}

/// Writes the heightmap's mesh as binary glTF.
pub fn write_glb(map: &Heightmap, out: impl Write) -> Result<(), ExportError> {
    write_glb_with(map, &[], out)
}

/// Writes the heightmap's mesh and `placed` meshes (name, mesh; in the same frame) as binary
/// glTF: one node and mesh each, the terrain first.
pub fn write_glb_with(map: &Heightmap, placed: &[(String, Mesh)], out: impl Write) -> Result<(), ExportError> {
    let terrain = Mesh::of(map)?;
    let all: Vec<(&str, &Mesh)> = std::iter::once(("terrain", &terrain))
        .chain(placed.iter().map(|(n, m)| (n.as_str(), m)))
        .collect();
    write_glb_meshes(&all, out)
}

/// Writes `meshes` (name, mesh) as binary glTF, one node each; meshes without triangles are left
/// out (glTF has no empty accessors).
pub fn write_glb_meshes(meshes: &[(&str, &Mesh)], mut out: impl Write) -> Result<(), ExportError> {
    let all: Vec<&(&str, &Mesh)> = meshes.iter().filter(|(_, m)| !m.indices.is_empty()).collect();
    let mut bin = Vec::new();
    let (mut nodes, mut meshes, mut accessors, mut views) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, (name, mesh)) in all.iter().enumerate() {
        let at = bin.len();
        for p in &mesh.positions {
            p.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
        }
        let normals_at = bin.len();
        for n in &mesh.normals {
            n.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
        }
        let colors = mesh.colors.len() == mesh.positions.len();
        let colors_at = bin.len();
        if colors {
            for c in &mesh.colors {
                c.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
            }
        }
        let indices_at = bin.len();
        for i in &mesh.indices {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let end = bin.len();
        let (mut min, mut max) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in &mesh.positions {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        let n = mesh.positions.len();
        // One accessor per buffer view, numbered in the order they are pushed.
        let first = accessors.len();
        let mut attributes = json!({"POSITION": first, "NORMAL": first + 1});
        accessors.push(
            json!({"bufferView": first, "componentType": FLOAT, "count": n, "type": "VEC3", "min": min, "max": max}),
        );
        views.push(json!({"buffer": 0, "byteOffset": at, "byteLength": normals_at - at, "target": ARRAY_BUFFER}));
        accessors.push(json!({"bufferView": first + 1, "componentType": FLOAT, "count": n, "type": "VEC3"}));
        views.push(json!({"buffer": 0, "byteOffset": normals_at, "byteLength": colors_at - normals_at, "target": ARRAY_BUFFER}));
        if colors {
            // COLOR_0: linear RGB, as glTF specifies vertex colours.
            let c = accessors.len();
            attributes["COLOR_0"] = json!(c);
            accessors.push(json!({"bufferView": c, "componentType": FLOAT, "count": n, "type": "VEC3"}));
            views.push(json!({"buffer": 0, "byteOffset": colors_at, "byteLength": indices_at - colors_at, "target": ARRAY_BUFFER}));
        }
        let idx = accessors.len();
        accessors.push(
            json!({"bufferView": idx, "componentType": UNSIGNED_INT, "count": mesh.indices.len(), "type": "SCALAR"}),
        );
        views.push(json!({"buffer": 0, "byteOffset": indices_at, "byteLength": end - indices_at, "target": ELEMENT_ARRAY_BUFFER}));
        nodes.push(json!({"mesh": k, "name": name}));
        meshes.push(json!({"name": name, "primitives": [{
            "attributes": attributes, "indices": idx, "mode": TRIANGLES}]}));
    }
    let bin_len = bin.len();
    let doc = json!({
        "asset": {"version": "2.0", "generator": "penmodel"},
        "scene": 0,
        "scenes": [{"nodes": (0..all.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin_len}]
    });
    let mut json = doc.to_string().into_bytes();
    pad(&mut json, b' ');
    pad(&mut bin, 0);
    let total = 12 + 8 + json.len() as u64 + 8 + bin.len() as u64;
    let total32 = u32::try_from(total).map_err(|_| ExportError::TooLarge(total))?;
    let mut head = Vec::with_capacity(28);
    for v in [MAGIC, 2, total32, json.len() as u32, CHUNK_JSON] {
        head.extend_from_slice(&v.to_le_bytes());
    }
    out.write_all(&head)?;
    out.write_all(&json)?;
    out.write_all(&(bin.len() as u32).to_le_bytes())?;
    out.write_all(&CHUNK_BIN.to_le_bytes())?;
    out.write_all(&bin)?;
    out.flush()?;
    Ok(())
}
