//! Exports: PNG with its height range, raw float32, OBJ and binary glTF (read back with an
//! independent glTF reader).

use std::io::Cursor;
use std::path::PathBuf;

use penmodel_terrain::{Document, Heightmap, export, generate};

fn volcano() -> Heightmap {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/03-island-with-crater.json");
    generate(&Document::load(&path).unwrap()).unwrap()
}

/// A small heightmap with a negative height, to see signs and the row order.
fn tiny() -> Heightmap {
    Heightmap::from_heights(3, 2, 2.0, vec![0.0, 1.5, -2.0, 4.0, 0.25, 2.5]).unwrap()
}

#[test]
fn raw_is_little_endian_row_major() {
    let mut bytes = Vec::new();
    export::write_raw(&tiny(), &mut bytes).unwrap();
    assert_eq!(bytes.len(), 6 * 4);
    // Index r·cols + c: cell (c 0, r 1) is the 4th value, 4.0 = 0x40800000.
    assert_eq!(&bytes[12..16], &[0x00, 0x00, 0x80, 0x40]);
    let map = volcano();
    let mut bytes = Vec::new();
    export::write_raw(&map, &mut bytes).unwrap();
    let back = export::read_raw(Cursor::new(bytes), map.cols(), map.rows()).unwrap();
    assert_eq!(back, map.heights());
}

#[test]
fn png_is_16_bit_grayscale_with_its_range() {
    let map = volcano();
    let mut bytes = Vec::new();
    let range = export::write_png(&map, &mut bytes).unwrap();
    assert_eq!((range.min, range.max), map.range());
    assert_eq!(export::read_png_range(Cursor::new(&bytes)).unwrap(), Some(range));
    let mut reader = png::Decoder::new(Cursor::new(&bytes)).read_info().unwrap();
    let info = reader.info();
    assert_eq!((info.width, info.height), (map.cols(), map.rows()));
    assert_eq!(
        (info.color_type, info.bit_depth),
        (png::ColorType::Grayscale, png::BitDepth::Sixteen)
    );
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    // Each pixel decodes to its height within half a quantisation step (plus f32 rounding).
    let step = (range.max - range.min) / 65535.0;
    for (i, px) in buf.chunks_exact(2).enumerate() {
        let v = u16::from_be_bytes([px[0], px[1]]);
        let h = map.heights()[i];
        assert!(
            (range.height(v) - h).abs() <= step * 0.5 + 1e-5,
            "pixel {i}: {v} → {} vs {h}",
            range.height(v)
        );
    }
    // The extremes map to 0 and 65535.
    let t = tiny();
    let mut bytes = Vec::new();
    export::write_png(&t, &mut bytes).unwrap();
    let mut reader = png::Decoder::new(Cursor::new(&bytes)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    let px: Vec<u16> = buf.chunks_exact(2).map(|p| u16::from_be_bytes([p[0], p[1]])).collect();
    // (h + 2)/6 · 65535 rounded: 0 → 21845, 1.5 → 38228.75, −2 → 0, 4 → 65535, 0.25 → 24575.625,
    // 2.5 → 49151.25.
    assert_eq!(px, vec![21845, 38229, 0, 65535, 24576, 49151]);
}

#[test]
fn obj_has_a_vertex_per_cell_and_two_triangles_per_square() {
    let mut bytes = Vec::new();
    export::write_obj(&tiny(), &mut bytes).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let lines = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!((lines("v "), lines("vn "), lines("f ")), (6, 6, 4));
    // Cell (1, 0) at x = 3, y = 1 (cell centre), height 1.5 → "v 3 1.5 1".
    assert!(text.lines().any(|l| l == "v 3 1.5 1"), "{text}");
    // First square: a = 1, b = 2, d = 4, e = 5 (1-based) → (a, d, b) and (b, d, e).
    assert!(text.contains("f 1//1 4//4 2//2\nf 2//2 4//4 5//5\n"), "{text}");
    assert!(matches!(
        export::write_obj(&Heightmap::from_heights(1, 3, 1.0, vec![0.0; 3]).unwrap(), Vec::new()),
        Err(export::ExportError::TooSmallForMesh { cols: 1, rows: 3 })
    ));
}

#[test]
fn glb_reads_back_with_an_independent_reader() {
    let map = volcano();
    let mut bytes = Vec::new();
    export::write_glb(&map, &mut bytes).unwrap();
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let mesh = gltf.meshes().next().unwrap();
    let prim = mesh.primitives().next().unwrap();
    assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
    let reader = prim.reader(|_| Some(&blob));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let (cols, rows) = (map.cols() as usize, map.rows() as usize);
    assert_eq!(positions.len(), cols * rows);
    assert_eq!(normals.len(), cols * rows);
    assert_eq!(indices.len(), (cols - 1) * (rows - 1) * 6);
    let s = map.cell_size() as f32;
    for (i, p) in positions.iter().enumerate() {
        let (c, r) = ((i % cols) as f32, (i / cols) as f32);
        assert_eq!(*p, [(c + 0.5) * s, map.heights()[i], (r + 0.5) * s]);
    }
    for n in &normals {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-5 && n[1] > 0.0);
    }
    // Every triangle faces up (+Y), counter-clockwise seen from above.
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
        let (u, v) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
        // Y of (b − a) × (c − a) = dz_u·dx_v − dx_u·dz_v.
        assert!(u[1] * v[0] - u[0] * v[1] > 0.0);
    }
    let bounds = gltf.accessors().next().unwrap();
    assert_eq!(bounds.max().unwrap()[1].as_f64().unwrap() as f32, map.range().1);
}

