//! Thermal erosion (issue 20): the pass a plain reference computes, conserving material and
//! never raising a peak; a local edit recomputes a window, equal to a full rebuild to the bit;
//! bad settings are refused by name, and documents without it load as before.

use crate::common;

use common::*;
use penmodel_terrain::{Detail, Document, Edit, Editor, Erosion, FigurePath, Heightmap, Region, generate};

/// Two regions with steep peaks (slopes of 2–3 m per 1 m cell, far above a 33° talus): a large
/// one and a small one.
fn peaks() -> Document {
    let mut d = document(
        80,
        vec![
            Region {
                boundary: polygon([30.0, 30.0], 26.0, 24, 0.2),
                figures: vec![point([24.0, 28.0], 60.0, 0.0), point([38.0, 36.0], 40.0, 1.0)],
                metric: None,
            },
            Region {
                boundary: polygon([66.0, 64.0], 10.0, 16, 0.0),
                figures: vec![point([66.0, 64.0], 25.0, 0.0)],
                metric: None,
            },
        ],
    );
    d.terrain.erosion = Some(Erosion {
        iterations: 6,
        ..Erosion::default()
    });
    d
}

fn bits(m: &Heightmap) -> Vec<u32> {
    m.heights().iter().map(|h| h.to_bits()).collect()
}

/// The pass as `docs/document.md` states it, over the whole grid, cell after cell: every
/// neighbour pair's flow `k·sign(d)·max(0, |d| − T)`, `k = amount/8`, summed in the documented
/// neighbour order, in `f64`, all cells from the last step's heights.
fn reference(e: &Erosion, before: &Heightmap) -> Vec<f32> {
    let (cols, rows) = (before.cols() as i64, before.rows() as i64);
    let mut h: Vec<f64> = before.heights().iter().map(|&v| f64::from(v)).collect();
    let t = e.talus.to_radians().tan() * before.cell_size();
    for _ in 0..e.iterations {
        let last = h.clone();
        for r in 0..rows {
            for c in 0..cols {
                let here = last[(r * cols + c) as usize];
                let mut flow = 0.0;
                for dr in -1..=1i64 {
                    for dc in -1..=1i64 {
                        let (nc, nr) = (c + dc, r + dr);
                        if (dc, dr) == (0, 0) || nc < 0 || nr < 0 || nc >= cols || nr >= rows {
                            continue;
                        }
                        let d = last[(nr * cols + nc) as usize] - here;
                        let limit = if dc != 0 && dr != 0 {
                            t * std::f64::consts::SQRT_2
                        } else {
                            t
                        };
                        if d.abs() > limit {
                            flow += d - limit.copysign(d);
                        }
                    }
                }
                h[(r * cols + c) as usize] = here + e.amount / 8.0 * flow;
            }
        }
    }
    h.into_iter().map(|v| v as f32).collect()
}

#[test]
fn erosion_is_the_stated_pass_conserves_material_and_lowers_the_peaks() {
    let doc = peaks();
    let mut plain = doc.clone();
    plain.terrain.erosion = None;
    let (before, after) = (generate(&plain).unwrap(), generate(&doc).unwrap());
    let e = doc.terrain.erosion.unwrap();
    assert_eq!(
        bits(&after),
        reference(&e, &before).iter().map(|h| h.to_bits()).collect::<Vec<_>>()
    );
    // Material only moves: the sums agree to the rounding of each cell to f32.
    let sum = |m: &Heightmap| m.heights().iter().map(|&h| f64::from(h)).sum::<f64>();
    let ulps = before.heights().len() as f64 * 60.0 * f64::from(f32::EPSILON);
    assert!(
        (sum(&before) - sum(&after)).abs() <= ulps,
        "{} vs {}",
        sum(&before),
        sum(&after)
    );
    // Never above the highest or below the lowest ground (a monotone pass), and the peaks lower.
    let range = |m: &Heightmap| {
        m.heights()
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &h| (lo.min(h), hi.max(h)))
    };
    let (lo, hi) = range(&before);
    let (alo, ahi) = range(&after);
    assert!(alo >= lo && ahi < hi, "{lo}..{hi} became {alo}..{ahi}");
    // The steepest step between neighbours shrinks.
    let steepest = |m: &Heightmap| {
        let mut s = 0.0f32;
        for r in 0..m.rows() {
            for c in 1..m.cols() {
                s = s.max((m.get(c, r) - m.get(c - 1, r)).abs());
            }
        }
        s
    };
    assert!(
        steepest(&after) < steepest(&before),
        "{} vs {}",
        steepest(&after),
        steepest(&before)
    );
}

