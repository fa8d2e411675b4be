//! Heightmaps out (RAW16, GeoTIFF, sidecars) and in (a document's `terrain.base`), issue 46.

use std::fs;

use crate::common::*;
use crate::editing::{detail, edit_for, erosion, op};
use penmodel_terrain::document::{Base, BaseHeights, Erosion};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::export::{self, Format, GeoRef, Sidecar};
use penmodel_terrain::{Document, Heightmap, generate, import};
use proptest::prelude::*;

/// A slanted plane with a bump: every height differs, so a row or column swap shows.
fn ramp(cols: u32, rows: u32) -> Vec<f32> {
    (0..rows)
        .flat_map(|r| (0..cols).map(move |c| 100.0 + 3.0 * c as f32 - 1.5 * r as f32 + (c * r % 7) as f32))
        .collect()
}

fn map(cols: u32, rows: u32) -> Heightmap {
    Heightmap::from_heights(cols, rows, 12.5, ramp(cols, rows)).unwrap()
}

#[test]
fn raw16_is_rows_by_cols_little_endian_within_one_step() {
    let m = map(7, 5);
    let mut bytes = Vec::new();
    let range = export::write_raw16(&m, &mut bytes).unwrap();
    assert_eq!(bytes.len(), 7 * 5 * 2);
    let step = (range.max - range.min) / 65535.0;
    for (i, h) in m.heights().iter().enumerate() {
        let v = u16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]);
        assert!((range.height(v) - h).abs() <= step, "cell {i}");
    }
    let sidecar = Sidecar::new(Format::Raw16, &m, range).to_json();
    let v: serde_json::Value = serde_json::from_str(&sidecar).unwrap();
    assert_eq!(v["format"], "raw16");
    assert_eq!((v["rows"].as_u64(), v["cols"].as_u64()), (Some(5), Some(7)));
    assert_eq!(v["cell_size_m"].as_f64(), Some(12.5));
    assert_eq!(v["byte_order"], "little-endian");
    let scale = v["vertical_scale_m_per_step"].as_f64().unwrap();
    assert!((scale - f64::from(range.max - range.min) / 65535.0).abs() < 1e-12);
}

#[test]
fn geotiff_reads_back_with_its_size_scale_origin_and_heights() {
    let m = map(9, 4);
    let geo = GeoRef {
        origin: [500_000.0, 4_100_000.0],
        epsg: Some(32654),
    };
    let mut bytes = Vec::new();
    export::write_geotiff(&m, geo, &mut bytes).unwrap();
    let t = export::read_geotiff(&bytes).unwrap();
    assert_eq!((t.cols, t.rows), (9, 4));
    assert_eq!(t.heights, m.heights());
    assert_eq!(t.pixel_scale, Some([12.5, 12.5]));
    assert_eq!(t.origin, Some([500_000.0, 4_100_000.0]));
    // Every cut of the file is an error, not a panic.
    for n in [0, 3, 8, 20, bytes.len() / 2, bytes.len() - 1] {
        assert!(export::read_geotiff(&bytes[..n]).is_err(), "cut at {n}");
    }
    // A size far beyond the file is refused before anything is allocated for it.
    let mut huge = bytes.clone();
    let ifd = u32::from_le_bytes([huge[4], huge[5], huge[6], huge[7]]) as usize;
    for entry in [0, 1] {
        let at = ifd + 2 + entry * 12 + 8;
        huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    }
    let e = export::read_geotiff(&huge).unwrap_err();
    assert!(e.contains("cut off") && e.contains("4294967295 × 4294967295"), "{e}");
}

/// A document on a 40 × 40 grid with one region, and a base heightmap file beside it.
fn with_base(dir: &std::path::Path, base: &[f32]) -> Document {
    let mut bytes = Vec::new();
    for h in base {
        bytes.extend_from_slice(&h.to_le_bytes());
    }
    fs::write(dir.join("base.f32"), bytes).unwrap();
    let mut doc = document(
        40,
        vec![penmodel_terrain::Region {
            metric: None,
            boundary: polygon([20.0, 20.0], 15.0, 8, 0.1),
            figures: vec![point([14.2, 18.3], 30.0, -1.0), point([24.0, 22.0], 12.0, 0.5)],
        }],
    );
    doc.terrain.base = Some(Base::new("base.f32"));
    doc
}

