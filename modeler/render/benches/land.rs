//! The land look's maps (`penmodel_render::land::Land::prepare`) of a 512² terrain (320 m, two
//! regions: one over most of the grid, one of 40 m across in a corner), per frame:
//!
//! - `still`: an unchanged terrain, the scene carrying the editor's revisions;
//! - `still_compared`: the same without revisions (the heights compared with a copy);
//! - `local`: after a move of the small region's figure (its box, about 70² cells, changed);
//! - `region`: after a pull of the large region's figure (most of the grid changed);
//! - `fresh`: the maps made from nothing (what every remake cost before they followed the
//!   changed rectangle: the light was remade everywhere).
//!
//! Every edit is applied outside the timed part; the maps are remade for each (light lag 0).
//!
//! `cargo bench -p penmodel-render --bench land`

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use penmodel_render::land::Land;
use penmodel_render::{Camera, Scene, Style};
use penmodel_terrain::{Document, Edit, Editor, Figure, FigureKind, FigurePath, Grid, Region};

fn document() -> Document {
    let square = |x0: f64, y0: f64, x1: f64, y1: f64| vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]];
    let point = |x: f64, y: f64, height: f64| Figure {
        kind: FigureKind::Point,
        points: vec![[x, y]],
        height,
        slope: 0.0,
        figures: Vec::new(),
    };
    let mut doc = Document::new(Grid {
        cols: 512,
        rows: 512,
        cell_size: 0.625,
    });
    doc.regions.push(Region {
        boundary: square(5.0, 5.0, 250.0, 300.0),
        figures: vec![
            point(80.0, 90.0, 60.0),
            point(180.0, 200.0, 45.0),
            point(120.0, 250.0, 30.0),
        ],
        metric: None,
    });
    doc.regions.push(Region {
        boundary: square(265.0, 20.0, 305.0, 60.0),
        figures: vec![point(285.0, 40.0, 20.0)],
        metric: None,
    });
    doc
}

fn scene<'a>(editor: &'a Editor, style: &Style, revisions: bool) -> Scene<'a> {
    let mut s = Scene::new(editor.heightmap(), Camera::overview([320.0, 320.0], 0.5, 0.6));
    s.style = style.clone();
    s.revisions = revisions.then(|| editor.revisions());
    s
}

fn bench(c: &mut Criterion) {
    let mut editor = Editor::new(document()).expect("a valid document");
    let style = Style {
        light_lag: 0,
        ..Style::land()
    };
    let mut light = Vec::new();
    let mut g = c.benchmark_group("land_maps_512");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    for (name, revisions) in [("still", true), ("still_compared", false)] {
        let mut land = Land::default();
        land.prepare(&scene(&editor, &style, revisions), &mut light);
        g.bench_function(name, |b| {
            b.iter(|| black_box(land.prepare(&scene(&editor, &style, revisions), &mut light)))
        });
    }
    // Edits back and forth, each followed by a timed remake.
    let mut edited = |name: &str, at: FigurePath, by: [f64; 2], height: Option<f64>| {
        let mut land = Land::default();
        land.prepare(&scene(&editor, &style, true), &mut light);
        let mut step = 0u32;
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut spent = Duration::ZERO;
                for _ in 0..iters {
                    step += 1;
                    let sign = if step.is_multiple_of(2) { -1.0 } else { 1.0 };
                    let edit = match height {
                        Some(h) => Edit::SetHeight {
                            at: at.clone(),
                            height: h + sign,
                        },
                        None => Edit::MoveFigure {
                            at: at.clone(),
                            by: [by[0] * sign, by[1] * sign],
                        },
                    };
                    editor.apply(edit).expect("the edit applies");
                    let t = Instant::now();
                    black_box(land.prepare(&scene(&editor, &style, true), &mut light));
                    spent += t.elapsed();
                }
                spent
            })
        });
    };
    edited("local", FigurePath::new(1, 0), [2.0, 1.0], None);
    edited("region", FigurePath::new(0, 0), [0.0; 2], Some(60.0));
    g.bench_function("fresh", |b| {
        let mut land = Land::default();
        b.iter(|| {
            land.forget();
            black_box(land.prepare(&scene(&editor, &style, true), &mut light))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