#[test]
fn a_local_edit_recomputes_a_window_equal_to_a_full_rebuild_to_the_bit() {
    for detail in [None, Some(Detail::default())] {
        let mut doc = peaks();
        doc.terrain.detail = detail.map(|d| Detail { scale: 16.0, ..d });
        let mut editor = Editor::new(doc).unwrap();
        let small = FigurePath::new(1, 0);
        let n = 6;
        for (i, edit) in [
            Edit::MoveFigure {
                at: small.clone(),
                by: [2.0, -1.0],
            },
            Edit::MoveFigure {
                at: FigurePath::new(0, 1),
                by: [-3.0, 2.0],
            },
            Edit::MoveFigure {
                at: small.clone(),
                by: [-1.0, 2.0],
            },
        ]
        .into_iter()
        .enumerate()
        {
            let old = editor.heightmap().clone();
            let outcome = editor.apply(edit).unwrap();
            assert_eq!(
                bits(editor.heightmap()),
                bits(&generate(editor.document()).unwrap()),
                "edit {i}, detail {detail:?}"
            );
            // Only the rectangle returned changed, and for the small region's edits it is its
            // box grown by the detail's cell and the steps: well inside the grid.
            let r = outcome.changed;
            for row in 0..old.rows() {
                for c in 0..old.cols() {
                    let inside = (r.c0..r.c0 + r.width).contains(&c) && (r.r0..r.r0 + r.height).contains(&row);
                    if !inside {
                        assert_eq!(old.get(c, row).to_bits(), editor.heightmap().get(c, row).to_bits());
                    }
                }
            }
            if i != 1 {
                assert!(r.width <= 21 + 2 * (n + 1) && r.height <= 21 + 2 * (n + 1), "{r:?}");
            }
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
fn settings_load_with_defaults_and_bad_ones_are_refused_by_name() {
    let doc = peaks();
    let text = doc.to_json();
    assert!(text.contains("\"erosion\""), "{text}");
    assert_eq!(Document::from_json(&text).unwrap(), doc);
    // Each key optional.
    let mut plain = doc.clone();
    plain.terrain.erosion = None;
    let plain_text = plain.to_json();
    assert!(!plain_text.contains("erosion"), "left out when off: {plain_text}");
    let current = format!("\"version\": {}", penmodel_terrain::document::VERSION);
    let empty = plain_text.replacen(&current, &format!("{current}, \"terrain\": {{\"erosion\": {{}}}}"), 1);
    assert_eq!(
        Document::from_json(&empty).unwrap().terrain.erosion,
        Some(Erosion::default()),
        "{empty}"
    );
    let swap = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1)
    };
    refused(
        &swap("\"talus\": 33.0", "\"talus\": 95.0"),
        "terrain.erosion.talus: the erosion's talus must be from 1 to 89 degrees, got 95",
    );
    refused(
        &swap("\"iterations\": 6", "\"iterations\": 201"),
        "terrain.erosion.iterations: the erosion's iterations must be from 0 to 200, got 201",
    );
    refused(
        &swap("\"amount\": 0.5", "\"amount\": -0.1"),
        "terrain.erosion.amount: the erosion's amount must be from 0 to 1, got -0.1",
    );
    // Older documents have none.
    refused(
        &text.replacen(&current, "\"version\": 3", 1),
        "terrain: needs document version 4",
    );
    plain.terrain = Default::default();
    let old = Document::from_json(&plain.to_json().replacen(&current, "\"version\": 3", 1)).unwrap();
    assert_eq!(old.terrain.erosion, None);
}
