//! Binary glTF 2.0 (`.glb`), written directly: a 12-byte header (`glTF`, version 2, total
//! length), a JSON chunk padded with spaces to 4 bytes, and a BIN chunk (each accessor's data
//! 4-byte aligned).
//!
//! A [`GlbScene`] is materials (PBR metallic-roughness, a base colour each) and parts: a mesh of
//! one or more triangle primitives (POSITION, NORMAL, COLOR_0 when the mesh has colours, 32-bit
//! indices, and a material each), drawn once by one node, or at many places by one node with
//! the `EXT_mesh_gpu_instancing` extension (TRANSLATION, ROTATION and SCALE per instance). The
//! extension is then both used and required: a loader without it would draw one instance at the
//! origin instead of all of them in their places, so it had better refuse the file and say why.

use std::io::Write;

use serde_json::{Value, json};

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
/// The instancing extension's name.
pub const INSTANCING: &str = "EXT_mesh_gpu_instancing";

fn pad(bytes: &mut Vec<u8>, with: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(with);
    }
}

/// How a material's alpha is read (glTF's `alphaMode`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Alpha {
    /// Alpha is ignored.
    Opaque,
    /// Blended with what is behind (water).
    Blend,
    /// Cut out below the cutoff (leaves with an alpha texture).
    Mask(f32),
}

/// A PBR metallic-roughness material with a base colour (linear RGBA; a primitive's COLOR_0
/// multiplies it).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Its name in the file.
    pub name: String,
    /// Linear RGBA, 0 to 1.
    pub base_color: [f32; 4],
    /// 0 (dielectric) to 1.
    pub metallic: f32,
    /// 0 (mirror) to 1 (matte).
    pub roughness: f32,
    /// How alpha is read.
    pub alpha: Alpha,
    /// Drawn from both sides (leaves, cards).
    pub double_sided: bool,
}

impl Material {
    /// An opaque, non-metallic material of linear colour `rgb` and `roughness`.
    pub fn opaque(name: &str, rgb: [f32; 3], roughness: f32) -> Material {
        Material {
            name: name.to_string(),
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            metallic: 0.0,
            roughness,
            alpha: Alpha::Opaque,
            double_sided: false,
        }
    }

    /// White, for a mesh whose vertex colours (COLOR_0) are its colour.
    pub fn vertex_coloured(name: &str) -> Material {
        Material::opaque(name, [1.0; 3], 0.9)
    }

    /// Light grey: a mesh with no colour of its own.
    pub fn plain(name: &str) -> Material {
        Material::opaque(name, [0.5; 3], 0.9)
    }

    /// Water: blue, smooth, seen through (alpha blended).
    pub fn water() -> Material {
        Material {
            alpha: Alpha::Blend,
            base_color: [0.03, 0.16, 0.30, 0.7],
            ..Material::opaque("water", [0.0; 3], 0.1)
        }
    }

    fn json(&self) -> Value {
        let mut m = json!({
            "name": self.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": self.base_color,
                "metallicFactor": self.metallic,
                "roughnessFactor": self.roughness,
            },
        });
        match self.alpha {
            Alpha::Opaque => {}
            Alpha::Blend => m["alphaMode"] = json!("BLEND"),
            Alpha::Mask(cutoff) => {
                m["alphaMode"] = json!("MASK");
                m["alphaCutoff"] = json!(cutoff);
            }
        }
        if self.double_sided {
            m["doubleSided"] = json!(true);
        }
        m
    }
}

/// Where one instance of a part stands: glTF's translation, rotation (unit quaternion
/// `[x, y, z, w]`) and scale, applied scale first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Metres, in the exports' frame (X = x, Y up, Z = y).
    pub translation: [f32; 3],
    /// A unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
    /// Per axis.
    pub scale: [f32; 3],
}

/// A mesh of the scene: its primitives (a mesh each with the index of its material in
/// [`GlbScene::materials`]), drawn once in place (`instances: None`) or at each of `instances`.
#[derive(Debug, Clone)]
pub struct Part<'a> {
    /// The mesh's and node's name.
    pub name: String,
    /// (mesh, material) per primitive; meshes without triangles are left out.
    pub primitives: Vec<(&'a Mesh, usize)>,
    /// `None`: one node at the identity; else one node with the instancing extension.
    pub instances: Option<Vec<Instance>>,
}

/// What a GLB holds: materials and parts.
#[derive(Debug, Clone, Default)]
pub struct GlbScene<'a> {
    /// The materials, referred to by index.
    pub materials: Vec<Material>,
    /// The meshes, each with its node.
    pub parts: Vec<Part<'a>>,
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
/// out (glTF has no empty accessors). A mesh with vertex colours gets a white material (its
/// colours show), one without a grey one.
pub fn write_glb_meshes(meshes: &[(&str, &Mesh)], out: impl Write) -> Result<(), ExportError> {
    let scene = GlbScene {
        materials: vec![Material::plain("plain"), Material::vertex_coloured("vertex colours")],
        parts: meshes
            .iter()
            .map(|(name, mesh)| Part {
                name: name.to_string(),
                primitives: vec![(*mesh, usize::from(has_colors(mesh)))],
                instances: None,
            })
            .collect(),
    };
    write_glb_scene(&scene, out)
}

