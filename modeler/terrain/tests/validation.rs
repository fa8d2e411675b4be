//! Malformed documents: each problem is reported at the right element with the right reason.

use crate::common;

use common::*;
use penmodel_terrain::validate::{CurveDefect, FigureDefect, GridDefect};
use penmodel_terrain::{Defect, Document, LoadError, Region, validate};

fn base() -> Document {
    document(
        40,
        vec![Region {
            metric: None,
            boundary: polygon([20.0, 20.0], 15.0, 8, 0.1),
            figures: vec![
                point([14.2, 18.3], 30.0, -1.0),
                polyline(vec![[18.0, 18.0], [22.0, 19.0], [24.0, 25.0]], 12.0, 0.0),
                closed(
                    polygon([24.0, 14.0], 4.0, 6, 0.0),
                    12.0,
                    0.5,
                    vec![point([24.1, 14.2], 25.0, 0.0)],
                ),
            ],
        }],
    )
}

#[track_caller]
fn rejects(doc: &Document, path: &str, problem: impl Fn(&Defect) -> bool) {
    match validate::document(doc) {
        Ok(()) => panic!("accepted, expected an error at {path}"),
        Err(e) => {
            assert_eq!(e.path, path, "{e}");
            assert!(problem(&e.defect), "{e}");
            // The JSON loader reports the same error. JSON has no NaN or infinity: serde_json
            // writes them as null, which the loader refuses at the same element.
            match Document::from_json(&doc.to_json()) {
                Err(LoadError::Invalid(le)) => assert_eq!(le, e),
                Err(LoadError::Parse { path: p, message, .. }) if !doc_is_finite(&e.defect) => {
                    assert!(p.starts_with(&e.path), "{p} vs {}", e.path);
                    assert!(message.contains("null"), "{message}");
                }
                other => panic!("{other:?}"),
            }
        }
    }
}

fn doc_is_finite(problem: &Defect) -> bool {
    !matches!(problem, Defect::NotFinite | Defect::Grid(GridDefect::CellSize(_)))
}

#[test]
fn the_base_document_is_valid() {
    validate::document(&base()).unwrap();
}

#[test]
fn open_curves() {
    let mut d = base();
    d.regions[0].boundary.pop();
    rejects(&d, "regions[0].boundary", |p| {
        matches!(p, Defect::Curve(CurveDefect::OpenCurve { .. }))
    });
    let mut d = base();
    d.regions[0].figures[2].points.pop();
    rejects(&d, "regions[0].figures[2].points", |p| {
        matches!(p, Defect::Curve(CurveDefect::OpenCurve { .. }))
    });
}

#[test]
fn self_intersecting_curves() {
    // A bow tie: segment 2 (points[2] → points[3]) crosses segment 0.
    let mut d = base();
    d.regions[0].figures[2].points = vec![[21.0, 11.0], [27.0, 17.0], [27.0, 11.0], [21.0, 17.0], [21.0, 11.0]];
    d.regions[0].figures[2].figures.clear();
    rejects(&d, "regions[0].figures[2].points[2]", |p| {
        *p == Defect::Curve(CurveDefect::SelfIntersecting(0))
    });
    // A boundary doubling back on itself along a line.
    let mut d = base();
    d.regions[0].boundary = vec![[5.0, 5.0], [35.0, 5.0], [20.0, 5.0], [20.0, 35.0], [5.0, 5.0]];
    rejects(&d, "regions[0].boundary[1]", |p| {
        *p == Defect::Curve(CurveDefect::SelfIntersecting(0))
    });
}

