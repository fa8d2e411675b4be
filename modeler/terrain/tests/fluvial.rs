//! Fluvial erosion (issue 39): the seed's examples, eroded with the defaults, drain like land
//! (the signatures `docs/erosion.md` states); the same document gives the same bits on one
//! thread and two; extreme settings never give NaN; bad settings are refused by path, and a
//! version 4 document cannot ask for it.

use crate::examples::examples;
use penmodel_terrain::fluvial::{self, measure};
use penmodel_terrain::{Document, Erosion, Fluvial, Heightmap, TerrainEngine, generate};

fn with_fluvial(mut doc: Document, f: Fluvial) -> Document {
    doc.terrain.erosion = Some(Erosion {
        fluvial: Some(f),
        ..doc.terrain.erosion.unwrap_or_default()
    });
    doc
}

#[test]
fn the_examples_eroded_drain_like_land() {
    for (name, doc) in examples() {
        let before = measure::signatures(&generate(&doc).unwrap(), None);
        let land = generate(&with_fluvial(doc, Fluvial::default())).unwrap();
        let s = measure::signatures(&land, None);
        assert!((0.35..=0.65).contains(&s.area_tau), "{name}: {s:?}");
        assert!((0.45..=0.70).contains(&s.hack_h), "{name}: {s:?}");
        assert!(s.slope_mode_share <= 0.25, "{name}: {s:?}");
        assert_eq!(s.pits, 0, "{name}: {s:?}");
        // The sketch alone drains like a cone: the erosion is what brings τ into the range.
        assert!(before.area_tau > 0.8, "{name} before: {before:?}");
    }
}

#[test]
fn the_same_document_gives_the_same_bits_on_any_number_of_threads() {
    let (_, doc) = examples().remove(3);
    let doc = with_fluvial(
        doc,
        Fluvial {
            steps: 30,
            ..Fluvial::default()
        },
    );
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| generate(&doc).unwrap())
    };
    let bits = |m: &Heightmap| m.heights().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let one = on(1);
    assert_eq!(bits(&one), bits(&on(2)));
    assert_eq!(bits(&one), bits(&on(2)), "a second run");
}

#[test]
fn extreme_settings_never_give_nan_and_stay_within_the_sketch() {
    let (_, doc) = examples().remove(0);
    let sketch = generate(&doc).unwrap();
    let (lo, hi) = sketch.range();
    for f in [
        Fluvial {
            k: 1.0,
            dt: 1e6,
            response: 1e6,
            steps: 20,
            ..Fluvial::default()
        },
        Fluvial {
            k: 1.0,
            n: 4.0,
            m: 2.0,
            diffusion: Some(100.0),
            steps: 20,
            ..Fluvial::default()
        },
        Fluvial {
            k: 0.0,
            n: 0.5,
            m: 0.0,
            noise: 100.0,
            steps: 20,
            ..Fluvial::default()
        },
        Fluvial {
            k: 1e-9,
            dt: 1.0,
            response: 1e9,
            steps: 5,
            ..Fluvial::default()
        },
    ] {
        let land = fluvial::erode(f, &sketch, Some(fluvial::held_cells(&doc)));
        for &v in land.heights() {
            assert!(v.is_finite(), "{f:?}");
            // Raised toward the sketch, worn down toward receivers, diffused between
            // neighbours: never beyond the sketch's range plus its noise.
            assert!(v >= lo - 1e-3 && v <= hi + f.noise as f32 + 1e-3, "{f:?}: {v}");
        }
    }
}

#[test]
fn the_engine_re_erodes_the_whole_grid_after_a_pull() {
    let (_, doc) = examples().remove(3);
    let doc = with_fluvial(
        doc,
        Fluvial {
            steps: 20,
            ..Fluvial::default()
        },
    );
    let mut engine = TerrainEngine::new(&doc).unwrap();
    let mut pulled = doc.clone();
    pulled.regions[0].figures[0].height += 5.0;
    let at = penmodel_terrain::FigurePath::new(0, 0);
    let rect = engine.update(&pulled, &penmodel_terrain::change::Scope::Height(at));
    assert_eq!((rect.width, rect.height), (doc.grid.cols, doc.grid.rows));
    assert_eq!(engine.heightmap(), &generate(&pulled).unwrap());
    assert_ne!(engine.heightmap(), engine.sketch());
}

