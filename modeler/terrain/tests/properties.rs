//! Properties of the terrain rules on random documents and grids.

use crate::baseline;
use crate::common;

use common::*;
use penmodel_terrain::cells::{self, Mask};
use penmodel_terrain::distance;
use penmodel_terrain::{FigureKind, Metric, Region, generate, profile};
use proptest::prelude::*;

/// A random set of cells in a w × h box, and some sources among them.
fn random_mask() -> impl Strategy<Value = (Mask, Vec<(u32, u32)>)> {
    (1u32..18, 1u32..18).prop_flat_map(|(w, h)| {
        (
            prop::collection::vec(prop::bool::weighted(0.7), (w * h) as usize),
            prop::collection::vec((0..w, 0..h), 0..4),
        )
            .prop_map(move |(bits, sources)| {
                let cells: Vec<(u32, u32)> = (0..w * h)
                    .filter(|&i| bits[i as usize])
                    .map(|i| (i % w + 3, i / w + 2))
                    .collect();
                let mask = Mask::from_cells(&cells);
                let sources = sources.into_iter().map(|(c, r)| (c + 3, r + 2)).collect();
                (mask, sources)
            })
    })
}

/// One region on a 24 × 24 grid with one figure of any kind.
fn single_figure_document() -> impl Strategy<Value = penmodel_terrain::Document> {
    let c = [12.0, 12.0];
    (
        star(c, 11.0),
        open_figure(c, 5.0),
        (1.5..4.0f64, 5usize..9),
        any::<bool>(),
    )
        .prop_map(move |(boundary, open, (rc, k), make_closed)| {
            let figure = if make_closed {
                closed(
                    polygon(open.points[0], rc * 0.4, k, 0.3),
                    open.height,
                    open.slope,
                    vec![],
                )
            } else {
                open
            };
            document(
                24,
                vec![Region {
                    metric: None,
                    boundary,
                    figures: vec![figure],
                }],
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The breadth-first maps equal the seed's repeat-until-stable sweeps, unreachable cells included.
    #[test]
    fn bfs_equals_seed_sweeps((mask, sources) in random_mask()) {
        prop_assert_eq!(distance::from_sources(&mask, &sources), baseline::from_sources(&mask, &sources));
        prop_assert_eq!(distance::edge_layers(&mask), baseline::edge_layers(&mask));
    }

    /// The Euclidean maps equal brute force: `dp` the smallest distance to a source in the region,
    /// `df` the smallest distance to a cell outside the region (the box's surroundings included)
    /// less one, each compared as the square root of the exact squared distance.
    #[test]
    fn euclidean_maps_equal_brute_force((mask, sources) in random_mask()) {
        let dp = penmodel_terrain::edt::from_sources(&mask, &sources);
        let df = penmodel_terrain::edt::to_edge(&mask);
        let (w, h) = (i64::from(mask.width), i64::from(mask.height));
        let inside = |x: i64, y: i64| (0..w).contains(&x) && (0..h).contains(&y) && mask.bits()[(y * w + x) as usize];
        let srcs: Vec<(i64, i64)> = sources
            .iter()
            .map(|&(c, r)| (i64::from(c) - i64::from(mask.c0), i64::from(r) - i64::from(mask.r0)))
            .filter(|&(x, y)| inside(x, y))
            .collect();
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if !inside(x, y) {
                    prop_assert!(dp[i].is_infinite() && df[i].is_infinite());
                    continue;
                }
                let near = srcs.iter().map(|&(sx, sy)| (sx - x).pow(2) + (sy - y).pow(2)).min();
                let want = near.map_or(f32::INFINITY, |d2| (d2 as f64).sqrt() as f32);
                prop_assert_eq!(dp[i], want, "dp at ({}, {})", x, y);
                // The nearest outside cell lies within the box and a one-cell border around it.
                let mut edge = i64::MAX;
                for oy in -1..=h {
                    for ox in -1..=w {
                        if !inside(ox, oy) {
                            edge = edge.min((ox - x).pow(2) + (oy - y).pow(2));
                        }
                    }
                }
                prop_assert_eq!(df[i], ((edge as f64).sqrt() - 1.0) as f32, "df at ({}, {})", x, y);
            }
        }
    }

    /// Every weight is in [0, 1], and so is eq. 2's share of the relief, for any slope.
    #[test]
    fn weights_and_shapes_in_unit_interval((mask, sources) in random_mask(), s in -50.0..50.0f64) {
        let df = distance::edge_layers(&mask);
        let dp = distance::from_sources(&mask, &sources);
        for i in 0..mask.box_len() {
            if mask.bits()[i] {
                let w = profile::weight(df[i], dp[i]);
                prop_assert!((0.0..=1.0).contains(&w), "w = {} at df {} dp {}", w, df[i], dp[i]);
                let f = profile::shape(w, s);
                prop_assert!((0.0..=1.0).contains(&f), "shape = {}", f);
                prop_assert_eq!(w == 1.0, dp[i] == 0);
            }
        }
    }

    /// One figure's terrain lies between min(0, H) and max(0, H), exactly: each cell is
    /// relief × coefficient with the coefficient in [0, 1].
    #[test]
    fn one_figure_stays_between_zero_and_its_height(doc in single_figure_document()) {
        let map = generate(&doc).unwrap();
        let h = doc.regions[0].figures[0].height as f32;
        let (lo, hi) = (h.min(0.0), h.max(0.0));
        for &v in map.heights() {
            prop_assert!(v >= lo && v <= hi, "height {} outside [{}, {}]", v, lo, hi);
        }
        // And the figure's own cells are at H.
        for (c, r) in cells::figure_cells(&doc.grid, &doc.regions[0].figures[0]) {
            prop_assert_eq!(map.get(c, r), h);
        }
    }

    /// With the breadth-first maps or the seed's sweeps, the terrain is the same to the bit.
    #[test]
    fn generation_equals_seed_method(mut doc in nested_document()) {
        doc.terrain.metric = Metric::Taxicab;
        prop_assert_eq!(generate(&doc).unwrap(), baseline::generate(&doc).unwrap());
    }

    /// Continuity across a nested region's edge. On a grid "continuous" means the nested region
    /// adds no step of its own: every cell on its edge (a 4-neighbour outside it) that is not on
    /// one of its figures has exactly the plateau height H of the closed figure, which is also the
    /// height the parent gives the closed figure's cells. The step to a parent cell p beside it is
    /// then the parent's own slope toward its figure: with the closed figure alone in the parent
    /// (p has dp = 1), |h(p) − H| = |H|·(1 − shape(df/(df + 1), s0)) ≤ |H|·max(1, 1 − s0)/(df(p) + 1).
    /// In either metric, with that metric's `df`.
    #[test]
    fn continuous_across_nested_edge(mut doc in nested_document(), euclidean in any::<bool>()) {
        let metric = if euclidean { Metric::Euclidean } else { Metric::Taxicab };
        doc.terrain.metric = metric;
        // The closed figure alone in the parent, for the bound on the parent's side.
        doc.regions[0].figures.retain(|f| f.kind == FigureKind::Closed);
        let map = generate(&doc).unwrap();
        let k = &doc.regions[0].figures[0];
        let nested = cells::closed_mask(&doc.grid, &k.points);
        let region = cells::closed_mask(&doc.grid, &doc.regions[0].boundary);
        let df = distance::edge_map(metric, &region);
        let on_inner: Vec<(u32, u32)> = k.figures.iter().flat_map(|f| cells::figure_cells(&doc.grid, f)).collect();
        let h_k = k.height as f32;
        let bound_factor = 1f64.max(1.0 - k.slope);
        for q in nested.cells() {
            let (c, r) = q;
            let outside: Vec<(u32, u32)> = [(c.wrapping_sub(1), r), (c + 1, r), (c, r.wrapping_sub(1)), (c, r + 1)]
                .into_iter()
                .filter(|&p| !nested.contains(p))
                .collect();
            if outside.is_empty() || on_inner.contains(&q) {
                continue;
            }
            prop_assert_eq!(map.get(c, r), h_k, "nested edge cell {:?}", q);
            for p in outside.into_iter().filter(|&p| region.contains(p)) {
                let dfp = df[region.index(p).unwrap()];
                prop_assert!(dfp.is_finite());
                let step = (f64::from(map.get(p.0, p.1)) - f64::from(h_k)).abs();
                let bound = f64::from(h_k).abs() * bound_factor / (f64::from(dfp) + 1.0);
                prop_assert!(step <= bound * (1.0 + 1e-6) + 1e-5, "step {} > bound {} between {:?} and {:?}", step, bound, p, q);
            }
        }
    }
}
