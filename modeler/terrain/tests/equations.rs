//! Hand-computed small grids for each rule of issue 6: rasterisation, dp, df, eq. 1–4.
//!
//! Every expected number is worked out in the comments from the rules, not taken from the code.

use penmodel_terrain::cells::{self, Mask};
use penmodel_terrain::distance::{self, UNREACHABLE};
use penmodel_terrain::{Document, Figure, FigureKind, Grid, Metric, Region, generate, profile};

const EPS: f32 = 1e-5;

fn grid(n: u32) -> Grid {
    Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    }
}

fn square(lo: f64, hi: f64) -> Vec<[f64; 2]> {
    vec![[lo, lo], [hi, lo], [hi, hi], [lo, hi], [lo, lo]]
}

fn point(x: f64, y: f64, height: f64, slope: f64) -> Figure {
    Figure {
        kind: FigureKind::Point,
        points: vec![[x, y]],
        height,
        slope,
        figures: vec![],
    }
}

/// A document with seed 000's taxicab distances, whose numbers these tests work out by hand.
fn doc(n: u32, regions: Vec<Region>) -> Document {
    let mut d = Document::new(grid(n));
    d.terrain.metric = Metric::Taxicab;
    d.regions = regions;
    d
}

/// The 7 × 7 square region of cells (0..=6, 0..=6) on an 8 × 8 grid: boundary through the
/// centres of the outer ring of cells.
fn square_region(figures: Vec<Figure>) -> Region {
    Region {
        metric: None,
        boundary: square(0.5, 6.5),
        figures,
    }
}

fn close(a: f32, b: f64) -> bool {
    (f64::from(a) - b).abs() <= f64::from(EPS) * b.abs().max(1.0)
}

#[track_caller]
fn assert_h(map: &penmodel_terrain::Heightmap, c: u32, r: u32, expected: f64) {
    let h = map.get(c, r);
    assert!(close(h, expected), "cell ({c}, {r}): got {h}, expected {expected}");
}

// ---- rasterisation ----

#[test]
fn point_is_its_cell() {
    let g = Grid {
        cols: 10,
        rows: 10,
        cell_size: 2.0,
    };
    // x/s = 1.5 → column 1; y/s = 4.0 lies on the line between rows 3 and 4 → row 4 (half-open).
    assert_eq!(cells::point_cell(&g, [3.0, 8.0]), (1, 4));
    assert_eq!(cells::point_cell(&g, [0.0, 0.0]), (0, 0));
    assert_eq!(cells::point_cell(&g, [19.99, 0.1]), (9, 0));
}

#[test]
fn segment_is_four_connected_supercover() {
    let g = grid(8);
    // (0.5, 0.5) → (3.5, 1.5): slope 1/3. It crosses x = 1 at y = 0.667 and x = 2 at y = 1.0
    // exactly — the grid corner (2, 1), with x and y both increasing: tie → step x first, so
    // (1,0) → (2,0) → (2,1), then x = 3 at y = 1.33 → (3,1).
    let mut cells = Vec::new();
    cells::segment_cells(&g, [0.5, 0.5], [3.5, 1.5], &mut cells);
    assert_eq!(cells, vec![(0, 0), (1, 0), (2, 0), (2, 1), (3, 1)]);
    // Drawn the other way round: the same cells.
    let mut back = Vec::new();
    cells::segment_cells(&g, [3.5, 1.5], [0.5, 0.5], &mut back);
    back.reverse();
    assert_eq!(back, cells);
}

#[test]
fn diagonal_through_corners_tie_rule() {
    let g = grid(8);
    // Exactly through corners (1, 1) and (2, 2): each corner adds the corner's column, row above
    // it in cell terms (X, Y−1): (1, 0) and (2, 1).
    let mut cells = Vec::new();
    cells::segment_cells(&g, [0.5, 0.5], [2.5, 2.5], &mut cells);
    assert_eq!(cells, vec![(0, 0), (1, 0), (1, 1), (2, 1), (2, 2)]);
    let mut back = Vec::new();
    cells::segment_cells(&g, [2.5, 2.5], [0.5, 0.5], &mut back);
    back.sort();
    cells.sort();
    assert_eq!(back, cells);
    // x increasing, y decreasing through corner (1, 2): the half-open corner point (1, 2) lies
    // in cell (1, 2), so the walk is (0,2) → (1,2) → (1,1): 4-connected without a tie cell.
    let mut anti = Vec::new();
    cells::segment_cells(&g, [0.5, 2.5], [1.5, 1.5], &mut anti);
    assert_eq!(anti, vec![(0, 2), (1, 2), (1, 1)]);
}