#[test]
fn bad_settings_are_refused_by_path() {
    let (_, doc) = examples().remove(0);
    for (f, path) in [
        (
            Fluvial {
                k: -1.0,
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.k",
        ),
        (
            Fluvial {
                m: 2.5,
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.m",
        ),
        (
            Fluvial {
                steps: 6000,
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.steps",
        ),
        (
            Fluvial {
                steps: 0,
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.steps",
        ),
        (
            Fluvial {
                diffusion: Some(f64::NAN),
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.diffusion",
        ),
        (
            Fluvial {
                response: 10.0,
                ..Fluvial::default()
            },
            "terrain.erosion.fluvial.response",
        ),
    ] {
        let e = TerrainEngine::new(&with_fluvial(doc.clone(), f))
            .err()
            .expect("refused");
        assert_eq!(e.path, path, "{e}");
    }
}

#[test]
fn older_documents_load_unchanged_and_cannot_ask_for_it() {
    let v4 = r#"{"version": 4, "grid": {"cols": 8, "rows": 8, "cell_size": 1.0}, "regions": [],
        "terrain": {"erosion": {}}}"#;
    let doc = Document::from_json(v4).unwrap();
    assert_eq!(doc.terrain.erosion.and_then(|e| e.fluvial), None);
    let asks = v4.replace(r#""erosion": {}"#, r#""erosion": {"fluvial": {}}"#);
    let e = Document::from_json(&asks).unwrap_err();
    assert!(e.to_string().contains("terrain.erosion.fluvial"), "{e}");
    let v5 = asks.replace(r#""version": 4"#, r#""version": 5"#);
    let doc = Document::from_json(&v5).unwrap();
    assert_eq!(doc.terrain.erosion.and_then(|e| e.fluvial), Some(Fluvial::default()));
}

#[test]
fn a_progressive_pull_shows_at_once_and_settles_on_the_exact_land() {
    let (_, doc) = examples().remove(3);
    let doc = with_fluvial(
        doc,
        Fluvial {
            steps: 12,
            ..Fluvial::default()
        },
    );
    let mut editor = penmodel_terrain::Editor::new(doc).unwrap();
    editor.set_progressive_erosion(true);
    let at = penmodel_terrain::FigurePath::new(0, 0);
    let height = editor.document().regions[0].figures[0].height + 5.0;
    editor
        .preview(&penmodel_terrain::Edit::SetHeight { at, height })
        .unwrap();
    // At once: the pull's change on the old land (the cells it reaches), the exact run
    // pending.
    let exact = generate(editor.document()).unwrap();
    assert_ne!(editor.heightmap(), &exact);
    assert!(editor.terrain().erosion_pending());
    let mut settled = penmodel_terrain::Rect::EMPTY;
    for _ in 0..12 {
        settled = editor.settle_erosion(1);
        if settled.width > 0 {
            break;
        }
    }
    assert_eq!(settled.width, editor.document().grid.cols);
    assert!(!editor.terrain().erosion_pending());
    assert_eq!(editor.heightmap(), &exact);
}

#[test]
fn no_thermal_iterations_is_no_thermal_pass() {
    // `"iterations": 0` (what new documents carry beside `"fluvial"`) leaves the thermal pass
    // out: the terrain is the one without erosion, to the bit.
    let (_, doc) = examples().remove(3);
    let mut off = doc.clone();
    off.terrain.erosion = Some(Erosion {
        iterations: 0,
        ..Erosion::default()
    });
    let bits = |m: &Heightmap| m.heights().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&generate(&off).unwrap()), bits(&generate(&doc).unwrap()));
    // And 16, the default, does change it: the comparison could fail.
    let mut on = doc.clone();
    on.terrain.erosion = Some(Erosion::default());
    assert_ne!(bits(&generate(&on).unwrap()), bits(&generate(&doc).unwrap()));
}
