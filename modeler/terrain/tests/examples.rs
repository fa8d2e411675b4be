//! The seed's five modeling examples, rebuilt as documents in `modeler/examples/`, load and
//! generate.

use std::path::PathBuf;

use penmodel_terrain::{Document, Figure, FigureKind, cells, generate};

fn examples() -> Vec<(String, Document)> {
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
