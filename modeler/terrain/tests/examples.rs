//! The seed's five modeling examples, rebuilt as documents in `modeler/examples/`, load and
//! generate.

use std::path::PathBuf;

use penmodel_terrain::{Document, Figure, FigureKind, cells, generate};

pub(crate) fn examples() -> Vec<(String, Document)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let doc = Document::load(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p.file_name().unwrap().to_string_lossy().into_owned(), doc)
        })
        .collect()
}

fn walk<'a>(fs: &'a [Figure], out: &mut Vec<&'a Figure>) {
    for f in fs {
        out.push(f);
        walk(&f.figures, out);
    }
}

#[test]
fn five_examples_with_the_seeds_figure_counts() {
    let docs = examples();
    assert_eq!(docs.len(), 5);
    // Table 2 of the thesis: input feature figures per example, generation regions included.
    let counts: Vec<usize> = docs
        .iter()
        .map(|(_, d)| {
            let mut figs = Vec::new();
            d.regions.iter().for_each(|r| walk(&r.figures, &mut figs));
            d.regions.len() + figs.len()
        })
        .collect();
    assert_eq!(counts, vec![9, 3, 9, 2, 11]);
}

#[test]
fn examples_generate() {
    for (name, doc) in examples() {
        let map = generate(&doc).unwrap();
        let mut figs = Vec::new();
        doc.regions.iter().for_each(|r| walk(&r.figures, &mut figs));
        // Every point figure stands at its height (no two figures share a cell in the examples).
        for f in figs.iter().filter(|f| f.kind == FigureKind::Point) {
            let (c, r) = cells::point_cell(&doc.grid, f.points[0]);
            assert_eq!(map.get(c, r), f.height as f32, "{name}: point at {:?}", f.points[0]);
        }
        // The terrain spans from 0 (outside the regions) to the highest figure; heights are
        // weighted means of reliefs, so nothing rises above it.
        let top = figs.iter().map(|f| f.height).fold(0.0, f64::max) as f32;
        assert_eq!(map.range(), (0.0, top), "{name}");
        // And the document survives a save and load unchanged.
        assert_eq!(Document::from_json(&doc.to_json()).unwrap(), doc, "{name}");
    }
}

/// The examples are version 1 files: they load with seed 000's taxicab distances, and their
/// terrain is the seed method's to the bit (saved again as version 4, they say so and stay so).
#[test]
fn older_versions_keep_taxicab_terrain_to_the_bit() {
    for (name, doc) in examples() {
        assert_eq!(doc.terrain.metric, penmodel_terrain::Metric::Taxicab, "{name}");
        let map = generate(&doc).unwrap();
        assert_eq!(map, crate::baseline::generate(&doc).unwrap(), "{name}");
        let again = Document::from_json(&doc.to_json()).unwrap();
        assert_eq!(again, doc, "{name}");
        assert_eq!(generate(&again).unwrap(), map, "{name}");
    }
}

/// A new document uses Euclidean distances: a point peak in a round region is a cone, its
/// height depending on the distance from the peak alone (to within a cell's rasterisation of the
/// boundary), where taxicab distances make a four-sided pyramid.
#[test]
fn a_new_document_makes_a_cone() {
    use penmodel_terrain::{Grid, Metric, Region};
    let mut doc = Document::new(Grid {
        cols: 101,
        rows: 101,
        cell_size: 1.0,
    });
    assert_eq!(doc.terrain.metric, Metric::Euclidean);
    let boundary: Vec<[f64; 2]> = (0..=64)
        .map(|i| {
            let t = std::f64::consts::TAU * f64::from(i % 64) / 64.0;
            [50.5 + 48.0 * t.cos(), 50.5 + 48.0 * t.sin()]
        })
        .collect();
    doc.regions.push(Region {
        boundary,
        figures: vec![Figure {
            kind: FigureKind::Point,
            points: vec![[50.5, 50.5]],
            height: 100.0,
            slope: 0.0,
            figures: vec![],
        }],
        metric: None,
    });
    // On a ring of cells 29.5 to 30.5 cells from the peak the heights spread by the ring's width
    // and the boundary's rasterisation only; with taxicab distances, whose rings are diamonds,
    // by much more.
    let spread = |doc: &Document| {
        let map = generate(doc).unwrap();
        let ring = (0..101u32)
            .flat_map(|r| (0..101u32).map(move |c| (c, r)))
            .filter(|&(c, r)| {
                let d = (f64::from(c) - 50.0).hypot(f64::from(r) - 50.0);
                (29.5..30.5).contains(&d)
            });
        let (lo, hi) = ring.fold((f32::MAX, f32::MIN), |(lo, hi), (c, r)| {
            let h = map.get(c, r);
            (lo.min(h), hi.max(h))
        });
        f64::from(hi - lo)
    };
    let euclidean = spread(&doc);
    doc.terrain.metric = Metric::Taxicab;
    let taxicab = spread(&doc);
    // Measured: 2.0 m (the ring's width of one cell on a slope of about 2 m a cell) and 5.8 m.
    assert!(
        euclidean < 0.5 * taxicab,
        "ring spread: euclidean {euclidean} m, taxicab {taxicab} m"
    );
}

/// Issue 47: the ridgeline example's flanks ran off the grid, leaving a 12.2 m wall at its edge
/// in every render and export. The land of every example comes down to the ground inside it.
#[test]
fn every_example_comes_down_to_the_ground_at_the_grids_edge() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut paths = vec![dir.join("ridges/ridgelines.json")];
    paths.extend(examples().into_iter().map(|(name, _)| dir.join(name)));
    for p in paths {
        let map = generate(&Document::load(&p).unwrap()).unwrap();
        let (cols, rows) = (map.cols(), map.rows());
        let edge = (0..cols)
            .flat_map(|c| [(c, 0), (c, rows - 1)])
            .chain((0..rows).flat_map(|r| [(0, r), (cols - 1, r)]))
            .map(|(c, r)| map.get(c, r))
            .fold(0.0f32, f32::max);
        assert!(edge < 0.01, "{}: {edge} m at the grid's edge", p.display());
    }
}