#[test]
fn closed_curve_is_boundary_plus_centres_inside() {
    let g = grid(8);
    // Triangle (0.5,0.5) (5.5,0.5) (0.5,5.5). Boundary: row 0 cols 0..=5, column 0 rows 0..=5,
    // and the hypotenuse x + y = 6, which passes exactly through the corners (5,1), (4,2), …,
    // (1,5). Walking from (5.5,0.5) with x decreasing and y increasing, each corner point lies
    // (half-open) in the cell below-right of it, so the walk is (5,0) (5,1) (4,1) (4,2) (3,2)
    // (3,3) (2,3) (2,4) (1,4) (1,5) (0,5): the cells with c + r = 5 and those with c + r = 6,
    // 1 ≤ c ≤ 5. Inside: centres (c + ½, r + ½) with c + r + 1 < 6, i.e. c + r ≤ 4.
    // Together: every (c, r) with c, r ≤ 5 and c + r ≤ 6.
    let m = cells::closed_mask(&g, &[[0.5, 0.5], [5.5, 0.5], [0.5, 5.5], [0.5, 0.5]]);
    let mut expected = Vec::new();
    for r in 0..=5u32 {
        for c in 0..=5u32 {
            if c + r <= 6 {
                expected.push((c, r));
            }
        }
    }
    let got: Vec<(u32, u32)> = m.cells().collect();
    assert_eq!(got, expected);
}

// ---- distances ----

fn mask_from_rows(rows: &[&str]) -> Mask {
    let mut cells = Vec::new();
    for (r, line) in rows.iter().enumerate() {
        for (c, ch) in line.chars().enumerate() {
            if ch != '.' {
                cells.push((c as u32, r as u32));
            }
        }
    }
    Mask::from_cells(&cells)
}

fn render(mask: &Mask, d: &[u32]) -> Vec<String> {
    (0..mask.height as usize)
        .map(|r| {
            (0..mask.width as usize)
                .map(|c| match d[r * mask.width as usize + c] {
                    UNREACHABLE => '.',
                    v => char::from_digit(v, 36).unwrap_or('?'),
                })
                .collect()
        })
        .collect()
}

#[test]
fn dp_goes_around_obstacles() {
    // A U-shaped region; the source at the bottom of the left arm. The right arm is reached only
    // around the bottom: distances count 4-neighbour steps inside the region.
    let m = mask_from_rows(&["x...x", "x...x", "xxxxx"]);
    let d = distance::from_sources(&m, &[(0, 0)]);
    assert_eq!(render(&m, &d), vec!["0...8", "1...7", "23456"]);
    assert_eq!(
        render(&m, &crate::baseline::from_sources(&m, &[(0, 0)])),
        render(&m, &d)
    );
}

#[test]
fn df_counts_layers_from_the_edge() {
    // 7 × 5 block: rings 0, 1, 2 from the edge. The notch at (3, 0) makes (3, 1) an edge cell
    // (a 4-neighbour outside), so (3, 2) is only one layer in.
    let m = mask_from_rows(&["xxx.xxx", "xxxxxxx", "xxxxxxx", "xxxxxxx", "xxxxxxx"]);
    let d = distance::edge_layers(&m);
    assert_eq!(
        render(&m, &d),
        vec!["000.000", "0110110", "0121210", "0111110", "0000000"]
    );
    assert_eq!(render(&m, &crate::baseline::edge_layers(&m)), render(&m, &d));
}

// ---- eq. 1 and eq. 2 ----

#[test]
fn weight_eq1() {
    assert_eq!(profile::weight(3, 0), 1.0);
    assert_eq!(profile::weight(0, 0), 1.0);
    assert_eq!(profile::weight(0, 5), 0.0);
    assert_eq!(profile::weight(1, 2), 1.0 / 3.0);
    assert_eq!(profile::weight(4, UNREACHABLE), 0.0);
}

