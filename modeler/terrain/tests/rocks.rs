//! The rock field (seed 001): each property checked by a computation of the test's own — brute
//! force nearest seeds, pairwise distances, circumcircles — not by the code under test.

use penmodel_terrain::rocks::{Amount, Layer, Recipe, RecipeError, Sampler, Scatter, Shape, scatter};

/// A small fig. 1-like field: quick in a debug build, every stage exercised.
fn recipe(seed: u64) -> Recipe {
    let mut r = Recipe::figure_1(96, 80, seed);
    r.layers[0].radius = 7.0;
    r.layers[1].radius = 3.0;
    r.layers[2].radius = 1.5;
    r
}

/// Pixel → index of the nearest seed (lowest index on a tie), by scanning seeds sorted by x.
fn nearest(width: u32, height: u32, seeds: &[[f64; 2]]) -> Vec<u32> {
    let mut by_x: Vec<u32> = (0..seeds.len() as u32).collect();
    by_x.sort_by(|&a, &b| seeds[a as usize][0].total_cmp(&seeds[b as usize][0]));
    let xs: Vec<f64> = by_x.iter().map(|&i| seeds[i as usize][0]).collect();
    let mut out = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let q = [f64::from(x) + 0.5, f64::from(y) + 0.5];
            let mut best = (f64::INFINITY, u32::MAX);
            let start = xs.partition_point(|&sx| sx < q[0]);
            let consider = |k: usize, best: &mut (f64, u32)| {
                let i = by_x[k];
                let s = seeds[i as usize];
                let d = (s[0] - q[0]).powi(2) + (s[1] - q[1]).powi(2);
                if d < best.0 || (d == best.0 && i < best.1) {
                    *best = (d, i);
                }
            };
            for (k, &sx) in xs.iter().enumerate().skip(start) {
                if (sx - q[0]).powi(2) > best.0 {
                    break;
                }
                consider(k, &mut best);
            }
            for (k, &sx) in xs.iter().enumerate().take(start).rev() {
                if (sx - q[0]).powi(2) > best.0 {
                    break;
                }
                consider(k, &mut best);
            }
            out.push(best.1);
        }
    }
    out
}

fn run(r: &Recipe) -> Scatter {
    scatter(r, None).expect("a valid recipe")
}

#[test]
fn no_two_seeds_of_a_diagram_are_within_its_radius_and_every_pixel_is_near_one() {
    for sampler in [Sampler::Saturate, Sampler::Darts { fill: 0.7 }] {
        let mut r = recipe(3);
        r.sampler = sampler;
        let s = run(&r);
        for d in &s.diagrams {
            let mut pts = d.seeds.clone();
            pts.sort_by(|a, b| a[0].total_cmp(&b[0]));
            for i in 0..pts.len() {
                for j in i + 1..pts.len() {
                    if pts[j][0] - pts[i][0] > d.radius {
                        break;
                    }
                    let dist = ((pts[j][0] - pts[i][0]).powi(2) + (pts[j][1] - pts[i][1]).powi(2)).sqrt();
                    assert!(
                        dist > d.radius,
                        "r = {}: seeds {:?} and {:?} are {dist} apart",
                        d.radius,
                        pts[i],
                        pts[j]
                    );
                }
            }
            if sampler == Sampler::Saturate {
                // Maximal: no pixel centre is farther than r from every seed (else it would have been kept).
                let owner = nearest(s.width, s.height, &d.seeds);
                for (p, &o) in owner.iter().enumerate() {
                    let q = [(p % s.width as usize) as f64 + 0.5, (p / s.width as usize) as f64 + 0.5];
                    let sd = d.seeds[o as usize];
                    let dist = ((sd[0] - q[0]).powi(2) + (sd[1] - q[1]).powi(2)).sqrt();
                    assert!(
                        dist <= d.radius,
                        "pixel {q:?} is {dist} from the nearest seed, r = {}",
                        d.radius
                    );
                }
            }
        }
    }
}

/// The pixels of every kept cell, by brute-force nearest seeds; panics if a pixel is in two.
fn kept_pixels(s: &Scatter) -> Vec<Vec<u32>> {
    let mut owner = vec![None; s.width as usize * s.height as usize];
    let mut per_diagram = vec![Vec::new(); s.diagrams.len()];
    for (di, d) in s.diagrams.iter().enumerate() {
        let labels = nearest(s.width, s.height, &d.seeds);
        let kept: std::collections::HashSet<u32> = d.cells.iter().copied().collect();
        for (p, l) in labels.iter().enumerate() {
            if kept.contains(l) {
                if let Some((od, oc)) = owner[p] {
                    panic!("pixel {p} is in cell {oc} of diagram {od} and cell {l} of diagram {di}");
                }
                owner[p] = Some((di, *l));
                per_diagram[di].push(p as u32);
            }
        }
    }
    per_diagram
}

