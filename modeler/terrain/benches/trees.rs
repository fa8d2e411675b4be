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
//! - `follow/<n>/512/{all,local}`: the editor's forest brought up to date after a change of the
//!   terrain on 512² cells of 2 m, with `n` trees (30 single ones; or with a grove of about
//!   5,000 more): `all` stands every tree again (what every edit did before the forest kept its
//!   trees in squares of the ground, with that index built), `local` only those over a change of
//!   64 × 64 cells ([`Forest::follow`] given the engine's changed rectangle).
//!
//! Run: `cargo bench -p penmodel-terrain --bench trees` (filter with e.g. `-- draw`).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DAffine3;
use penmodel_terrain::document::{Document, Grid, Grove, GroveSpecies, Sway, Tree, Wind};
use penmodel_terrain::trees::nodes::STOP;
use penmodel_terrain::trees::silhouette::{self, View};
use penmodel_terrain::trees::{Drawn, Forest, NodeTree, Preset, Species, fit, grove, wind};

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

/// 30 trees spread over a 512² grid of 2 m cells, and with `grove` a grove of about 5,000 trees
/// (a circle of 282 m at 200 trees per hectare) in the middle.
fn forest_scene(grove: bool) -> (Document, penmodel_terrain::Heightmap) {
    let n = 512u32;
    let mut doc = Document::new(Grid {
        cols: n,
        rows: n,
        cell_size: 2.0,
    });
    doc.trees = (0..30u32)
        .map(|k| Tree {
            at: [
                20.0 + 984.0 * f64::from(k % 6) / 5.0,
                20.0 + 984.0 * f64::from(k / 6) / 4.0,
            ],
            height: 12.0,
            preset: Some(Preset::ALL[k as usize % Preset::ALL.len()].name().to_owned()),
            maps: None,
            seed: u64::from(k),
            wind: None,
        })
        .collect();
    if grove {
        let region: Vec<[f64; 2]> = (0..=96)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k % 96) / 96.0;
                [512.0 + 282.0 * a.cos(), 512.0 + 282.0 * a.sin()]
            })
            .collect();
        doc.groves.push(Grove {
            region,
            density: 200.0,
            mix: vec![GroveSpecies {
                preset: "oak".into(),
                weight: 1.0,
            }],
            height: 10.0,
            seed: 2,
            wind: None,
        });
    }
    let hill = |x: f64, y: f64| (20.0 * (x / 37.0).sin() * (y / 53.0).cos()) as f32;
    let heights = (0..n * n).map(|i| hill(f64::from(i % n), f64::from(i / n))).collect();
    let map = penmodel_terrain::Heightmap::from_heights(n, n, 2.0, heights).expect("a 512² map");
    (doc, map)
}

fn follow(c: &mut Criterion) {
    let mut g = c.benchmark_group("trees");
    for with_grove in [false, true] {
        let (doc, map) = forest_scene(with_grove);
        let mut forest = Forest::of(&doc, &map);
        let n = forest.trees().len();
        println!("follow: {n} trees");
        g.bench_function(format!("follow/{n}/512/all"), |b| {
            b.iter(|| forest.follow(black_box(&doc), &map, None))
        });
        // A change of 64 × 64 cells in the grove's quarter.
        g.bench_function(format!("follow/{n}/512/local"), |b| {
            b.iter(|| forest.follow(black_box(&doc), &map, Some((200, 200, 64, 64))))
        });
    }
    g.finish();
}

criterion_group!(benches, trees, follow);
criterion_main!(benches);