#[test]
fn the_sketch_is_added_onto_the_base_and_erosion_runs_on_the_sum() {
    let dir = tempfile::tempdir().unwrap();
    let base = ramp(40, 40);
    let doc = with_base(dir.path(), &base);
    let path = dir.path().join("doc.json");
    fs::write(&path, doc.to_json()).unwrap();
    let loaded = Document::load(&path).unwrap();
    assert_eq!(loaded.terrain.base.as_ref().unwrap().heights.get(), Some(&base[..]));
    let sum = generate(&loaded).unwrap();
    let mut sketch_doc = doc.clone();
    sketch_doc.terrain.base = None;
    let sketch = generate(&sketch_doc).unwrap();
    for (i, b) in base.iter().enumerate() {
        assert_eq!(sum.heights()[i], sketch.heights()[i] + b, "cell {i}");
    }
    // Thermal erosion of the sum: it moves material where the sum (not the sketch alone) is steep.
    let mut eroded_doc = loaded.clone();
    eroded_doc.terrain.erosion = Some(Erosion {
        talus: 5.0,
        ..Erosion::default()
    });
    let eroded = generate(&eroded_doc).unwrap();
    assert_ne!(eroded.heights(), sum.heights());
    // Mass is kept by the thermal pass, so the eroded sum has the sum's total height.
    let total = |m: &Heightmap| m.heights().iter().map(|&h| f64::from(h)).sum::<f64>();
    assert!(
        (total(&eroded) - total(&sum)).abs() < 1e-3 * total(&sum).abs(),
        "{} vs {}",
        total(&eroded),
        total(&sum)
    );
    // The document is saved naming its base, not holding its heights.
    let json = loaded.to_json();
    assert!(
        json.contains("\"base\": {\"path\": \"base.f32\"}") || json.contains("\"path\": \"base.f32\""),
        "{json}"
    );
    assert!(json.len() < 4000);
}