#[test]
fn kept_cells_share_no_pixel_and_reach_their_area_fractions() {
    for seed in [1, 2] {
        let r = recipe(seed);
        let s = run(&r);
        let pixels = kept_pixels(&s);
        let field = f64::from(s.width * s.height);
        assert_eq!(s.field_pixels as f64, field);
        for (i, d) in s.diagrams.iter().enumerate() {
            assert_eq!(pixels[i].len(), d.pixels, "diagram {i}: the pixels it reports");
            let Amount::Fraction(target) = r.layers[i].amount else {
                unreachable!()
            };
            let goal = (target * field).ceil() as usize;
            let got = pixels[i].len();
            if d.reached {
                assert!(got >= goal, "diagram {i}: {got} pixels, the goal {goal}");
            } else {
                assert!(got < goal);
                assert_eq!(
                    d.tried,
                    d.seeds.len(),
                    "diagram {i} stopped short with cells left to try"
                );
            }
            // It stopped as soon as it got there: without its last cell it was short.
            if let Some(&last) = d.cells.last() {
                let labels = nearest(s.width, s.height, &d.seeds);
                let last_size = labels.iter().filter(|&&l| l == last).count();
                assert!(
                    got - last_size < goal,
                    "diagram {i} took a cell after reaching its goal"
                );
            }
        }
        // The largest mean cell (fewest seeds) chose first.
        let mut by_order: Vec<_> = s.diagrams.iter().collect();
        by_order.sort_by_key(|d| d.order);
        assert!(by_order.windows(2).all(|w| w[0].seeds.len() <= w[1].seeds.len()));
    }
}

#[test]
fn counts_stop_at_the_count() {
    let mut r = recipe(5);
    r.layers[0].amount = Amount::Count(4);
    r.layers[1].amount = Amount::Count(30);
    let s = run(&r);
    assert_eq!(s.diagrams[0].cells.len(), 4);
    assert_eq!(s.diagrams[1].cells.len(), 30);
    assert_eq!(s.rocks.iter().filter(|k| k.diagram == 0).count(), 4);
}

fn circumcircle_contains(a: [f64; 2], b: [f64; 2], c: [f64; 2], p: [f64; 2]) -> f64 {
    // The incircle determinant, divided by the triangle's doubled area so the sign does not
    // depend on the orientation; > 0 inside.
    let (ax, ay) = (a[0] - p[0], a[1] - p[1]);
    let (bx, by) = (b[0] - p[0], b[1] - p[1]);
    let (cx, cy) = (c[0] - p[0], c[1] - p[1]);
    let det = (ax * ax + ay * ay) * (bx * cy - cx * by) - (bx * bx + by * by) * (ax * cy - cx * ay)
        + (cx * cx + cy * cy) * (ax * by - bx * ay);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    det / area
}

