//! Fractal detail and the terrain settings (issue 20): detail stays off the figures and the
//! regions' edges, is bounded by its amount, is the same for the same seed, and bad settings
//! are refused by name.

use crate::common;

use common::*;
use penmodel_terrain::cells;
use penmodel_terrain::detail::{fbm, gradient_noise};
use penmodel_terrain::{Detail, Document, LoadError, Metric, Region, generate};

fn hills() -> Document {
    let mut d = document(
        96,
        vec![Region {
            boundary: polygon([48.0, 48.0], 44.0, 24, 0.2),
            figures: vec![
                point([40.0, 44.0], 60.0, 0.5),
                polyline(vec![[20.0, 60.0], [50.0, 70.0], [70.0, 50.0]], 35.0, -0.5),
                closed(
                    polygon([62.0, 30.0], 9.0, 8, 0.0),
                    25.0,
                    0.0,
                    vec![point([62.0, 30.0], 45.0, 0.0)],
                ),
            ],
            metric: None,
        }],
    );
    d.terrain.detail = Some(Detail {
        amount: 0.3,
        scale: 24.0,
        octaves: 4,
        seed: 7,
    });
    d
}

#[test]
fn detail_spares_the_figures_and_the_edges_and_is_bounded() {
    let doc = hills();
    let mut plain = doc.clone();
    plain.terrain.detail = None;
    let (with, without) = (generate(&doc).unwrap(), generate(&plain).unwrap());
    let grid = doc.grid;
    // On every figure's cells (a closed figure's are its nested region's, whose own figure is
    // checked too) the detail is 0: a pull lands where the pen is.
    let r = &doc.regions[0];
    for f in [&r.figures[0], &r.figures[1], &r.figures[2].figures[0]] {
        for (c, rr) in cells::figure_cells(&grid, f) {
            assert_eq!(with.get(c, rr), without.get(c, rr), "figure cell ({c}, {rr})");
        }
    }
    // At the region's edge (and outside it) nothing changes either.
    let mask = cells::closed_mask(&grid, &r.boundary);
    let nested = cells::closed_mask(&grid, &r.figures[2].points);
    let mut changed = 0;
    for rr in 0..grid.rows {
        for c in 0..grid.cols {
            let (a, b) = (f64::from(with.get(c, rr)), f64::from(without.get(c, rr)));
            let edge = [
                (c.wrapping_sub(1), rr),
                (c + 1, rr),
                (c, rr.wrapping_sub(1)),
                (c, rr + 1),
            ]
            .iter()
            .any(|&n| !mask.contains(n));
            if !mask.contains((c, rr)) || edge {
                assert_eq!(a, b, "edge or outside cell ({c}, {rr})");
                continue;
            }
            // Bounded: amount × (|h| + scale/4 × the steepest slope of the 3 × 3 block, √2 for
            // the diagonal), the slope read here by its own differences.
            let at = |x: u32, y: u32| f64::from(without.get(x.min(grid.cols - 1), y.min(grid.rows - 1)));
            let mut steep = 0.0f64;
            for (x, y) in [
                (c + 1, rr),
                (c.saturating_sub(1), rr),
                (c, rr + 1),
                (c, rr.saturating_sub(1)),
            ] {
                steep = steep.max((at(x, y) - b).abs());
            }
            let bound = 0.3 * (b.abs() + 6.0 * 2f64.sqrt() * 2.0 * steep) + 1e-3;
            assert!((a - b).abs() <= bound, "({c}, {rr}): {a} vs {b}, bound {bound}");
            if a != b && !nested.contains((c, rr)) {
                changed += 1;
            }
        }
    }
    assert!(changed > 1000, "detail on only {changed} cells");
}

#[test]
fn the_same_seed_the_same_detail() {
    let doc = hills();
    assert_eq!(generate(&doc).unwrap(), generate(&doc.clone()).unwrap());
    let mut other = doc.clone();
    if let Some(d) = &mut other.terrain.detail {
        d.seed = 8;
    }
    assert_ne!(generate(&doc).unwrap(), generate(&other).unwrap());
    // The noise: 0 on the lattice, within [−1, 1] as fBm everywhere sampled.
    for i in -20..20 {
        assert_eq!(gradient_noise(f64::from(i), f64::from(3 * i), 5), 0.0);
    }
    let d = Detail::default();
    let mut spread = (f64::MAX, f64::MIN);
    for i in 0..20_000 {
        let v = fbm(&d, f64::from(i) * 7.31, f64::from(i % 97) * 13.7);
        assert!((-1.0..=1.0).contains(&v));
        spread = (spread.0.min(v), spread.1.max(v));
    }
    assert!(spread.0 < -0.3 && spread.1 > 0.3, "fbm spread {spread:?}");
    // The row-wise evaluation the layer uses is fbm itself, to the bit.
    for (cell, seed) in [(12.5, 0u64), (1.0, 99), (0.37, 5)] {
        let d = Detail {
            scale: 40.0 * cell,
            seed,
            ..Detail::default()
        };
        let y = 17.5 * cell;
        let mut row = vec![0.0; 300];
        penmodel_terrain::detail::fbm_row(&d, cell, y, &mut row);
        for (k, v) in row.iter().enumerate() {
            assert_eq!(
                v.to_bits(),
                fbm(&d, (k as f64 + 0.5) * cell, y).to_bits(),
                "cell {cell}, k {k}"
            );
        }
    }
}

