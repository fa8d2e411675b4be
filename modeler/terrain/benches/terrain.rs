//! Terrain generation figures (issue 6): full regeneration, a pull (one figure's height changes),
//! the start of a pull (first height change of another figure), a slope change and a moved
//! point, at 256², 512² and 1024² cells; beside the seed's repeat-until-stable method (full
//! regeneration with the sweeps of `tests/baseline.rs`) on the same documents. Each update is an
//! edit applied to the document and the terrain engine brought up to date with its scope, as the
//! editor does, without the editor's history.
//!
//! The document is example 1 (`examples/01-ridges-and-peaks.json`: one region over most of the
//! grid, eight control figures) on an N × N grid over the same 320 m square.
//!
//! Validation of large curves (issue 22): `validate/ring/N` checks one region whose boundary is
//! a rippled circle of N vertices (10k, 40k, 100k) with a closed figure of N vertices inside;
//! checking every pair of segments took 0.61 s at 10k and 9.5 s at 40k.
//!
//! Each figure also with Euclidean distances (issue 20): `full_euclidean/512`, `move_point_euclidean/512`, ….
//!
//! Run: `cargo bench -p penmodel-terrain --bench terrain` (filter with e.g. `-- pull/512`).

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use penmodel_terrain::{
    CurvePath, Document, Edit, Figure, FigureKind, FigurePath, Grid, Metric, Point, Rect, Region, TerrainEngine,
    generate, validate,
};

#[path = "../tests/baseline.rs"]
mod baseline;

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

/// A document and its terrain, edited as the editor does.
struct Model {
    doc: Document,
    terrain: TerrainEngine,
}

impl Model {
    fn edit(&mut self, edit: Edit) -> Rect {
        let applied = edit.apply_to(&mut self.doc).expect("the bench's edits are valid");
        self.terrain.update(&self.doc, &applied.scope)
    }
}

fn terrain(c: &mut Criterion) {
    let mut g = c.benchmark_group("terrain");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    let peak = FigurePath::new(0, 0);
    let other = FigurePath::new(0, 1);
    // Seed 000's taxicab distances (the example is a version 1 file) under the old names, and the
    // Euclidean ones (issue 20) with `_euclidean` after the name.
    for (suffix, metric) in [("", Metric::Taxicab), ("_euclidean", Metric::Euclidean)] {
        for n in SIZES {
            let mut doc = document(n);
            doc.terrain.metric = metric;
            let id = |name: &str| BenchmarkId::new(format!("{name}{suffix}"), n);
            g.bench_with_input(id("full"), &doc, |b, doc| b.iter(|| generate(black_box(doc))));

            let mut model = Model {
                terrain: TerrainEngine::new(&doc).expect("valid"),
                doc: doc.clone(),
            };
            let mut h = 60.0;
            g.bench_function(id("pull"), |b| {
                b.iter(|| {
                    h = if h == 60.0 { 61.0 } else { 60.0 };
                    model.edit(Edit::SetHeight {
                        at: black_box(peak.clone()),
                        height: h,
                    })
                })
            });

            let mut flip = false;
            g.bench_function(id("pull_start"), |b| {
                b.iter(|| {
                    // Alternating figures: each height change starts a new pull (rebuilds rest_k).
                    flip = !flip;
                    let (at, h) = if flip { (&peak, 60.5) } else { (&other, 45.5) };
                    model.edit(Edit::SetHeight {
                        at: black_box(at.clone()),
                        height: h,
                    })
                })
            });

            let mut s = -1.5;
            g.bench_function(id("slope"), |b| {
                b.iter(|| {
                    s = if s == -1.5 { -1.4 } else { -1.5 };
                    model.edit(Edit::SetSlope {
                        at: black_box(peak.clone()),
                        slope: s,
                    })
                })
            });

            let curve = CurvePath::Figure(FigurePath::new(0, 3));
            let mut x = 110.0;
            g.bench_function(id("move_point"), |b| {
                b.iter(|| {
                    x = if x == 110.0 { 112.0 } else { 110.0 };
                    model.edit(Edit::MovePoint {
                        curve: curve.clone(),
                        index: 1,
                        to: [x, 170.0],
                    })
                })
            });

            if metric == Metric::Taxicab {
                g.bench_with_input(BenchmarkId::new("seed_full", n), &doc, |b, doc| {
                    b.iter(|| baseline::generate(black_box(doc)))
                });
            }
        }
    }
    g.finish();
}

/// A circle of `n` vertices with a radial ripple, closed.
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

fn validation(c: &mut Criterion) {
    let mut g = c.benchmark_group("validate");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for n in [10_000usize, 40_000, 100_000] {
        let mut doc = Document::new(Grid {
            cols: 1000,
            rows: 1000,
            cell_size: 1.0,
        });
        doc.regions.push(Region {
            metric: None,
            boundary: ripple([500.0, 500.0], 450.0, n),
            figures: vec![Figure {
                kind: FigureKind::Closed,
                points: ripple([500.0, 500.0], 300.0, n),
                height: 30.0,
                slope: 0.0,
                figures: vec![],
            }],
        });
        g.bench_with_input(BenchmarkId::new("ring", n), &doc, |b, doc| {
            b.iter(|| validate::document(black_box(doc)).expect("valid"))
        });
    }
    g.finish();
}

criterion_group!(benches, terrain, validation);
criterion_main!(benches);