#[test]
fn one_point_linear_and_both_slope_signs() {
    // 7 × 7 region, point at the centre cell (3, 3). df: 0 on the outer ring, 1, 2, 3 at the
    // centre. dp = |c − 3| + |r − 3|.
    //   (3,1): df 1, dp 2 → w = 1/3      (2,2): df 2, dp 2 → w = 1/2
    //   (1,1): df 1, dp 4 → w = 1/5      (2,3): df 2, dp 1 → w = 2/3
    //   (0,3): df 0 → w = 0              (3,3): on the figure → w = 1
    let cases: [((u32, u32), f64); 6] = [
        ((3, 1), 1.0 / 3.0),
        ((2, 2), 0.5),
        ((1, 1), 0.2),
        ((2, 3), 2.0 / 3.0),
        ((0, 3), 0.0),
        ((3, 3), 1.0),
    ];
    // s = 0: h = 30 w.  s = 1: h = 30 (1 − (1 − w)²).  s = −1: h = 30 w².
    for (s, f) in [
        (0.0, (|w: f64| 30.0 * w) as fn(f64) -> f64),
        (1.0, |w: f64| 30.0 * (1.0 - (1.0 - w) * (1.0 - w))),
        (-1.0, |w: f64| 30.0 * w * w),
    ] {
        let map = generate(&doc(8, vec![square_region(vec![point(3.5, 3.5, 30.0, s)])])).unwrap();
        for ((c, r), w) in cases {
            assert_h(&map, c, r, f(w));
        }
        // Outside the region (column 7, row 7): 0.
        assert_h(&map, 7, 3, 0.0);
        assert_h(&map, 3, 7, 0.0);
    }
    // Concretely, at (3, 1): 10, 16.667 (bell, above linear), 3.333 (sharp, below linear).
    let bell = generate(&doc(8, vec![square_region(vec![point(3.5, 3.5, 30.0, 1.0)])])).unwrap();
    assert_h(&bell, 3, 1, 50.0 / 3.0);
    let sharp = generate(&doc(8, vec![square_region(vec![point(3.5, 3.5, 30.0, -1.0)])])).unwrap();
    assert_h(&sharp, 3, 1, 10.0 / 3.0);
}

#[test]
fn negative_height_is_a_depression() {
    let map = generate(&doc(8, vec![square_region(vec![point(3.5, 3.5, -12.0, 0.0)])])).unwrap();
    assert_h(&map, 3, 3, -12.0);
    assert_h(&map, 2, 2, -6.0);
    assert_h(&map, 3, 0, 0.0);
}

// ---- eq. 3 ----

#[test]
fn two_points_inverse_distance_blend() {
    // Points A at cell (1, 3), height 10, and B at cell (5, 3), height 20, slope 0.
    //  (3,3): df 3, dpA 2, dpB 2 → wA = wB = 3/5 → hA = 6, hB = 12 → (6/2 + 12/2)/(1/2 + 1/2) = 9
    //  (2,3): df 2, dpA 1, dpB 3 → wA = 2/3, wB = 2/5 → hA = 20/3, hB = 8
    //         → (20/3 + 8/3)/(1 + 1/3) = 7
    //  (1,3): on A → 10.   (3,1): df 1, dpA 4, dpB 4 → w = 1/5 → hA 2, hB 4 → 3
    let map = generate(&doc(
        8,
        vec![square_region(vec![
            point(1.5, 3.5, 10.0, 0.0),
            point(5.5, 3.5, 20.0, 0.0),
        ])],
    ))
    .unwrap();
    assert_h(&map, 3, 3, 9.0);
    assert_h(&map, 2, 3, 7.0);
    assert_h(&map, 1, 3, 10.0);
    assert_h(&map, 5, 3, 20.0);
    assert_h(&map, 3, 1, 3.0);
}

