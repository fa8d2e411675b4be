//! The limits of issue 22: nesting depth, the ranges that keep the terrain finite, the engine's
//! memory bound, the end of a document, the curve checks on large inputs, and the messages.

use crate::common::*;
use penmodel_terrain::editor::{Editor, EditorError};
use penmodel_terrain::export::{self, ExportError};
use penmodel_terrain::geometry::{self, Side};
use penmodel_terrain::validate::{self, CurveDefect, FigureDefect, MAX_DEPTH, MAX_ENGINE_BYTES};
use penmodel_terrain::{Defect, Document, Edit, EditError, FigurePath, Heightmap, LoadError, Point, Region};

/// A square `[lo, hi]²`, closed.
fn square(lo: f64, hi: f64) -> Vec<Point> {
    vec![[lo, lo], [hi, lo], [hi, hi], [lo, hi], [lo, lo]]
}

fn one_region(n: u32, figures: Vec<penmodel_terrain::Figure>) -> Document {
    document(
        n,
        vec![Region {
            metric: None,
            boundary: square(1.0, f64::from(n) - 1.0),
            figures,
        }],
    )
}

/// The path of the figure at `depth` in a chain of figures each nested in the one before.
fn chain(depth: usize) -> FigurePath {
    let mut p = FigurePath::new(0, 0);
    for _ in 1..depth {
        p = p.child(0);
    }
    p
}

fn nested_square(depth: usize) -> penmodel_terrain::Figure {
    let d = depth as f64;
    closed(square(1.0 + 2.0 * d, 199.0 - 2.0 * d), 10.0 + d, 0.5, vec![])
}

#[test]
fn the_deepest_document_the_editor_allows_saves_and_loads_back() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("deep.json");
    let mut editor = Editor::create(&path, one_region(200, vec![])).unwrap();
    for depth in 1..=MAX_DEPTH {
        editor
            .apply(Edit::AddFigure {
                at: chain(depth),
                figure: nested_square(depth),
            })
            .unwrap_or_else(|e| panic!("depth {depth}: {e}"));
    }
    // One more level is refused, by the editor as by validation.
    let e = editor
        .apply(Edit::AddFigure {
            at: chain(MAX_DEPTH + 1),
            figure: nested_square(MAX_DEPTH + 1),
        })
        .unwrap_err();
    match e {
        EditorError::Edit(EditError::Invalid(v)) => {
            assert_eq!(v.defect, Defect::Figure(FigureDefect::TooDeep(MAX_DEPTH + 1)), "{v}");
            assert_eq!(v.path, chain(MAX_DEPTH + 1).to_string());
        }
        other => panic!("{other}"),
    }
    // Moving the region journals its whole nesting in the inverse edit (and, after saving, in the
    // history line): every line parses back too.
    editor
        .apply(Edit::MoveRegion {
            index: 0,
            by: [0.25, 0.0],
        })
        .unwrap();
    editor.save().unwrap();
    let saved = editor.document().clone();
    assert_eq!(Document::load(&path).unwrap(), saved);
    // Read-only: the editor that saved it still has it open for writing.
    let (reopened, _) = Editor::open_read_only(&path).unwrap();
    assert_eq!(reopened.document(), &saved);
    assert!(reopened.can_undo());
    drop(reopened);

    // The loader refuses a document one level deeper with the same error.
    let mut deeper = saved.clone();
    let mut f = &mut deeper.regions[0].figures[0];
    for _ in 1..MAX_DEPTH {
        f = &mut f.figures[0];
    }
    f.figures.push(point([100.0, 100.0], 5.0, 0.0));
    match Document::from_json(&deeper.to_json()) {
        Err(LoadError::Invalid(v)) => assert_eq!(v.defect, Defect::Figure(FigureDefect::TooDeep(MAX_DEPTH + 1))),
        other => panic!("{other:?}"),
    }
    // Far deeper than the JSON reader goes: a plain message, no "recursion limit".
    let mut deepest = deeper.clone();
    let mut f = &mut deepest.regions[0].figures[0];
    for _ in 1..MAX_DEPTH {
        f = &mut f.figures[0];
    }
    for _ in 0..40 {
        f.figures = vec![closed(square(90.0, 110.0), 1.0, 0.0, vec![])];
        f = &mut f.figures[0];
    }
    let text = deepest.to_json();
    let e = Document::from_json(&text).unwrap_err().to_string();
    assert!(e.contains("nested too deeply") && !e.contains("recursion"), "{e}");
}