fn has_colors(mesh: &Mesh) -> bool {
    !mesh.colors.is_empty() && mesh.colors.len() == mesh.positions.len()
}

/// The BIN chunk and the accessors and buffer views into it, one view per accessor.
#[derive(Default)]
struct Buffers {
    bin: Vec<u8>,
    accessors: Vec<Value>,
    views: Vec<Value>,
}

impl Buffers {
    /// Appends `values` (each `N` floats) as an accessor of `kind` ("VEC3", …); returns its index.
    fn floats<const N: usize>(&mut self, values: &[[f32; N]], kind: &str, target: Option<u32>, bounds: bool) -> usize {
        let at = self.bin.len();
        for v in values {
            v.iter().for_each(|x| self.bin.extend_from_slice(&x.to_le_bytes()));
        }
        let mut accessor = json!({"bufferView": self.views.len(), "componentType": FLOAT,
            "count": values.len(), "type": kind});
        if bounds {
            let (mut min, mut max) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
            for v in values {
                for k in 0..N {
                    min[k] = min[k].min(v[k]);
                    max[k] = max[k].max(v[k]);
                }
            }
            accessor["min"] = json!(min.as_slice());
            accessor["max"] = json!(max.as_slice());
        }
        self.push(at, target, accessor)
    }

    fn indices(&mut self, indices: &[u32]) -> usize {
        let at = self.bin.len();
        indices
            .iter()
            .for_each(|i| self.bin.extend_from_slice(&i.to_le_bytes()));
        let accessor = json!({"bufferView": self.views.len(), "componentType": UNSIGNED_INT,
            "count": indices.len(), "type": "SCALAR"});
        self.push(at, Some(ELEMENT_ARRAY_BUFFER), accessor)
    }

    fn push(&mut self, at: usize, target: Option<u32>, accessor: Value) -> usize {
        let mut view = json!({"buffer": 0, "byteOffset": at, "byteLength": self.bin.len() - at});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.views.push(view);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

/// A unit normal: `n` when it is one (to the validator's tolerance), else `n` made one, or +Y
/// when it has no direction (a degenerate triangle's).
fn unit(n: [f32; 3]) -> [f32; 3] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if (len - 1.0).abs() < 1e-4 {
        n
    } else if len > 1e-12 && len.is_finite() {
        n.map(|v| v / len)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// Writes `scene` as binary glTF. A primitive naming a material that is not there is an error.
pub fn write_glb_scene(scene: &GlbScene<'_>, mut out: impl Write) -> Result<(), ExportError> {
    let mut buf = Buffers::default();
    let (mut nodes, mut meshes) = (Vec::new(), Vec::new());
    let mut instanced = false;
    for part in &scene.parts {
        if part.instances.as_ref().is_some_and(|i| i.is_empty()) {
            continue;
        }
        let mut primitives = Vec::new();
        for &(mesh, material) in &part.primitives {
            if mesh.indices.is_empty() {
                continue;
            }
            if material >= scene.materials.len() {
                return Err(ExportError::NoMaterial(material));
            }
            let position = buf.floats(&mesh.positions, "VEC3", Some(ARRAY_BUFFER), true);
            let normals: Vec<[f32; 3]> = mesh.normals.iter().map(|&n| unit(n)).collect();
            let normal = buf.floats(&normals, "VEC3", Some(ARRAY_BUFFER), false);
            let mut attributes = json!({"POSITION": position, "NORMAL": normal});
            if has_colors(mesh) {
                // COLOR_0: linear RGB, as glTF specifies vertex colours.
                attributes["COLOR_0"] = json!(buf.floats(&mesh.colors, "VEC3", Some(ARRAY_BUFFER), false));
            }
            let indices = buf.indices(&mesh.indices);
            primitives.push(json!({"attributes": attributes, "indices": indices,
                "material": material, "mode": TRIANGLES}));
        }
        if primitives.is_empty() {
            continue;
        }
        let mut node = json!({"mesh": meshes.len(), "name": part.name});
        if let Some(instances) = &part.instances {
            instanced = true;
            let t: Vec<[f32; 3]> = instances.iter().map(|i| i.translation).collect();
            let r: Vec<[f32; 4]> = instances.iter().map(|i| i.rotation).collect();
            let s: Vec<[f32; 3]> = instances.iter().map(|i| i.scale).collect();
            let (t, r, s) = (
                buf.floats(&t, "VEC3", None, false),
                buf.floats(&r, "VEC4", None, false),
                buf.floats(&s, "VEC3", None, false),
            );
            node["extensions"] = json!({INSTANCING: {"attributes": {
                "TRANSLATION": t, "ROTATION": r, "SCALE": s}}});
        }
        nodes.push(node);
        meshes.push(json!({"name": part.name, "primitives": primitives}));
    }
    let Buffers {
        mut bin,
        accessors,
        views,
    } = buf;
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "penmodel"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": scene.materials.iter().map(Material::json).collect::<Vec<_>>(),
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    if instanced {
        doc["extensionsUsed"] = json!([INSTANCING]);
        doc["extensionsRequired"] = json!([INSTANCING]);
    }
    if scene.materials.is_empty() {
        doc.as_object_mut().map(|o| o.remove("materials"));
    }
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