#[test]
fn figures_outside_their_region() {
    let mut d = base();
    d.regions[0].figures[0].points[0] = [2.0, 2.0];
    rejects(&d, "regions[0].figures[0].points[0]", |p| {
        *p == Defect::Figure(FigureDefect::OutsideRegion("regions[0].boundary".into()))
    });
    // A nested figure outside its closed figure (but inside the region).
    let mut d = base();
    d.regions[0].figures[2].figures[0].points[0] = [20.0, 25.0];
    rejects(&d, "regions[0].figures[2].figures[0].points[0]", |p| {
        *p == Defect::Figure(FigureDefect::OutsideRegion("regions[0].figures[2].points".into()))
    });
    // A polyline whose points are inside but whose segment leaves the region: a square region
    // with a notch, the segment jumping across the notch.
    let mut d = base();
    d.regions[0].boundary = vec![
        [5.0, 5.0],
        [35.0, 5.0],
        [35.0, 35.0],
        [20.5, 35.0],
        [20.0, 12.0],
        [19.5, 35.0],
        [5.0, 35.0],
        [5.0, 5.0],
    ];
    d.regions[0].figures = vec![polyline(vec![[10.0, 30.0], [30.0, 30.0]], 5.0, 0.0)];
    rejects(&d, "regions[0].figures[0].points[1]", |p| {
        *p == Defect::Figure(FigureDefect::CrossesRegionEdge("regions[0].boundary".into()))
    });
}

#[test]
fn overlapping_regions() {
    let mut d = base();
    d.regions.push(Region {
        metric: None,
        boundary: polygon([36.0, 20.0], 3.5, 6, 0.0),
        figures: vec![],
    });
    rejects(
        &d,
        "regions[1]",
        |p| matches!(p, Defect::Figure(FigureDefect::Overlap { other, .. }) if other == "regions[0]"),
    );
    // Closer than a cell without touching still overlaps on the grid: x = 35.1 and x = 35.4
    // both fall in column 35.
    let mut d = document(40, vec![]);
    d.regions.push(Region {
        metric: None,
        boundary: vec![[1.0, 1.0], [35.1, 1.0], [35.1, 20.0], [1.0, 20.0], [1.0, 1.0]],
        figures: vec![],
    });
    d.regions.push(Region {
        metric: None,
        boundary: vec![[35.4, 1.0], [39.0, 1.0], [39.0, 20.0], [35.4, 20.0], [35.4, 1.0]],
        figures: vec![],
    });
    rejects(&d, "regions[1]", |p| {
        *p == Defect::Figure(FigureDefect::Overlap {
            other: "regions[0]".into(),
            cell: (35, 1),
        })
    });
    // Sibling closed figures bound nested regions: they must not overlap either.
    let mut d = base();
    d.regions[0]
        .figures
        .push(closed(polygon([27.0, 15.0], 3.0, 5, 0.0), 5.0, 0.0, vec![]));
    rejects(
        &d,
        "regions[0].figures[3]",
        |p| matches!(p, Defect::Figure(FigureDefect::Overlap { other, .. }) if other == "regions[0].figures[2]"),
    );
}

#[test]
fn non_finite_numbers() {
    let mut d = base();
    d.regions[0].figures[1].slope = f64::INFINITY;
    rejects(&d, "regions[0].figures[1].slope", |p| *p == Defect::NotFinite);
    let mut d = base();
    d.regions[0].figures[2].figures[0].height = f64::NAN;
    rejects(&d, "regions[0].figures[2].figures[0].height", |p| {
        *p == Defect::NotFinite
    });
    let mut d = base();
    d.regions[0].figures[1].points[2] = [f64::NAN, 3.0];
    rejects(&d, "regions[0].figures[1].points[2]", |p| *p == Defect::NotFinite);
    let mut d = base();
    d.grid.cell_size = f64::NAN;
    rejects(&d, "grid.cell_size", |p| {
        matches!(p, Defect::Grid(GridDefect::CellSize(_)))
    });
}

#[test]
fn grids() {
    let mut d = base();
    d.grid.cols = 100_000;
    d.grid.rows = 100_000;
    rejects(&d, "grid", |p| {
        *p == Defect::Grid(GridDefect::GridTooLarge {
            cells: 10_000_000_000,
            max: validate::MAX_CELLS,
        })
    });
    let mut d = base();
    d.grid.rows = 0;
    rejects(&d, "grid", |p| *p == Defect::Grid(GridDefect::EmptyGrid));
    let mut d = base();
    d.grid.cols = 30; // the region reaches x = 35
    rejects(&d, "regions[0].boundary[0]", |p| {
        matches!(p, Defect::Curve(CurveDefect::OutsideGrid { .. }))
    });
}

