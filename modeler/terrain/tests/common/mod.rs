//! Document builders and proptest strategies shared by the modeler's tests.
#![allow(dead_code)]

use std::f64::consts::PI;

use penmodel_terrain::{Document, Figure, FigureKind, Grid, Heightmap, Point, Region};
use proptest::prelude::*;

pub fn grid(n: u32) -> Grid {
    Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    }
}

/// A regular polygon (closed: first point repeated) of `k` vertices, radius `r`, around `c`.
pub fn polygon(c: Point, r: f64, k: usize, phase: f64) -> Vec<Point> {
    let mut pts: Vec<Point> = (0..k)
        .map(|i| {
            let t = phase + 2.0 * PI * i as f64 / k as f64;
            [c[0] + r * t.cos(), c[1] + r * t.sin()]
        })
        .collect();
    pts.push(pts[0]);
    pts
}

pub fn point(p: Point, height: f64, slope: f64) -> Figure {
    Figure {
        kind: FigureKind::Point,
        points: vec![p],
        height,
        slope,
        figures: vec![],
    }
}

pub fn polyline(points: Vec<Point>, height: f64, slope: f64) -> Figure {
    Figure {
        kind: FigureKind::Polyline,
        points,
        height,
        slope,
        figures: vec![],
    }
}

pub fn closed(points: Vec<Point>, height: f64, slope: f64, figures: Vec<Figure>) -> Figure {
    Figure {
        kind: FigureKind::Closed,
        points,
        height,
        slope,
        figures,
    }
}

pub fn document(n: u32, regions: Vec<Region>) -> Document {
    let mut d = Document::new(grid(n));
    d.regions = regions;
    d
}

/// Largest absolute height in a document, at least 1.
pub fn max_height(doc: &Document) -> f64 {
    fn walk(fs: &[Figure], m: &mut f64) {
        for f in fs {
            *m = m.max(f.height.abs());
            walk(&f.figures, m);
        }
    }
    let mut m = 1.0f64;
    for r in &doc.regions {
        walk(&r.figures, &mut m);
    }
    m
}

/// Most figures in one figure list of the document.
pub fn max_figures(doc: &Document) -> usize {
    fn walk(fs: &[Figure], m: &mut usize) {
        *m = (*m).max(fs.len());
        for f in fs {
            walk(&f.figures, m);
        }
    }
    let mut m = 0;
    for r in &doc.regions {
        walk(&r.figures, &mut m);
    }
    m
}

/// The first cell where two heightmaps differ by more than `tol`.
pub fn first_difference(a: &Heightmap, b: &Heightmap, tol: f32) -> Option<(u32, u32, f32, f32)> {
    let cols = a.cols();
    a.heights()
        .iter()
        .zip(b.heights())
        .enumerate()
        .find(|(_, (x, y))| (*x - *y).abs() > tol)
        .map(|(i, (x, y))| ((i % cols as usize) as u32, (i / cols as usize) as u32, *x, *y))
}

/// The first cell where two heightmaps differ in any bit: the terrain engine's updates equal a
/// full regeneration exactly (`engine/regions.rs`).
pub fn first_bit_difference(a: &Heightmap, b: &Heightmap) -> Option<(u32, u32, f32, f32)> {
    let cols = a.cols() as usize;
    assert_eq!(
        (a.cols(), a.rows()),
        (b.cols(), b.rows()),
        "heightmaps of different sizes"
    );
    a.heights()
        .iter()
        .zip(b.heights())
        .position(|(x, y)| x.to_bits() != y.to_bits())
        .map(|i| ((i % cols) as u32, (i / cols) as u32, a.heights()[i], b.heights()[i]))
}

/// A star-shaped region boundary around `c`: `k` vertices at evenly spaced angles with radii in
/// [0.7 R, R]. Everything within 0.5 R of `c` is strictly inside it (the nearest edge is at
/// least 0.7 R·cos(π/k) ≥ 0.6 R away for k ≥ 6).
pub fn star(c: Point, big_r: f64) -> impl Strategy<Value = Vec<Point>> {
    (6usize..10, 0.0..PI).prop_flat_map(move |(k, phase)| {
        prop::collection::vec(0.7..1.0f64, k).prop_map(move |radii| {
            let mut pts: Vec<Point> = radii
                .iter()
                .enumerate()
                .map(|(i, rr)| {
                    let t = phase + 2.0 * PI * i as f64 / k as f64;
                    [c[0] + big_r * rr * t.cos(), c[1] + big_r * rr * t.sin()]
                })
                .collect();
            pts.push(pts[0]);
            pts
        })
    })
}

/// A point within `r` of `c` (on a disc, so never on a curve around it at larger distance).
pub fn near(c: Point, r: f64) -> impl Strategy<Value = Point> {
    (0.0..r, 0.0..2.0 * PI).prop_map(move |(d, t)| [c[0] + d * t.cos(), c[1] + d * t.sin()])
}

pub fn height() -> impl Strategy<Value = f64> {
    prop_oneof![-60.0..60.0f64, Just(0.0)]
}

pub fn slope() -> impl Strategy<Value = f64> {
    prop_oneof![-4.0..4.0f64, Just(0.0)]
}

/// A point or polyline (2–3 points) figure within `r` of `c`.
pub fn open_figure(c: Point, r: f64) -> impl Strategy<Value = Figure> {
    (
        prop::collection::vec(near(c, r), 1..4),
        height(),
        slope(),
        any::<bool>(),
    )
        .prop_map(|(pts, h, s, as_point)| {
            if as_point || pts.len() == 1 {
                point(pts[0], h, s)
            } else {
                polyline(pts, h, s)
            }
        })
}

/// One region on an n × n grid (n = 40) with: open figures, and one closed figure (a regular
/// polygon) holding open figures of its own.
pub fn nested_document() -> impl Strategy<Value = Document> {
    let n = 40u32;
    let c = [20.0, 20.0];
    let big_r = 18.0;
    (
        star(c, big_r),
        (3.5..5.5f64, 5usize..9, 0.0..PI),
        near(c, 2.5),
        height(),
        slope(),
        prop::collection::vec(open_figure(c, 8.5), 0..3),
        prop::collection::vec(any::<u8>(), 0..3),
    )
        .prop_flat_map(move |(boundary, (rc, k, phase), kc, kh, ks, outer, inner_seeds)| {
            // Open figures of the parent must stay off the closed figure's disc? No: they may
            // cross it; the nested region then decides those cells.
            let inner_n = inner_seeds.len();
            prop::collection::vec(open_figure(kc, rc * 0.8 - 0.6), inner_n).prop_map(move |inner| {
                let kfig = closed(polygon(kc, rc, k, phase), kh, ks, inner);
                let mut figures = outer.clone();
                figures.push(kfig);
                document(
                    n,
                    vec![Region {
                        metric: None,
                        boundary: boundary.clone(),
                        figures,
                    }],
                )
            })
        })
}
