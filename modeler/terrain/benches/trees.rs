//! Fractal trees (issue 14, seed 004):
//!
//! - `build/<preset>`: the full fractal computation — every composition of maps down to 2 % of
//!   the height, with its geometry ([`NodeTree::build`]); the seed's "fractal computation" of a
//!   tree at Q = 0.02 (280 ms on its machine).
//! - `draw/<preset>/q<Q>`: the multiplexed LOD walk of the precomputed tree at roughness Q,
//!   copying geometry into a reused buffer (the seed: 40 ms at Q = 0.02); at 0.02 it is the
//!   whole tree, as the build, so the two compare the same output.
//! - `draw_wind/table-3.1/q0.02`: the same walk with every generation swaying.
//! - `grove/r50/200ha`: a grove's trees (Poisson-disk positions, presets, heights) in a circle
//!   of 50 m at 200 trees per hectare (about 157 trees).
//!
//! - `fit/render/table-3.1`: one candidate silhouette of the fit (the tree to scale 0.05,
//!   rasterised on 64 × 64, blurred), the unit of its cost. Printed before the runs: the fit on
//!   silhouettes (128 px) of each preset nudged by 1.5 fit steps per parameter with 2 % of the
//!   pixels flipped — the correlations it starts from and reaches in 30 steps, and its time.
//!
//! Run: `cargo bench -p penmodel-terrain --bench trees` (filter with e.g. `-- draw`).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DAffine3;
use penmodel_terrain::document::{Grove, GroveSpecies, Sway, Wind};
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::silhouette::{self, View};
use penmodel_terrain::trees::{Drawn, NodeTree, Preset, Species, fit, grove, wind};

fn clear(d: &mut Drawn) {
    d.mesh.positions.clear();
    d.mesh.normals.clear();
    d.mesh.colors.clear();
    d.mesh.indices.clear();
    d.impostors.clear();
    d.nodes = 0;
    d.polygons = 0;
    d.leaves = 0;
}

/// The fit's experiment: printed, not timed by criterion (a fit takes seconds).
fn fit_experiment() {
    for (k, p) in Preset::ALL.into_iter().enumerate() {
        let seed = 11 + k as u64;
        let truth = fit::nudged(&Species::preset(p), 1.5, seed);
        let front = fit::speckled(&silhouette::render(&truth, View::Front, 128, STOP), 0.02, seed);
        let side = fit::speckled(&silhouette::render(&truth, View::Side, 128, STOP), 0.02, seed + 1);
        let t = std::time::Instant::now();
        match fit::fit(&front, &side, fit::Options::default()) {
            Ok(f) => println!(
                "fit {}: from {} {:.3}/{:.3} to {:.3}/{:.3} (front/side) in {} steps, {:.1} s",
                p.name(),
                f.preset.name(),
                f.start[0],
                f.start[1],
                f.reached[0],
                f.reached[1],
                f.iterations,
                t.elapsed().as_secs_f64()
            ),
            Err(e) => println!("fit {}: {e}", p.name()),
        }
    }
}

fn trees(c: &mut Criterion) {
    fit_experiment();
    let mut g = c.benchmark_group("trees");
    let table = Species::preset(Preset::Table31);
    g.bench_function("fit/render/table-3.1", |b| {
        b.iter(|| black_box(silhouette::render(&table, View::Front, fit::SIZE, fit::FIT_STOP).blurred(2)))
    });
    for p in [Preset::Table31, Preset::Fir] {
        let s = Species::preset(p);
        g.bench_function(format!("build/{}", p.name()), |b| {
            b.iter(|| black_box(NodeTree::build(&s)))
        });
        let tree = NodeTree::build(&s);
        let mut out = Drawn::default();
        for q in [0.02, 0.05, 0.1] {
            g.bench_function(format!("draw/{}/q{q}", p.name()), |b| {
                b.iter(|| {
                    clear(&mut out);
                    tree.draw(black_box(q), &DAffine3::IDENTITY, None, &mut out);
                    black_box(out.mesh.positions.len())
                })
            });
        }
    }
    let tree = NodeTree::build(&Species::preset(Preset::Table31));
    let gusty = Wind {
        direction: 30.0,
        generations: vec![
            Sway {
                amplitude: 2.0,
                frequency: 0.3,
                rest: 0.0,
            },
            Sway {
                amplitude: 5.0,
                frequency: 0.7,
                rest: 0.0,
            },
            Sway {
                amplitude: 9.0,
                frequency: 1.3,
                rest: 0.0,
            },
        ],
    };
    let pose = wind::pose(&gusty, 0.4);
    let mut out = Drawn::default();
    g.bench_function("draw_wind/table-3.1/q0.02", |b| {
        b.iter(|| {
            clear(&mut out);
            tree.draw(0.02, &DAffine3::IDENTITY, Some(&pose), &mut out);
            black_box(out.mesh.positions.len())
        })
    });
    let region: Vec<[f64; 2]> = (0..=64)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k % 64) / 64.0;
            [100.0 + 50.0 * a.cos(), 100.0 + 50.0 * a.sin()]
        })
        .collect();
    let gr = Grove {
        region,
        density: 200.0,
        mix: vec![
            GroveSpecies {
                preset: "oak".into(),
                weight: 2.0,
            },
            GroveSpecies {
                preset: "fir".into(),
                weight: 1.0,
            },
        ],
        height: 10.0,
        seed: 1,
        wind: None,
    };
    g.bench_function("grove/r50/200ha", |b| b.iter(|| black_box(grove::trees(&gr))));
    g.finish();
}

criterion_group!(benches, trees);
criterion_main!(benches);
