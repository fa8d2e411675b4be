//! Rivers (issue 13, seed 003). Targets: one iteration of a 40-control-point river on 1024²
//! ≤ 20 ms; the preview following a dragged control point ≤ 10 ms on 512².
//!
//! - `step/1024`: one iteration (erosion/deposition, migration, neck check, resampling, the
//!   nearest-sample field) of [`river::meander`] with 14 anchors (40 control points), 6 m wide,
//!   on 1024² cells.
//! - `preview/512/N`: what a drag costs: the river rebuilt from its entry (disc sweep, field, its
//!   N committed iterations) and the next iteration's erosion and deposition, 40 control points,
//!   4 m wide, on 512², for N = 0, 3 and 10: each committed iteration adds about a step.
//! - `drag/512/N`: the same drag's preview by `river::drag::Drag` (control point 20 of 40 moved
//!   6 m across, 4 m down): only the part of the course the point reaches is processed, the rest
//!   of the preview is the river's as grabbed.
//! - `carve/1024`: the carving of that river into flat ground.
//! - `morph/dilate|erode/L/1024`: the diamond of level L over a whole 1024² mask (the river's),
//!   the step `scripts/river_peer.py` times beside scipy.ndimage in one run.
//!
//! Run: `cargo bench -p penmodel-terrain --bench river`.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use penmodel_terrain::river::{self, Constants, Shape, carve, morph};
use penmodel_terrain::{Grid, Heightmap};

fn grid(n: u32) -> Grid {
    Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    }
}

fn bench(c: &mut Criterion) {
    let big = river::meander(1024, 14, 6.0, 1);
    assert_eq!(big.points.len(), 40);
    let shape = Shape::new(&big, &grid(1024), &Constants::default());
    c.bench_function("step/1024", |b| {
        b.iter_batched(
            || shape.clone(),
            |mut s| {
                s.step();
                s
            },
            criterion::BatchSize::LargeInput,
        )
    });
    for iterations in [0, 3, 10] {
        let small = river::meander(512, 14, 4.0, iterations);
        c.bench_with_input(BenchmarkId::new("preview/512", iterations), &small, |b, small| {
            b.iter(|| {
                let s = Shape::process(black_box(small), &grid(512), &Constants::default());
                s.preview()
            })
        });
    }
    for iterations in [0, 3, 10] {
        let small = river::meander(512, 14, 4.0, iterations);
        let drag = river::drag::Drag::new(&small, 20, &grid(512), &Constants::default());
        let mut moved = small.clone();
        moved.points[20] = [moved.points[20][0] + 6.0, moved.points[20][1] - 4.0];
        c.bench_with_input(BenchmarkId::new("drag/512", iterations), &moved, |b, moved| {
            b.iter(|| drag.preview(black_box(moved)))
        });
    }
    let ground = Heightmap::from_heights(1024, 1024, 1.0, vec![10.0; 1024 * 1024]).expect("1024² heights");
    c.bench_function("carve/1024", |b| {
        b.iter(|| carve::carve(&shape, big.width, big.depth, black_box(&ground)))
    });
    let (w, h) = (shape.window.width, shape.window.height);
    let mut g = c.benchmark_group("morph");
    for level in [2u8, 4, 6] {
        g.bench_with_input(BenchmarkId::new("dilate", level), &level, |b, &l| {
            b.iter(|| morph::dilate(black_box(&shape.mask), w, h, l))
        });
        g.bench_with_input(BenchmarkId::new("erode", level), &level, |b, &l| {
            b.iter(|| morph::erode(black_box(&shape.mask), w, h, l))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