#[test]
fn figure_shapes() {
    let mut d = base();
    d.regions[0].figures[0].points.push([15.0, 18.0]);
    rejects(&d, "regions[0].figures[0].points", |p| {
        *p == Defect::Figure(FigureDefect::PointCount(2))
    });
    let mut d = base();
    d.regions[0].figures[1].points.truncate(1);
    rejects(&d, "regions[0].figures[1].points", |p| {
        *p == Defect::Figure(FigureDefect::PolylineTooShort(1))
    });
    let mut d = base();
    d.regions[0].figures[1].points[1] = d.regions[0].figures[1].points[0];
    rejects(&d, "regions[0].figures[1].points[1]", |p| {
        *p == Defect::Curve(CurveDefect::RepeatedPoint)
    });
    let mut d = base();
    d.regions[0].figures[2].points = vec![[22.0, 12.0], [25.0, 12.0], [22.0, 12.0]];
    d.regions[0].figures[2].figures.clear();
    rejects(&d, "regions[0].figures[2].points", |p| {
        *p == Defect::Curve(CurveDefect::CurveTooShort(2))
    });
    let mut d = base();
    d.regions[0].figures[1].figures.push(point([20.0, 20.0], 1.0, 0.0));
    rejects(&d, "regions[0].figures[1].figures", |p| {
        *p == Defect::Figure(FigureDefect::NestedInOpenFigure("polyline"))
    });
}

#[test]
fn json_errors_name_the_element() {
    let text = base().to_json().replacen("\"height\": 30.0", "\"height\": \"high\"", 1);
    match Document::from_json(&text) {
        Err(LoadError::Parse {
            path, message, line, ..
        }) => {
            assert_eq!(path, "regions[0].figures[0].height");
            assert!(message.contains("invalid type: string \"high\""), "{message}");
            assert!(line > 1);
        }
        other => panic!("{other:?}"),
    }
    let text = base()
        .to_json()
        .replacen("\"slope\": -1.0", "\"slope\": -1.0, \"colour\": 3", 1);
    match Document::from_json(&text) {
        Err(LoadError::Parse { path, message, .. }) => {
            assert_eq!(path, "regions[0].figures[0].colour");
            assert!(message.contains("unknown field `colour`"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let (current, next) = (
        penmodel_terrain::document::VERSION,
        penmodel_terrain::document::VERSION + 1,
    );
    let text = base()
        .to_json()
        .replacen(&format!("\"version\": {current}"), &format!("\"version\": {next}"), 1);
    match Document::from_json(&text) {
        Err(LoadError::Invalid(e)) => {
            assert_eq!(
                (e.path.as_str(), e.defect),
                ("version", Defect::Version(next.to_string()))
            )
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        Document::from_json("{\"version\": 1, \"grid\": "),
        Err(LoadError::Parse { .. })
    ));
}

#[test]
fn save_load_round_trip_is_exact() {
    let mut d = base();
    d.note = Some("round trip".into());
    // Numbers whose shortest decimal form needs all 17 digits.
    d.regions[0].figures[0].height = 0.1 + 0.2;
    d.regions[0].figures[0].slope = -1.0 / 3.0;
    d.regions[0].figures[1].points[0] = [18.000000000000004, 17.999999999999996];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.json");
    d.save(&path).unwrap();
    assert_eq!(Document::load(&path).unwrap(), d);
    // Atomic save leaves no temporary file behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("d.json")]);
    // And an invalid document is not written at all.
    let mut bad = d.clone();
    bad.regions[0].figures[0].height = f64::NAN;
    assert!(bad.save(&path).is_err());
    assert_eq!(Document::load(&path).unwrap(), d);
}