#[test]
fn bad_bases_are_errors_that_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = with_base(dir.path(), &ramp(40, 40));
    let path = dir.path().join("doc.json");
    let load = |doc: &Document| {
        fs::write(&path, doc.to_json()).unwrap();
        Document::load(&path).unwrap_err().to_string()
    };
    // Missing.
    doc.terrain.base = Some(Base::new("missing.f32"));
    let e = load(&doc);
    assert!(e.contains("terrain.base.path") && e.contains("missing.f32"), "{e}");
    // Wrong size / truncated.
    fs::write(dir.path().join("short.f32"), [0u8; 40 * 39 * 4 + 3]).unwrap();
    doc.terrain.base = Some(Base::new("short.f32"));
    let e = load(&doc);
    assert!(
        e.contains("short.f32") && e.contains("6243 bytes") && e.contains("40 × 40"),
        "{e}"
    );
    // NaN.
    let mut nan = ramp(40, 40);
    nan[41] = f32::NAN;
    fs::write(
        dir.path().join("nan.f32"),
        nan.iter().flat_map(|h| h.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
    doc.terrain.base = Some(Base::new("nan.f32"));
    let e = load(&doc);
    assert!(e.contains("cell (1, 1)") && e.contains("not a finite number"), "{e}");
    // A PNG of another size, and a PNG without its range.
    let m = Heightmap::from_heights(5, 4, 1.0, ramp(5, 4)).unwrap();
    let mut png = Vec::new();
    export::write_png(&m, &mut png).unwrap();
    fs::write(dir.path().join("small.png"), &png).unwrap();
    doc.terrain.base = Some(Base::new("small.png"));
    let e = load(&doc);
    assert!(e.contains("5 × 4 cells") && e.contains("40 × 40"), "{e}");
    // Not a PNG at all.
    fs::write(dir.path().join("junk.png"), b"not a png").unwrap();
    doc.terrain.base = Some(Base::new("junk.png"));
    let e = load(&doc);
    assert!(e.contains("junk.png") && e.contains("not a PNG heightmap"), "{e}");
    // A document built in code whose base is not loaded is refused by the engine.
    doc.terrain.base = Some(Base::new("base.f32"));
    let e = generate(&doc).unwrap_err().to_string();
    assert!(e.contains("not loaded"), "{e}");
    // A version 5 file may not have a base; without one it still loads, as version 6.
    let v5 = doc.to_json().replace("\"version\": 6", "\"version\": 5");
    let e = Document::from_json(&v5).unwrap_err().to_string();
    assert!(e.contains("terrain.base: needs document version 6"), "{e}");
    doc.terrain.base = None;
    let v5 = doc.to_json().replace("\"version\": 6", "\"version\": 5");
    assert_eq!(Document::from_json(&v5).unwrap().version, 6);
}

#[test]
fn a_png_base_reads_within_its_16_bit_step() {
    let dir = tempfile::tempdir().unwrap();
    let m = Heightmap::from_heights(40, 40, 2.0, ramp(40, 40)).unwrap();
    let mut png = Vec::new();
    let range = export::write_png(&m, &mut png).unwrap();
    let path = dir.path().join("dem.png");
    fs::write(&path, &png).unwrap();
    let read = import::read(&path, &import::Options::default()).unwrap();
    assert_eq!((read.cols, read.rows, read.cell_size), (40, 40, Some(2.0)));
    let step = (range.max - range.min) / 65535.0;
    for (a, b) in read.heights.iter().zip(m.heights()) {
        assert!((a - b).abs() <= step, "{a} vs {b}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// A GeoTIFF with bytes changed anywhere (in its header, its tags, their values) reads as
    /// some heightmap or is an error: never a panic, never an allocation the file cannot back.
    #[test]
    fn a_damaged_geotiff_is_an_error_not_a_panic(changes in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut bytes = Vec::new();
        export::write_geotiff(&map(6, 5), GeoRef::default(), &mut bytes).unwrap();
        // Most changes land in the tags and values after the samples.
        let tags = 8 + 6 * 5 * 4;
        for (at, b) in changes {
            let i = tags + at.index(bytes.len() - tags);
            bytes[i] = b;
        }
        let _ = export::read_geotiff(&bytes);
    }

    /// With a base, an edited terrain still equals a full regeneration to the bit, with or
    /// without detail and erosion.
    #[test]
    fn incremental_equals_full_over_a_base(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..10), detail in detail(), erosion in erosion()) {
        doc.terrain.detail = detail;
        doc.terrain.erosion = erosion;
        let mut base = Base::new("base.f32");
        base.heights = BaseHeights::new(ramp(40, 40));
        doc.terrain.base = Some(base);
        let mut editor = Editor::new(doc).unwrap();
        for op in &ops {
            let Some(edit) = edit_for(editor.document(), op) else { continue };
            if editor.apply(edit.clone()).is_ok() {
                let full = generate(editor.document()).unwrap();
                prop_assert!(first_bit_difference(editor.heightmap(), &full).is_none(), "after {:?}", edit);
            }
        }
    }
}

#[test]
fn a_document_saved_in_another_folder_still_finds_its_base() {
    let dir = tempfile::tempdir().unwrap();
    let doc = with_base(dir.path(), &ramp(40, 40));
    let path = dir.path().join("doc.json");
    fs::write(&path, doc.to_json()).unwrap();
    let (mut editor, _) = Editor::open(&path).unwrap();
    fs::create_dir(dir.path().join("elsewhere")).unwrap();
    let moved = dir.path().join("elsewhere").join("doc.json");
    editor.save_as(&moved).unwrap();
    drop(editor);
    let loaded = Document::load(&moved).unwrap();
    assert_eq!(
        generate(&loaded).unwrap(),
        generate(&Document::load(&path).unwrap()).unwrap()
    );
}