#[test]
fn glb_scene_has_materials_and_instances() {
    use export::{Alpha, GlbScene, Instance, Material, Mesh, Part};
    let map = tiny();
    let terrain = Mesh::of(&map).unwrap();
    let tri = Mesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        // One normal without a direction: written as +Y, which the validator accepts.
        normals: vec![[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0; 3]],
        indices: vec![0, 1, 2],
        colors: Vec::new(),
    };
    let at = |x: f32| Instance {
        translation: [x, 0.0, 1.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
        scale: [2.0; 3],
    };
    let empty = Mesh::default();
    let scene = GlbScene {
        materials: vec![
            Material::plain("ground"),
            Material::water(),
            Material {
                alpha: Alpha::Mask(0.5),
                double_sided: true,
                ..Material::opaque("leaves", [0.1, 0.4, 0.1], 0.8)
            },
        ],
        parts: vec![
            Part {
                name: "terrain".into(),
                primitives: vec![(&terrain, 0)],
                instances: None,
            },
            Part {
                name: "tris".into(),
                primitives: vec![(&tri, 1), (&empty, 0)],
                instances: Some(vec![at(1.0), at(2.0), at(3.0)]),
            },
            // No instances: left out.
            Part {
                name: "none".into(),
                primitives: vec![(&tri, 1)],
                instances: Some(Vec::new()),
            },
        ],
    };
    let mut bytes = Vec::new();
    export::write_glb_scene(&scene, &mut bytes).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    assert_eq!(json["extensionsUsed"], serde_json::json!([export::INSTANCING]));
    assert_eq!(json["extensionsRequired"], serde_json::json!([export::INSTANCING]));
    let nodes = json["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 2);
    let ext = &nodes[1]["extensions"][export::INSTANCING]["attributes"];
    for k in ["TRANSLATION", "ROTATION", "SCALE"] {
        let a = &json["accessors"][ext[k].as_u64().unwrap() as usize];
        assert_eq!(a["count"], 3, "{k}");
    }
    assert_eq!(json["materials"][1]["alphaMode"], "BLEND");
    assert_eq!(json["materials"][2]["alphaMode"], "MASK");
    assert_eq!(json["materials"][2]["alphaCutoff"], 0.5);
    assert_eq!(json["materials"][2]["doubleSided"], true);
    let prims = json["meshes"][1]["primitives"].as_array().unwrap();
    assert_eq!(prims.len(), 1, "the empty primitive is left out");
    assert_eq!(prims[0]["material"], 1);
    // An independent reader: the materials, and the normals made unit.
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let mesh = gltf.meshes().nth(1).unwrap();
    let prim = mesh.primitives().next().unwrap();
    assert_eq!(prim.material().index(), Some(1));
    assert_eq!(prim.material().alpha_mode(), gltf::material::AlphaMode::Blend);
    let normals: Vec<[f32; 3]> = prim.reader(|_| Some(&blob)).read_normals().unwrap().collect();
    assert_eq!(normals, [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]);
    // A primitive naming a material not there is an error, not a broken file.
    let bad = GlbScene {
        materials: Vec::new(),
        parts: vec![Part {
            name: "t".into(),
            primitives: vec![(&tri, 0)],
            instances: None,
        }],
    };
    assert!(matches!(
        export::write_glb_scene(&bad, Vec::new()),
        Err(export::ExportError::NoMaterial(0))
    ));
}