#[test]
fn three_figures_and_the_on_figure_mean() {
    // A point (1,1) h 12, a point (5,5) h 6, a vertical polyline on column 3 from row 1 to 3
    // (cells (3,1) (3,2) (3,3)) h 30; all slope 0.
    //  (2,2): df 2; dpA = 2, dpB = 6, dpL = 1.  wA = 1/2, wB = 1/4, wL = 2/3.
    //         hA = 6, hB = 1.5, hL = 20. Σh/d = 3 + 0.25 + 20 = 23.25; Σ1/d = 1/2 + 1/6 + 1 = 5/3
    //         → 23.25 × 3/5 = 13.95
    //  (5,3): df 1; dpA = 6, dpB = 2, dpL = 2. wA = 1/7, wB = 1/3, wL = 1/3.
    //         hA = 12/7, hB = 2, hL = 10. Σh/d = 2/7 + 1 + 5 = 44/7; Σ1/d = 1/6 + 1/2 + 1/2 = 7/6
    //         → 44/7 × 6/7 = 264/49
    let figs = vec![
        point(1.5, 1.5, 12.0, 0.0),
        point(5.5, 5.5, 6.0, 0.0),
        Figure {
            kind: FigureKind::Polyline,
            points: vec![[3.5, 1.5], [3.5, 3.5]],
            height: 30.0,
            slope: 0.0,
            figures: vec![],
        },
    ];
    let map = generate(&doc(8, vec![square_region(figs.clone())])).unwrap();
    assert_h(&map, 2, 2, 13.95);
    assert_h(&map, 5, 3, 264.0 / 49.0);
    assert_h(&map, 3, 2, 30.0);

    // A cell on two figures takes their mean: a point at (3, 2), on the polyline, height 10
    // → (30 + 10)/2 = 20 there.
    let mut with_point = figs;
    with_point.push(point(3.5, 2.5, 10.0, 0.0));
    let map = generate(&doc(8, vec![square_region(with_point)])).unwrap();
    assert_h(&map, 3, 2, 20.0);
    assert_h(&map, 3, 1, 30.0);
    assert_eq!(profile::blend(&[(0, 30.0), (0, 10.0), (3, 99.0)]), 20.0);
    assert_eq!(profile::blend(&[(2, 6.0), (2, 12.0)]), 9.0);
    assert_eq!(profile::blend(&[(UNREACHABLE, 6.0)]), 0.0);
}

// ---- hierarchy and eq. 4 ----

#[test]
fn nested_region_stands_on_the_plateau() {
    // Region: the 11 × 11 cells (0..=10) of a 12 × 12 grid. Closed figure K: square through the
    // centres of cells 2..=8 (cells (2..=8, 2..=8)), height 10, slope s0 = 1. Nested in it a
    // point at (5, 5), height 25 (relief 15), slope s1 = 0.
    // Nested region: cells 2..=8; its df: 0 on its ring (2 or 8), 1, 2, 3 at (5,5).
    //  (5,3): df 1, dp 2 → w = 1/3 → eq. 4: s = (0 + 1)/3 − 1 = −2/3 (< 0, sharp)
    //         → relief 15 · (1/3)^(1 + 2/3) → height 10 + 15 · 3^(−5/3)
    //  (5,2): nested edge, w = 0 → height 10 (the plateau)
    //  (4,4): df 2, dp 2 → w = 1/2 → s = 1/2 − 1 = −1/2 → 10 + 15 · 0.5^1.5
    // Parent: K's cells are dp 0. (5,1): df 1, dp 1 → w = 1/2, s0 = 1 → 10 (1 − 0.5²) = 7.5.
    let k = Figure {
        kind: FigureKind::Closed,
        points: square(2.5, 8.5),
        height: 10.0,
        slope: 1.0,
        figures: vec![point(5.5, 5.5, 25.0, 0.0)],
    };
    let d = doc(
        12,
        vec![Region {
            metric: None,
            boundary: square(0.5, 10.5),
            figures: vec![k],
        }],
    );
    let map = generate(&d).unwrap();
    assert_h(&map, 5, 5, 25.0);
    assert_h(&map, 5, 3, 10.0 + 15.0 * 3f64.powf(-5.0 / 3.0));
    assert_h(&map, 5, 2, 10.0);
    assert_h(&map, 2, 2, 10.0);
    assert_h(&map, 4, 4, 10.0 + 15.0 * 0.5f64.powf(1.5));
    assert_h(&map, 5, 1, 7.5);
    assert_h(&map, 5, 0, 0.0);
    assert_eq!(profile::nested_slope(0.0, 1.0, 1.0 / 3.0), 1.0 / 3.0 - 1.0);
}

#[test]
fn nested_depression_in_a_plateau() {
    // As above but the nested point goes down to 4 (relief −6 below the plateau at 10), s1 = 0,
    // s0 = 0: eq. 4 gives s = 0 everywhere, so linear. (5,3): w = 1/3 → 10 − 6/3 = 8.
    let k = Figure {
        kind: FigureKind::Closed,
        points: square(2.5, 8.5),
        height: 10.0,
        slope: 0.0,
        figures: vec![point(5.5, 5.5, 4.0, 0.0)],
    };
    let d = doc(
        12,
        vec![Region {
            metric: None,
            boundary: square(0.5, 10.5),
            figures: vec![k],
        }],
    );
    let map = generate(&d).unwrap();
    assert_h(&map, 5, 5, 4.0);
    assert_h(&map, 5, 3, 8.0);
    assert_h(&map, 5, 2, 10.0);
}