#[test]
fn heights_slopes_and_cell_sizes_out_of_range_are_refused_everywhere() {
    let doc = |h: f64, s: f64| one_region(40, vec![point([20.0, 20.0], h, s)]);
    for (h, s, path, defect) in [
        (
            1.7e308,
            0.0,
            "regions[0].figures[0].height",
            Defect::Figure(FigureDefect::HeightRange(1.7e308)),
        ),
        (
            -1.7e308,
            0.0,
            "regions[0].figures[0].height",
            Defect::Figure(FigureDefect::HeightRange(-1.7e308)),
        ),
        (
            1e39,
            0.0,
            "regions[0].figures[0].height",
            Defect::Figure(FigureDefect::HeightRange(1e39)),
        ),
        (
            10.0,
            1e300,
            "regions[0].figures[0].slope",
            Defect::Figure(FigureDefect::SlopeRange(1e300)),
        ),
    ] {
        let d = doc(h, s);
        let e = validate::document(&d).unwrap_err();
        assert_eq!((e.path.as_str(), &e.defect), (path, &defect));
        match Document::from_json(&d.to_json()) {
            Err(LoadError::Invalid(le)) => assert_eq!(le, e),
            other => panic!("{other:?}"),
        }
        // Numbers in messages are compact.
        assert!(e.to_string().len() < 120, "{e}");
    }
    let e = validate::document(&doc(1.7e308, 0.0)).unwrap_err().to_string();
    assert!(e.ends_with("a height must be within ±1000000 m, got 1.7e308"), "{e}");

    let mut d = doc(10.0, 0.0);
    d.grid.cell_size = 1e308;
    let e = validate::document(&d).unwrap_err();
    assert_eq!(
        e.to_string(),
        "grid.cell_size: the cell size must be between 0.001 and 100000 m, got 1e308"
    );

    // The editor refuses the same values.
    let mut editor = Editor::new(doc(10.0, 0.0)).unwrap();
    for edit in [
        Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 1e308,
        },
        Edit::SetSlope {
            at: FigurePath::new(0, 0),
            slope: -1e308,
        },
    ] {
        assert!(editor.apply(edit.clone()).is_err());
        assert!(editor.preview(&edit).is_err());
    }
    assert_eq!(editor.document(), &doc(10.0, 0.0));

    // At the limits the terrain is finite: heights ±MAX_HEIGHT, slopes ±MAX_SLOPE, nested.
    let extreme = one_region(
        60,
        vec![
            point([10.0, 10.0], validate::MAX_HEIGHT, validate::MAX_SLOPE),
            point([50.0, 50.0], -validate::MAX_HEIGHT, -validate::MAX_SLOPE),
            closed(
                square(20.0, 40.0),
                -validate::MAX_HEIGHT,
                validate::MAX_SLOPE,
                vec![point([30.0, 30.0], validate::MAX_HEIGHT, -validate::MAX_SLOPE)],
            ),
        ],
    );
    let map = penmodel_terrain::generate(&extreme).unwrap();
    assert!(map.heights().iter().all(|h| h.is_finite()));
    export::write_obj(&map, &mut Vec::new()).unwrap();
}

/// The `open` line of a version-1 journal for the document file at `path`.
fn v1_open_line(path: &std::path::Path) -> String {
    let bytes = std::fs::read(path).unwrap();
    format!(
        "{{\"op\":\"open\",\"journal\":1,\"base\":\"{}\"}}\n",
        penmodel_terrain::journal::fingerprint(&bytes)
    )
}