/// Loads `text`, expecting a refusal whose message reads `says`.
#[track_caller]
fn refused(text: &str, says: &str) {
    match Document::from_json(text) {
        Err(e) => assert_eq!(e.to_string(), says),
        Ok(_) => panic!("accepted: {says}"),
    }
}

#[test]
fn bad_settings_are_refused_by_name() {
    let mut doc = hills();
    doc.terrain.metric = Metric::Taxicab;
    let text = doc.to_json();
    assert!(text.contains("\"metric\": \"taxicab\""), "{text}");
    assert_eq!(Document::from_json(&text).unwrap(), doc);
    let swap = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1)
    };
    match Document::from_json(&swap("\"taxicab\"", "\"manhattan\"")) {
        Err(LoadError::Parse { path, message, .. }) => {
            assert_eq!(path, "terrain.metric");
            assert!(
                message.contains("unknown variant `manhattan`, expected `taxicab` or `euclidean`"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
    refused(
        &swap("\"amount\": 0.3", "\"amount\": 1.5"),
        "terrain.detail.amount: the detail's amount must be from 0 to 1, got 1.5",
    );
    refused(
        &swap("\"scale\": 24.0", "\"scale\": 1.0"),
        "terrain.detail.scale: the detail's scale must be from 2 m (two cells) to 10 000 km, got 1",
    );
    refused(
        &swap("\"octaves\": 4", "\"octaves\": 0"),
        "terrain.detail.octaves: the detail's octaves must be from 1 to 12, got 0",
    );
    // A region's own metric, and the settings, need version 4.
    let mut own = hills();
    own.regions[0].metric = Some(Metric::Taxicab);
    let own_text = own.to_json();
    assert!(own_text.contains("\"metric\": \"taxicab\""));
    assert_eq!(Document::from_json(&own_text).unwrap(), own);
    let current = format!("\"version\": {}", penmodel_terrain::document::VERSION);
    own.terrain = Default::default();
    refused(
        &own.to_json().replacen(&current, "\"version\": 3", 1),
        "regions[0].metric: needs document version 4",
    );
    refused(
        &text.replacen(&current, "\"version\": 3", 1),
        "terrain: needs document version 4",
    );
}

#[test]
fn a_region_may_choose_its_own_metric() {
    let mut doc = hills();
    doc.terrain.detail = None;
    let euclidean = generate(&doc).unwrap();
    doc.regions[0].metric = Some(Metric::Taxicab);
    let own = generate(&doc).unwrap();
    doc.regions[0].metric = None;
    doc.terrain.metric = Metric::Taxicab;
    assert_eq!(own, generate(&doc).unwrap());
    assert_ne!(own, euclidean);
}

/// The hillshade of a plane `z = a·x` is `(−a·cos el·cos az + sin el)/√(1 + a²)`, worked out
/// from the plane's normal, on every inner cell (the border's slope is one-sided).
#[test]
fn hillshade_of_planes() {
    use penmodel_terrain::Heightmap;
    use penmodel_terrain::ridge::sun::{Field, Sun, hillshade};
    for a in [0.0f64, 0.3, -0.8] {
        let (cols, rows, cell) = (12u32, 9u32, 2.0);
        let z: Vec<f32> = (0..rows * cols)
            .map(|i| (a * f64::from(i % cols) * cell) as f32)
            .collect();
        let map = Heightmap::from_heights(cols, rows, cell, z).unwrap();
        let sun = Sun::degrees(200.0, 35.0, "test").unwrap();
        let shade = hillshade(Field::of(&map), sun);
        let (az, el) = (200f64.to_radians(), 35f64.to_radians());
        let want = ((-a * el.cos() * az.cos() + el.sin()) / (1.0 + a * a).sqrt()).max(0.0);
        for r in 1..rows - 1 {
            for c in 1..cols - 1 {
                let got = f64::from(shade[(r * cols + c) as usize]);
                assert!((got - want).abs() < 1e-5, "a {a}: {got} vs {want} at ({c}, {r})");
            }
        }
    }
}

/// The version 4 example of `docs/document.md` with terrain settings loads as it says.
#[test]
fn the_settings_example_in_the_docs_loads() {
    let text = include_str!("../../../docs/document.md");
    let start = text
        .find("A version 4 file with terrain settings:")
        .expect("the example's heading");
    let block = &text[start..];
    let open = block.find("```json\n").expect("a json block") + "```json\n".len();
    let close = open + block[open..].find("```").expect("its end");
    let doc = Document::from_json(&block[open..close]).unwrap();
    assert_eq!(doc.terrain.metric, Metric::Euclidean);
    assert_eq!(doc.terrain.detail.map(|d| (d.amount, d.seed)), Some((0.12, 3)));
    assert_eq!(doc.metric_of(&doc.regions[0]), Metric::Taxicab);
    generate(&doc).unwrap();
}
