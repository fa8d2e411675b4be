//! A grove of about 200 trees on a gentle terrain at 1280 × 720: one frame with every tree in
//! full and one with level of detail (Q by distance and gaze, seed 004), and the image difference
//! between them (mean absolute difference per RGB channel, 0–255, and PSNR), printed once.
//!
//! `cargo bench -p penmodel-render --bench trees`

use std::hint::black_box;
use std::sync::Arc;

use criterion::{Criterion, criterion_group, criterion_main};
use penmodel_render::{Camera, Frame, Renderer, Scene};
use penmodel_terrain::Heightmap;
use penmodel_terrain::document::{Grove, GroveSpecies};
use penmodel_terrain::trees::planted::turn;
use penmodel_terrain::trees::{NodeTree, Preset, Source, Species, Standing, grove};

/// 256² cells of 2 m: a gentle swell above sea level.
fn terrain() -> Heightmap {
    let n = 256u32;
    let heights = (0..n * n)
        .map(|i| {
            let (x, y) = (f64::from(i % n), f64::from(i / n));
            (12.0 + 4.0 * (x * 0.03).sin() + 3.0 * (y * 0.025).cos()) as f32
        })
        .collect();
    Heightmap::from_heights(n, n, 2.0, heights).expect("heights")
}

/// A mixed grove in a 140 m square (about 200 trees), standing on `map`.
fn grove_trees(map: &Heightmap) -> Vec<Standing> {
    let (x0, y0, side) = (186.0, 186.0, 140.0);
    let g = Grove {
        region: vec![
            [x0, y0],
            [x0 + side, y0],
            [x0 + side, y0 + side],
            [x0, y0 + side],
            [x0, y0],
        ],
        density: 100.0,
        mix: ["table-3.1", "cypress", "oak", "fir"]
            .iter()
            .map(|p| GroveSpecies {
                preset: p.to_string(),
                weight: 1.0,
            })
            .collect(),
        height: 12.0,
        seed: 4,
        wind: None,
    };
    let species: Vec<(Preset, Arc<NodeTree>)> = Preset::ALL
        .iter()
        .map(|&p| (p, Arc::new(NodeTree::build(&Species::preset(p)))))
        .collect();
    let ground = penmodel_terrain::rocks::place::ground(map);
    grove::trees(&g)
        .iter()
        .enumerate()
        .map(|(k, t)| Standing {
            source: Source::Grove(0, k),
            at: t.at,
            base: ground.height(t.at[0], t.at[1]),
            height: t.height,
            turn: turn(t.seed),
            nodes: Arc::clone(&species.iter().find(|(p, _)| *p == t.preset).expect("every preset").1),
            wind: None,
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let map = terrain();
    let trees = grove_trees(&map);
    let mut scene = Scene::new(
        &map,
        Camera::overview([512.0, 512.0], 20f64.to_radians(), 25f64.to_radians()),
    );
    if let penmodel_render::View::Orbit(o) = &mut scene.camera.view {
        o.distance *= 0.45;
    }
    scene.trees = &trees;
    let mut renderer = Renderer::new();
    let mut full = Frame::new(1280, 720).expect("frame");
    let mut lod = Frame::new(1280, 720).expect("frame");
    let lod_q = scene.tree_lod;
    scene.tree_lod = None;
    renderer.render(&scene, &mut full).expect("render");
    let sf = renderer.tree_stats();
    scene.tree_lod = lod_q;
    renderer.render(&scene, &mut lod).expect("render");
    let sl = renderer.tree_stats();
    let (mad, psnr) = full.difference(&lod).expect("frames of one size");
    println!(
        "trees {}: polygons full {} lod {} (copied {} + shapes {}), groups baked {}; image difference full vs lod: mean abs {mad:.3}/255 per channel, PSNR {psnr:.1} dB",
        sf.trees,
        sf.total_polygons(),
        sl.total_polygons(),
        sl.polygons,
        sl.impostors,
        sl.baked
    );
    if let Ok(dir) = std::env::var("TREES_BENCH_PNG") {
        let _ = penmodel_render::output::write_png(&full, &std::path::Path::new(&dir).join("grove_full.png"));
        let _ = penmodel_render::output::write_png(&lod, &std::path::Path::new(&dir).join("grove_lod.png"));
    }
    let mut group = c.benchmark_group("trees/grove");
    group.sample_size(20);
    for (name, q) in [("full", None), ("lod", lod_q)] {
        scene.tree_lod = q;
        let mut frame = Frame::new(1280, 720).expect("frame");
        group.bench_function(name, |b| {
            b.iter(|| renderer.render(black_box(&scene), &mut frame).expect("render"));
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