#[test]
fn a_journal_with_an_out_of_range_height_does_not_replay() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let doc = one_region(40, vec![point([20.0, 20.0], 10.0, 0.0)]);
    drop(Editor::create(&path, doc).unwrap());
    let journal = penmodel_terrain::journal::path_for(&path);
    // A version-1 journal: a line of version 2 would carry a checksum the test would have to
    // forge; the replay's checks are the same.
    let mut text = v1_open_line(&path);
    text.push_str(
        "{\"op\":\"do\",\"edit\":{\"op\":\"set_height\",\"at\":\"regions[0].figures[0]\",\"height\":1e308}}\n",
    );
    std::fs::write(&journal, text).unwrap();
    match Editor::open_read_only(&path).map(|_| ()).unwrap_err() {
        EditorError::Replay { line, reason, .. } => {
            assert_eq!(line, 2);
            assert!(
                reason.contains("a height must be within ±1000000 m, got 1e308"),
                "{reason}"
            );
        }
        other => panic!("{other}"),
    }
}

#[test]
fn exports_refuse_heights_that_are_not_finite() {
    let mut heights = vec![1.0f32; 9];
    heights[5] = f32::NAN;
    let map = Heightmap::from_heights(3, 3, 1.0, heights).unwrap();
    let check = |e: ExportError| {
        assert!(matches!(e, ExportError::NotFinite { col: 2, row: 1, .. }), "{e}");
    };
    check(export::write_raw(&map, &mut Vec::new()).unwrap_err());
    check(export::write_png(&map, &mut Vec::new()).unwrap_err());
    check(export::write_obj(&map, &mut Vec::new()).unwrap_err());
    check(export::write_glb(&map, &mut Vec::new()).unwrap_err());
}

#[test]
fn memory_is_bounded_before_anything_allocates() {
    // 300 figures on 2048² aborted the process; now validation refuses it, naming the numbers.
    let n = 2048;
    let figures: Vec<_> = (0..300)
        .map(|i| {
            point(
                [100.0 + f64::from(i % 20) * 90.0, 100.0 + f64::from(i / 20) * 120.0],
                20.0,
                0.0,
            )
        })
        .collect();
    let big = one_region(n, figures);
    let (bytes, count, _) = validate::engine_bytes(&big);
    assert!(bytes > MAX_ENGINE_BYTES && count == 300);
    let e = validate::document(&big).unwrap_err();
    assert!(matches!(e.defect, Defect::TooLarge { figures: 300, .. }), "{e}");
    let message = e.to_string();
    assert!(
        message.contains("300 figures") && message.contains("more than the limit of 2.1 GB"),
        "{message}"
    );
    match Document::from_json(&big.to_json()) {
        Err(LoadError::Invalid(le)) => assert_eq!(le, e),
        other => panic!("{other:?}"),
    }
    assert!(penmodel_terrain::TerrainEngine::new(&big).is_err());

    // An edit that would cross the limit is refused and changes nothing.
    let mut under = big.clone();
    while validate::engine_bytes(&under).0 > MAX_ENGINE_BYTES {
        under.regions[0].figures.pop();
    }
    validate::document(&under).unwrap();
    let before = under.clone();
    let err = Edit::AddFigure {
        at: FigurePath::new(0, 0),
        figure: point([50.0, 50.0], 1.0, 0.0),
    }
    .apply_to(&mut under)
    .unwrap_err();
    assert!(
        matches!(err, EditError::Invalid(ref v) if matches!(v.defect, Defect::TooLarge { .. })),
        "{err}"
    );
    assert_eq!(under, before);
}

#[test]
fn nothing_may_follow_the_document() {
    let text = one_region(40, vec![point([20.0, 20.0], 10.0, 0.0)]).to_json();
    Document::from_json(&format!("{text}\n  \n")).unwrap();
    for tail in ["xyz garbage {", "{}", &text] {
        match Document::from_json(&format!("{text}{tail}")) {
            Err(LoadError::Parse { path, message, .. }) => {
                assert_eq!(path, "");
                assert!(
                    message.contains("unexpected text after the end of the document"),
                    "{message}"
                );
            }
            other => panic!("{tail}: {other:?}"),
        }
    }
}

#[track_caller]
fn parse_error(text: &str) -> (String, String) {
    match Document::from_json(text) {
        Err(LoadError::Parse { path, message, .. }) => (path, message),
        other => panic!("{other:?}"),
    }
}