fn area(poly: &[[f64; 2]]) -> f64 {
    (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}

#[test]
fn each_rock_has_as_many_added_points_as_cell_vertices_and_a_delaunay_triangulation() {
    let s = run(&recipe(7));
    assert!(s.rocks.len() > 100, "{} rocks", s.rocks.len());
    for (n, rock) in s.rocks.iter().enumerate() {
        let k = rock.polygon.len();
        assert!(k >= 3, "rock {n}: a cell of {k} vertices");
        assert_eq!(rock.mesh.added.len(), k, "rock {n}: added points");
        assert_eq!(rock.mesh.vertices.len(), 2 * k);
        let pts: Vec<[f64; 2]> = rock.polygon.iter().chain(rock.mesh.added).copied().collect();
        // Each added point lies inside the (convex, positive) cell.
        for p in rock.mesh.added {
            for i in 0..k {
                let (a, b) = (rock.polygon[i], rock.polygon[(i + 1) % k]);
                assert!(
                    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0.0,
                    "rock {n}: {p:?} outside"
                );
            }
        }
        // A triangulation of n points with h on the hull has 2n − h − 2 triangles covering the cell.
        assert_eq!(rock.mesh.triangles.len(), 2 * pts.len() - k - 2, "rock {n}");
        let mut covered = 0.0;
        let scale = area(rock.polygon);
        for t in rock.mesh.triangles {
            let [a, b, c] = t.map(|i| pts[i as usize]);
            let doubled = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(doubled <= 0.0, "rock {n}: triangle {t:?} is not clockwise in (x, y)");
            covered -= doubled * 0.5;
            for (i, &p) in pts.iter().enumerate() {
                if t.contains(&(i as u32)) {
                    continue;
                }
                let inside = circumcircle_contains(a, b, c, p);
                assert!(
                    inside <= 1e-9 * scale.max(1.0),
                    "rock {n}: point {i} {p:?} is inside the circumcircle of {t:?} ({inside})"
                );
            }
        }
        assert!(
            (covered - scale).abs() <= 1e-9 * scale.max(1.0),
            "rock {n}: triangles cover {covered}, the cell {scale}"
        );
    }
}

#[test]
fn cells_are_their_pixels_and_rim_vertices_stay_on_the_ground() {
    let s = run(&recipe(11));
    for rock in &s.rocks {
        let d = &s.diagrams[rock.diagram];
        let seed = d.seeds[rock.cell as usize];
        let k = rock.polygon.len();
        // Every polygon vertex is at least as near its own seed as any other (a Voronoi cell).
        for v in rock.polygon {
            let own = (v[0] - seed[0]).powi(2) + (v[1] - seed[1]).powi(2);
            for o in &d.seeds {
                let other = (v[0] - o[0]).powi(2) + (v[1] - o[1]).powi(2);
                assert!(
                    own <= other + 1e-6,
                    "vertex {v:?} of cell {} is nearer {o:?}",
                    rock.cell
                );
            }
        }
        for (i, v) in rock.mesh.vertices.iter().enumerate() {
            if i < k {
                assert_eq!([v[0], v[1], v[2]], [rock.polygon[i][0], rock.polygon[i][1], 0.0]);
            } else {
                assert!(v[2] >= 0.0 && v[2].is_finite());
            }
        }
    }
}

#[test]
fn the_shape_follows_eq_2_and_3() {
    // Heights 0.5·r exactly, widths +0.2·r exactly: every added point moves 0.2·r out from the
    // added points' centroid and stands 0.5·r high.
    let radius = 6.0;
    let r = Recipe {
        width: 60,
        height: 60,
        layers: vec![Layer {
            radius,
            amount: Amount::Fraction(0.5),
            shape: Shape {
                widths: [0.2, 0.0, 0.0],
                heights: [0.5, 0.0, 0.0],
            },
        }],
        seed: 4,
        sampler: Sampler::Saturate,
    };
    let s = run(&r);
    for rock in &s.rocks {
        let k = rock.polygon.len();
        let g = rock
            .mesh
            .added
            .iter()
            .fold([0.0, 0.0], |g, p| [g[0] + p[0] / k as f64, g[1] + p[1] / k as f64]);
        for (p, v) in rock.mesh.added.iter().zip(&rock.mesh.vertices[k..]) {
            let before = ((p[0] - g[0]).powi(2) + (p[1] - g[1]).powi(2)).sqrt();
            let after = ((v[0] - g[0]).powi(2) + (v[1] - g[1]).powi(2)).sqrt();
            assert!(
                (after - before - 0.2 * radius).abs() < 1e-9,
                "moved {} not {}",
                after - before,
                0.2 * radius
            );
            assert!((v[2] - 0.5 * radius).abs() < 1e-12);
        }
    }
}

#[test]
fn a_seed_gives_the_same_rocks_on_any_number_of_threads() {
    let r = recipe(21);
    let strip = |mut s: Scatter| {
        s.timing = Default::default();
        s
    };
    let a = strip(run(&r));
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a pool");
    let b = strip(one.install(|| run(&r)));
    assert_eq!(a, b);
    let c = strip(run(&recipe(22)));
    assert_ne!(a.rocks, c.rocks);
}

#[test]
fn bad_recipes_name_the_layer() {
    let mut r = recipe(1);
    r.layers[1].radius = 0.0;
    assert_eq!(
        scatter(&r, None).err(),
        Some(RecipeError::RadiusNotPositive { layer: 1, radius: 0.0 })
    );
    let mut r = recipe(1);
    r.layers[0].radius = 500.0;
    assert!(matches!(
        scatter(&r, None),
        Err(RecipeError::RadiusTooLarge { layer: 0, .. })
    ));
    let mut r = recipe(1);
    r.layers[2].amount = Amount::Fraction(0.7);
    let e = scatter(&r, None).expect_err("refused");
    assert!(matches!(e, RecipeError::FractionsOverOne { .. }), "{e}");
    assert!(e.to_string().contains("more than 1"), "{e}");
    let mut r = recipe(1);
    r.layers[0].shape.heights[0] = -1.0;
    let e = scatter(&r, None).expect_err("refused");
    assert_eq!(e.to_string(), "layers[0].shape.c_h1: -1 must be from 0 to 10");
}

#[test]
fn a_mask_keeps_rocks_inside() {
    let r = recipe(9);
    let (w, h) = (r.width as usize, r.height as usize);
    // Inside: a disk in the middle.
    let inside: Vec<bool> = (0..w * h)
        .map(|p| {
            let (x, y) = ((p % w) as f64 + 0.5, (p / w) as f64 + 0.5);
            (x - 48.0).powi(2) + (y - 40.0).powi(2) < 30.0f64.powi(2)
        })
        .collect();
    let s = scatter(&r, Some(&inside)).expect("valid");
    assert_eq!(s.field_pixels, inside.iter().filter(|&&i| i).count());
    let pixels = kept_pixels(&s);
    for p in pixels.iter().flatten() {
        assert!(inside[*p as usize], "pixel {p} of a rock is outside the mask");
    }
    assert!(!s.rocks.is_empty());
}
