//! Terrain generation figures (issue 6): full regeneration, a pull (one figure's height changes),
//! the start of a pull (first height change of another figure), a slope change and a moved
//! point, at 256², 512² and 1024² cells; beside the seed's repeat-until-stable method (full
//! regeneration with the sweeps of `penmodel_terrain::baseline`) on the same documents.
//!
//! The document is example 1 (`examples/01-ridges-and-peaks.json`: one region over most of the
//! grid, eight control figures) on an N × N grid over the same 320 m square.
//!
//! Run: `cargo bench -p penmodel --bench terrain` (filter with e.g. `-- pull/512`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use penmodel_terrain::{CurvePath, Document, Edit, FigurePath, TerrainEngine, baseline, generate};

const SIZES: [u32; 3] = [256, 512, 1024];

fn document(n: u32) -> Document {
    let mut doc =
        Document::from_json(include_str!("../../examples/01-ridges-and-peaks.json")).expect("example 1 is valid");
    let extent = doc.grid.width();
    doc.grid.cols = n;
    doc.grid.rows = n;
    doc.grid.cell_size = extent / f64::from(n);
    doc
}

fn terrain(c: &mut Criterion) {
    let mut g = c.benchmark_group("terrain");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    let peak = FigurePath::new(0, 0);
    let other = FigurePath::new(0, 1);
    for n in SIZES {
        let doc = document(n);
        g.bench_with_input(BenchmarkId::new("full", n), &doc, |b, doc| {
            b.iter(|| generate(black_box(doc)))
        });

        let mut engine = TerrainEngine::new(doc.clone()).expect("valid");
        let mut h = 60.0;
        g.bench_function(BenchmarkId::new("pull", n), |b| {
            b.iter(|| {
                h = if h == 60.0 { 61.0 } else { 60.0 };
                engine.set_height(black_box(&peak), h)
            })
        });

        let mut flip = false;
        g.bench_function(BenchmarkId::new("pull_start", n), |b| {
            b.iter(|| {
                // Alternating figures: each height change starts a new pull (rebuilds rest_k).
                flip = !flip;
                let (at, h) = if flip { (&peak, 60.5) } else { (&other, 45.5) };
                engine.set_height(black_box(at), h)
            })
        });

        let mut s = -1.5;
        g.bench_function(BenchmarkId::new("slope", n), |b| {
            b.iter(|| {
                s = if s == -1.5 { -1.4 } else { -1.5 };
                engine.set_slope(black_box(&peak), s)
            })
        });

        let curve = CurvePath::Figure(FigurePath::new(0, 3));
        let mut x = 110.0;
        g.bench_function(BenchmarkId::new("move_point", n), |b| {
            b.iter(|| {
                x = if x == 110.0 { 112.0 } else { 110.0 };
                engine.apply(&Edit::MovePoint {
                    curve: curve.clone(),
                    index: 1,
                    to: [x, 170.0],
                })
            })
        });

        g.bench_with_input(BenchmarkId::new("seed_full", n), &doc, |b, doc| {
            b.iter(|| baseline::generate(black_box(doc)))
        });
    }
    g.finish();
}

criterion_group!(benches, terrain);
criterion_main!(benches);