#[test]
fn messages_say_what_is_expected_in_the_document_s_words() {
    let (path, message) = parse_error("[]");
    assert!(path.is_empty() && message.contains("expected a document") && !message.contains("struct"));
    let (path, message) = parse_error("42");
    assert!(path.is_empty() && message.contains("expected a document"), "{message}");
    // An error where the reader could not name the element: no `?`.
    let (path, _) = parse_error("{");
    assert_eq!(path, "");
    let (path, message) = parse_error(
        r#"{"version": 1, "grid": {"cols": 4, "rows": 4, "cell_size": 1}, "regions": [{"boundary": [[0, 0, 1]]}]}"#,
    );
    assert_eq!(
        (path.as_str(), message.as_str()),
        ("regions[0].boundary[0]", "a point is [x, y]: two numbers, found more")
    );
    let (_, message) = parse_error(
        r#"{"version": 1, "grid": {"cols": 4, "rows": 4, "cell_size": 1}, "regions": [{"boundary": [[0]]}]}"#,
    );
    assert_eq!(message, "a point is [x, y]: two numbers, found 1");
    let (path, message) = parse_error(r#"{"version": 1, "grid": 5}"#);
    assert!(path == "grid" && message.contains("expected a grid"), "{message}");

    // An OS error is said once, and not again as the source.
    let dir = tempfile::tempdir().unwrap();
    let e = Document::load(&dir.path().join("missing.json")).unwrap_err();
    let text = e.to_string();
    assert_eq!(text.matches("os error").count(), 1, "{text}");
    assert!(std::error::Error::source(&e).is_none());
}

#[test]
fn a_journal_s_invalid_utf8_is_reported_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let mut editor = Editor::create(&path, one_region(40, vec![point([20.0, 20.0], 10.0, 0.0)])).unwrap();
    editor
        .apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 11.0,
        })
        .unwrap();
    drop(editor);
    let journal = penmodel_terrain::journal::path_for(&path);
    // Version 1, whose lines have no checksum to catch the byte first (version 2's would).
    let mut bytes = v1_open_line(&path).into_bytes();
    bytes.extend_from_slice(
        b"{\"op\":\"do\",\"edit\":{\"op\":\"set_height\",\"at\":\"regions[0].figures[0]\",\"height\":11.0}}\n",
    );
    bytes.extend_from_slice(b"{\"op\":\"undo\xff\"}\n");
    std::fs::write(&journal, bytes).unwrap();
    let e = Editor::open(&path).map(|_| ()).unwrap_err().to_string();
    assert!(
        e.contains("line 3: not UTF-8 text: an invalid byte at column 12"),
        "{e}"
    );
}

/// The self-intersection check of validation as it was, pair by pair, for comparison.
fn brute_ring(pts: &[Point]) -> Option<(usize, usize)> {
    let n = pts.len() - 1;
    for j in 1..n {
        for i in 0..j {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            let meets = if adjacent {
                let (p, q, r) = if j == i + 1 {
                    (pts[i], pts[j], pts[j + 1])
                } else {
                    (pts[j], pts[0], pts[1])
                };
                let (p, q, r) = (glam::DVec2::from(p), glam::DVec2::from(q), glam::DVec2::from(r));
                geometry::orient(p, q, r) == 0.0 && (p - q).dot(r - q) > 0.0
            } else {
                geometry::segments_touch(pts[i], pts[i + 1], pts[j], pts[j + 1])
            };
            if meets {
                return Some((j, i));
            }
        }
    }
    None
}

/// A small deterministic generator (no dependency, same numbers everywhere).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn ring_result(doc: &Document) -> Option<(usize, usize)> {
    match validate::document(doc) {
        Ok(()) => None,
        Err(e) => match e.defect.clone() {
            Defect::Curve(CurveDefect::SelfIntersecting(i)) => {
                let j = e
                    .path
                    .rsplit('[')
                    .next()
                    .unwrap()
                    .trim_end_matches(']')
                    .parse()
                    .unwrap();
                Some((j, i))
            }
            other => panic!("{e} ({other:?})"),
        },
    }
}

#[test]
fn the_curve_checks_find_what_checking_every_pair_finds() {
    let mut rng = Lcg(22);
    for case in 0..60 {
        // Wobbly rings of 3 to 300 vertices, some crossing themselves, some touching, some not.
        let k = 3 + (rng.unit() * 300.0) as usize;
        let wobble = [0.0, 0.3, 0.9][case % 3];
        let mut pts: Vec<Point> = (0..k)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / k as f64;
                let r = 15.0 * (1.0 - wobble * rng.unit());
                // Snap some points to a coarse lattice so exact touches and collinear runs occur.
                let p = [20.0 + r * t.cos(), 20.0 + r * t.sin()];
                if case % 4 == 0 { [p[0].round(), p[1].round()] } else { p }
            })
            .collect();
        pts.dedup();
        while pts.len() > 1 && pts.last() == pts.first() {
            pts.pop();
        }
        if pts.len() < 3 {
            continue;
        }
        pts.push(pts[0]);
        let doc = document(
            40,
            vec![Region {
                metric: None,
                boundary: pts.clone(),
                figures: vec![],
            }],
        );
        assert_eq!(ring_result(&doc), brute_ring(&pts), "case {case}");
    }
}

/// A circle of `n` vertices with a radial ripple: valid, and every segment short.
fn ripple(c: Point, r: f64, n: usize) -> Vec<Point> {
    let mut pts: Vec<Point> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            let rr = r * (1.0 + 0.01 * (t * 50.0).sin());
            [c[0] + rr * t.cos(), c[1] + rr * t.sin()]
        })
        .collect();
    pts.push(pts[0]);
    pts
}

#[test]
fn large_curves_are_checked_correctly() {
    // 40,000 vertices: quadratic checks took about 9.5 s here (0.6 s at 10,000); the figures for
    // 10k, 40k and 100k are in the criterion bench (`validate/ring`). Correctness is asserted.
    let n = 40_000;
    let boundary = ripple([500.0, 500.0], 450.0, n);
    let inner = ripple([500.0, 500.0], 300.0, n);
    let good = document(
        1000,
        vec![Region {
            metric: None,
            boundary: boundary.clone(),
            figures: vec![
                closed(inner.clone(), 30.0, 0.0, vec![]),
                penmodel_terrain::Figure {
                    kind: penmodel_terrain::FigureKind::Polyline,
                    points: ripple([500.0, 500.0], 400.0, n)[..n].to_vec(),
                    height: 10.0,
                    slope: 0.0,
                    figures: vec![],
                },
            ],
        }],
    );
    validate::document(&good).unwrap();

    // Swapping two neighbouring vertices makes the segments around them cross.
    let j = 31_337;
    let mut bad = good.clone();
    bad.regions[0].boundary.swap(j, j + 1);
    let e = validate::document(&bad).unwrap_err();
    assert_eq!(
        (e.path.as_str(), e.defect),
        (
            format!("regions[0].boundary[{}]", j + 1).as_str(),
            Defect::Curve(CurveDefect::SelfIntersecting(j - 1))
        )
    );

    // A polyline vertex pushed onto the boundary, and one beyond it, are found as a point check
    // against every edge finds them.
    for (k, scale, expect) in [(12_345usize, 1.0, Side::On), (23_456, 1.2, Side::Outside)] {
        let mut d = good.clone();
        let b = boundary[k];
        let f = &mut d.regions[0].figures[1];
        f.points[k] = if scale == 1.0 {
            b
        } else {
            [500.0 + (b[0] - 500.0) * scale, 500.0 + (b[1] - 500.0) * scale]
        };
        assert_eq!(geometry::locate(&boundary, f.points[k]), expect);
        let e = validate::document(&d).unwrap_err();
        assert_eq!(e.path, format!("regions[0].figures[1].points[{k}]"), "{e}");
        let want = match expect {
            Side::On => Defect::Figure(FigureDefect::OnRegionEdge("regions[0].boundary".into())),
            _ => Defect::Figure(FigureDefect::OutsideRegion("regions[0].boundary".into())),
        };
        assert_eq!(e.defect, want);
    }
}
