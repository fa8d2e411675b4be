//! Ridgeline terrain (seed 002): each property checked by a computation of the test's own —
//! triangles built from the flank geometry, all-pairs shortest paths, drops traced one by one,
//! horizons walked cell by cell — not by the code under test.

use std::f64::consts::PI;

use penmodel_terrain::ridge::sun::{self, Field, Sun};
use penmodel_terrain::ridge::tree::Tree;
use penmodel_terrain::ridge::{Dtm, Filter, RidgeError, Skeleton, filter, grow, rain};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

type Tri = [[f64; 3]; 3];

/// Elevation of the plane through `t` at `q` if `q` is inside `t` (edges included, with a
/// tolerance), by Cramer's rule on the triangle's edge vectors.
fn on_triangle(t: &Tri, q: [f64; 2]) -> Option<f64> {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ux, uy, vx, vy) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
    let det = ux * vy - uy * vx;
    if det.abs() < 1e-12 {
        return None;
    }
    let (wx, wy) = (q[0] - a[0], q[1] - a[1]);
    let s = (wx * vy - wy * vx) / det;
    let u = (ux * wy - uy * wx) / det;
    let eps = 1e-9;
    (s >= -eps && u >= -eps && s + u <= 1.0 + eps).then(|| a[2] + s * (b[2] - a[2]) + u * (c[2] - a[2]))
}

/// A cone sector: apex `p` (x, y, elevation) falling at `tan`, over the directions `w` from
/// it with `inside(w)`.
struct Cone {
    p: [f64; 3],
    tan: f64,
    inside: Box<dyn Fn([f64; 2]) -> bool>,
}

impl Cone {
    fn at(&self, q: [f64; 2]) -> Option<f64> {
        let w = [q[0] - self.p[0], q[1] - self.p[1]];
        let z = self.p[2] - w[0].hypot(w[1]) * self.tan;
        ((self.inside)(w) && z >= 0.0).then_some(z)
    }
}

/// The polygons of a polyline as the module docs describe them: each segment's two flank quads
/// (split in two triangles), and the cone falling at α from each joint over its outer gap
/// (turns under 90°) and from each end over the half plane beyond it.
fn polygons(points: &[[f64; 3]], slope: f64) -> (Vec<Tri>, Vec<Cone>) {
    let tan = slope.tan();
    let mut out = Vec::new();
    let dir = |a: [f64; 3], b: [f64; 3]| {
        let l = (b[0] - a[0]).hypot(b[1] - a[1]);
        [(b[0] - a[0]) / l, (b[1] - a[1]) / l]
    };
    let off = |p: [f64; 3], n: [f64; 2], r: f64| [p[0] + n[0] * r, p[1] + n[1] * r, 0.0];
    for w in points.windows(2) {
        let (p, q) = (w[0], w[1]);
        let u = dir(p, q);
        for n in [[-u[1], u[0]], [u[1], -u[0]]] {
            let (pp, qq) = (off(p, n, p[2] / tan), off(q, n, q[2] / tan));
            out.push([p, q, qq]);
            out.push([p, qq, pp]);
        }
    }
    let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
    let mut cones = Vec::new();
    // Joints: the outer side of the turn, between the two segments' outer normals.
    for k in 1..points.len() - 1 {
        let (a, p, b) = (points[k - 1], points[k], points[k + 1]);
        let (u, v) = (dir(a, p), dir(p, b));
        let side = if cross(u, v) > 0.0 { -1.0 } else { 1.0 }; // left turn: the gap is on the right
        let (n1, n2) = ([-u[1] * side, u[0] * side], [-v[1] * side, v[0] * side]);
        let turn = cross(n1, n2);
        cones.push(Cone {
            p,
            tan,
            inside: Box::new(move |w| cross(n1, w) * turn >= 0.0 && cross(w, n2) * turn >= 0.0),
        });
    }
    // Ends: the half plane beyond.
    let ends = [
        (points[0], dir(points[1], points[0])),
        (
            points[points.len() - 1],
            dir(points[points.len() - 2], points[points.len() - 1]),
        ),
    ];
    for (p, out_dir) in ends {
        cones.push(Cone {
            p,
            tan,
            inside: Box::new(move |w| w[0] * out_dir[0] + w[1] * out_dir[1] >= 0.0),
        });
    }
    (out, cones)
}

fn lines() -> Vec<Vec<[f64; 3]>> {
    vec![
        vec![[10.0, 12.0, 14.0], [30.0, 16.0, 22.0], [44.0, 34.0, 18.0]],
        vec![[60.0, 50.0, 9.0], [48.0, 62.0, 16.5], [56.0, 76.0, 12.0]],
    ]
}

#[test]
fn unfiltered_dtm_is_the_max_over_the_polygons_at_cell_centres() {
    let (cols, rows, cell) = (90u32, 80u32, 1.0);
    let slope = 38f64.to_radians();
    let ls = lines();
    let skels: Vec<Skeleton> = ls.iter().map(|l| Skeleton::polyline(l, slope)).collect();
    let ids: Vec<(u32, &Skeleton)> = skels.iter().enumerate().map(|(i, s)| (i as u32, s)).collect();
    let dtm = Dtm::build(cols, rows, cell, Filter::NONE, &ids);
    let (tris, cones): (Vec<Vec<Tri>>, Vec<Vec<Cone>>) = ls.iter().map(|l| polygons(l, slope)).unzip();
    let (tris, cones): (Vec<Tri>, Vec<Cone>) = (
        tris.into_iter().flatten().collect(),
        cones.into_iter().flatten().collect(),
    );
    let mut covered = 0;
    for r in 0..rows {
        for c in 0..cols {
            let q = [(f64::from(c) + 0.5) * cell, (f64::from(r) + 0.5) * cell];
            let want = tris
                .iter()
                .filter_map(|t| on_triangle(t, q))
                .chain(cones.iter().filter_map(|k| k.at(q)))
                .fold(0.0f64, f64::max);
            let got = f64::from(dtm.raw()[(r * cols + c) as usize]);
            assert!((got - want).abs() < 1e-3, "cell ({c}, {r}): DTM {got}, polygons {want}");
            covered += usize::from(want > 0.0);
            // Unfiltered: the output is the maximum itself.
            assert_eq!(
                dtm.heights()[(r * cols + c) as usize].to_bits(),
                dtm.raw()[(r * cols + c) as usize].to_bits()
            );
        }
    }
    assert!(covered > 2000, "the ridgelines cover {covered} cells");
}

/// A random polyline of 2 to 6 points inside a `w × h` metre field.
/// Issue 47: a level ridgeline's ends and joints fell steeper than α (39° for α = 30°, 45° off
/// an end, across the seed's planar triangles); every flank, end and joint must fall at α, so
/// no two neighbouring cells differ by more than tan α times their distance.
#[test]
fn every_flank_end_and_joint_falls_at_the_slope() {
    let (cols, rows, cell) = (120u32, 100u32, 1.0);
    let slope = 30f64.to_radians();
    let line = [[30.0, 30.0, 20.0], [70.0, 35.0, 20.0], [80.0, 70.0, 20.0]];
    let dtm = Dtm::build(
        cols,
        rows,
        cell,
        Filter::NONE,
        &[(0, &Skeleton::polyline(&line, slope))],
    );
    let z = dtm.raw();
    let (mut worst, mut at) = (0.0f64, (0, 0));
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            let i = (r * cols + c) as usize;
            for (j, d) in [
                (i + 1, 1.0),
                (i + cols as usize, 1.0),
                (i + cols as usize + 1, 2f64.sqrt()),
            ] {
                let fall = (f64::from(z[i]) - f64::from(z[j])).abs() / (d * cell);
                if fall > worst {
                    (worst, at) = (fall, (c, r));
                }
            }
        }
    }
    assert!(
        worst.atan().to_degrees() <= 30.0 + 1e-3,
        "{:.2}° at cell {at:?}",
        worst.atan().to_degrees()
    );
}

fn random_line(rng: &mut ChaCha8Rng, w: f64, h: f64) -> Vec<[f64; 3]> {
    let n = rng.random_range(2..7);
    (0..n)
        .map(|_| {
            [
                rng.random_range(0.0..w),
                rng.random_range(0.0..h),
                rng.random_range(-2.0..25.0),
            ]
        })
        .collect()
}

#[test]
fn incremental_updates_equal_a_full_rebuild_bit_for_bit() {
    let (cols, rows, cell) = (96u32, 80u32, 0.75);
    let (w, h) = (f64::from(cols) * cell, f64::from(rows) * cell);
    for seed in 0..4u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let filter = Filter {
            radius: 1 + seed as u32 % 2,
            passes: seed as u32 % 3,
        };
        let mut live: Vec<Option<Skeleton>> = vec![None; 6];
        let mut dtm = Dtm::new(cols, rows, cell, filter);
        for step in 0..40 {
            let id = rng.random_range(0..live.len());
            let slope = rng.random_range(15.0f64..70.0).to_radians();
            let next = match (&live[id], rng.random_range(0..4)) {
                (None, _) => Some(Skeleton::polyline(&random_line(&mut rng, w, h), slope)),
                (Some(_), 0) => None,
                // Move one node (a pen drag), keeping the rest: only its polygons change.
                (Some(s), _) => {
                    let mut s = s.clone();
                    let k = rng.random_range(0..s.nodes.len());
                    s.nodes[k][0] += rng.random_range(-4.0..4.0);
                    s.nodes[k][1] += rng.random_range(-4.0..4.0);
                    s.nodes[k][2] += rng.random_range(-3.0..3.0);
                    Some(s)
                }
            };
            live[id] = next;
            dtm.set(id as u32, live[id].as_ref());
            let ids: Vec<(u32, &Skeleton)> = live
                .iter()
                .enumerate()
                .filter_map(|(i, s)| s.as_ref().map(|s| (i as u32, s)))
                .collect();
            let full = Dtm::build(cols, rows, cell, filter, &ids);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(
                bits(dtm.raw()) == bits(full.raw()),
                "seed {seed} step {step}: raw layers differ"
            );
            assert!(
                bits(dtm.heights()) == bits(full.heights()),
                "seed {seed} step {step}: filtered DTMs differ"
            );
        }
    }
}

#[test]
fn filter_is_the_repeated_box_mean_and_zero_passes_is_the_input() {
    let (cols, rows) = (23u32, 17u32);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let input: Vec<f32> = (0..cols * rows).map(|_| rng.random_range(0.0f32..10.0)).collect();
    let all = penmodel_terrain::Rect {
        c0: 0,
        r0: 0,
        width: cols,
        height: rows,
    };
    let mut out = vec![0.0f32; input.len()];
    filter::apply(&input, cols, Filter { radius: 2, passes: 0 }, all, &mut out);
    assert_eq!(out, input);
    let f = Filter { radius: 2, passes: 2 };
    filter::apply(&input, cols, f, all, &mut out);
    // Naively: row means then column means, edge cells repeated, in f64.
    let mut z: Vec<f64> = input.iter().map(|&v| f64::from(v)).collect();
    let at = |z: &[f64], c: i64, r: i64| {
        z[(r.clamp(0, rows as i64 - 1) * cols as i64 + c.clamp(0, cols as i64 - 1)) as usize]
    };
    for _ in 0..f.passes {
        let mut t = z.clone();
        for r in 0..rows as i64 {
            for c in 0..cols as i64 {
                t[(r * cols as i64 + c) as usize] = (-2..=2).map(|d| at(&z, c + d, r)).sum::<f64>() / 5.0;
            }
        }
        for r in 0..rows as i64 {
            for c in 0..cols as i64 {
                z[(r * cols as i64 + c) as usize] = (-2..=2).map(|d| at(&t, c, r + d)).sum::<f64>() / 5.0;
            }
        }
    }
    for (i, (&a, &b)) in out.iter().zip(&z).enumerate() {
        assert!((f64::from(a) - b).abs() < 1e-4, "cell {i}: {a} vs {b}");
    }
}

/// Shortest path lengths between all node pairs (Floyd–Warshall).
fn all_pairs(t: &Tree) -> Vec<Vec<f64>> {
    let n = t.nodes.len();
    let mut d = vec![vec![f64::INFINITY; n]; n];
    for (i, row) in d.iter_mut().enumerate() {
        row[i] = 0.0;
    }
    for &[a, b] in &t.edges {
        let (p, q) = (t.nodes[a as usize], t.nodes[b as usize]);
        let l = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
        d[a as usize][b as usize] = l;
        d[b as usize][a as usize] = l;
    }
    for k in 0..n {
        for i in 0..n {
            for j in 0..n {
                if d[i][k] + d[k][j] < d[i][j] {
                    d[i][j] = d[i][k] + d[k][j];
                }
            }
        }
    }
    d
}

#[test]
fn tree_elevations_are_the_shortest_path_to_the_nearest_end() {
    for seed in 0..20u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let n = rng.random_range(2..40usize);
        let nodes: Vec<[f64; 2]> = (0..n)
            .map(|_| [rng.random_range(0.0..500.0), rng.random_range(0.0..500.0)])
            .collect();
        // Each node after the first hangs from an earlier one: a random tree.
        let edges: Vec<[u32; 2]> = (1..n as u32).map(|i| [rng.random_range(0..i), i]).collect();
        let t = Tree {
            nodes,
            edges,
            theta: rng.random_range(5.0f64..40.0).to_radians(),
            h_end: rng.random_range(0.0..100.0),
        };
        t.check("tree").expect("a random tree is valid");
        let d = all_pairs(&t);
        let mut degree = vec![0; n];
        for e in &t.edges {
            degree[e[0] as usize] += 1;
            degree[e[1] as usize] += 1;
        }
        let z = t.elevations();
        for i in 0..n {
            let nearest = (0..n)
                .filter(|&j| degree[j] == 1)
                .map(|j| d[i][j])
                .fold(f64::INFINITY, f64::min);
            let want = t.h_end + nearest * t.theta.tan();
            assert!(
                (z[i] - want).abs() < 1e-9 * (1.0 + want.abs()),
                "seed {seed} node {i}: {} vs {want}",
                z[i]
            );
        }
    }
}

#[test]
fn bad_ridgelines_trees_and_suns_are_refused_by_name() {
    let slope = 30f64.to_radians();
    let one = Skeleton::polyline(&[[1.0, 2.0, 3.0]], slope);
    assert!(
        matches!(one.check("ridges.lines[4]"), Err(RidgeError::TooShort { what, points: 1 }) if what == "ridges.lines[4]")
    );
    let nan = Skeleton::polyline(&[[1.0, 2.0, 3.0], [4.0, 5.0, f64::NAN]], slope);
    let e = nan.check("ridges.lines[0]").expect_err("NaN refused");
    assert!(e.to_string().contains("ridges.lines[0].points[1]"), "{e}");
    let inf = Skeleton::polyline(&[[1.0, f64::INFINITY, 3.0], [4.0, 5.0, 6.0]], slope);
    assert!(matches!(inf.check("l"), Err(RidgeError::NotFinite { what }) if what == "l.points[0]"));
    for deg in [0.0, 90.0, -5.0, 120.0] {
        let s = Skeleton::polyline(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], f64::to_radians(deg));
        assert!(matches!(s.check("ridges"), Err(RidgeError::Slope { .. })), "α = {deg}°");
    }
    let cycle = Tree {
        nodes: vec![[0.0, 0.0], [10.0, 0.0], [5.0, 8.0], [5.0, 20.0]],
        edges: vec![[0, 1], [2, 3], [1, 2], [2, 0]],
        theta: 0.3,
        h_end: 0.0,
    };
    assert!(
        matches!(cycle.check("ridges.trees[1]"), Err(RidgeError::Cycle { what }) if what == "ridges.trees[1].edges[3]")
    );
    let e = Sun::degrees(30.0, -1.0, "--sun").expect_err("below the horizon");
    assert!(
        e.to_string().contains("--sun") && e.to_string().contains("horizon"),
        "{e}"
    );
    assert!(Sun::degrees(30.0, 0.0, "--sun").is_err());
    assert!(Sun::degrees(30.0, 45.0, "--sun").is_ok());
}

#[test]
fn a_v_shaped_valley_gathers_its_rain_on_the_axis() {
    let (cols, rows, cell) = (41u32, 30u32, 1.0);
    let axis = 20;
    // Sides falling 0.5 per cell towards the axis column, the whole valley falling 0.1 per row.
    let z: Vec<f32> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| 0.5 * (c as f32 - axis as f32).abs() + 0.1 * (rows - r) as f32))
        .collect();
    let counts = rain::counts(&z, cols, rows, cell);
    // Traced one by one: every drop adds 1 to each cell of its path.
    let mut traced = vec![0u32; z.len()];
    for start in 0..z.len() as u32 {
        let (mut c, mut r) = (start % cols, start / cols);
        loop {
            traced[(r * cols + c) as usize] += 1;
            let n = rain::step(&z, cols, rows, cell, c, r);
            if n == rain::STOP {
                break;
            }
            let i = (r * cols + c) as usize;
            assert!(z[n as usize] < z[i], "a drop climbs");
            (c, r) = (n % cols, n / cols);
        }
    }
    assert_eq!(counts, traced);
    for r in 2..rows - 1 {
        let row = &counts[(r * cols) as usize..((r + 1) * cols) as usize];
        let best = (0..cols as usize).max_by_key(|&c| row[c]).expect("a row has cells");
        assert_eq!(best as u32, axis, "row {r}: counts {row:?}");
    }
    // The axis carries every drop that fell upstream on the valley.
    let last = counts[((rows - 1) * cols + axis) as usize];
    assert!(last as usize > z.len() / 2, "the outlet passes {last} drops");
}

/// Issue 47: on one straight ridge, which has no valley, 38 % of the sloped cells were "valley"
/// by the count alone (a plane flank's count grows with the distance run). With the longest
/// path's test no cell of its flanks is valley, while a V-shaped valley's axis still is.
#[test]
fn a_straight_ridge_has_no_valley_and_a_v_valley_has_one() {
    let (cols, rows, cell) = (200u32, 160u32, 1.0);
    let slope = 30f64.to_radians();
    // 30 m high: its foot (52 m out) is inside the grid.
    let line = [[60.0, 80.0, 30.0], [140.0, 80.0, 30.0]];
    let dtm = Dtm::build(
        cols,
        rows,
        cell,
        Filter::DEFAULT,
        &[(0, &Skeleton::polyline(&line, slope))],
    );
    let z = dtm.heights();
    let next = rain::directions(z, cols, rows, cell);
    let (counts, longest) = (rain::accumulate(&next), rain::longest_paths(&next));
    let sloped = z.iter().filter(|&&v| v > 0.0).count();
    let share = |classes: rain::Classes| {
        let v = classes.valleys(&counts, &longest);
        z.iter().zip(&v).filter(|&(&h, &v)| h > 0.0 && v > 0.0).count() as f64 / sloped as f64
    };
    let seeds = rain::Classes {
        valley_convergence: 1,
        ..rain::Classes::DEFAULT
    };
    assert!(
        share(seeds) > 0.2,
        "the count alone: {:.1} % valley",
        100.0 * share(seeds)
    );
    assert_eq!(share(rain::Classes::DEFAULT), 0.0, "valley cells on a straight ridge");

    // The V: sides falling 0.5 per cell towards the axis, the valley 0.1 per row.
    let (cols, rows, axis) = (41u32, 60u32, 20u32);
    let z: Vec<f32> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| 0.5 * (c as f32 - axis as f32).abs() + 0.1 * (rows - r) as f32))
        .collect();
    let next = rain::directions(&z, cols, rows, cell);
    let v = rain::Classes::DEFAULT.valleys(&rain::accumulate(&next), &rain::longest_paths(&next));
    for r in 0..rows {
        let row: Vec<u32> = (0..cols).filter(|&c| v[(r * cols + c) as usize] > 0.0).collect();
        assert!(row.is_empty() || row == [axis], "row {r}: valley cells {row:?}");
    }
    let on_axis = (0..rows).filter(|&r| v[(r * cols + axis) as usize] > 0.0).count();
    assert!(on_axis > rows as usize / 2, "{on_axis} of {rows} axis cells are valley");
}

/// A bumpy terrain: cones and a ridge.
fn bumpy(cols: u32, rows: u32) -> Vec<f32> {
    let mut z = vec![0.0f32; (cols * rows) as usize];
    let cones = [
        (12.0, 9.0, 14.0, 0.9),
        (40.0, 30.0, 20.0, 1.3),
        (25.0, 35.0, 9.0, 0.6),
        (50.0, 8.0, 11.0, 2.0),
    ];
    for r in 0..rows {
        for c in 0..cols {
            let mut h = 0.2 * (c as f32 * 0.37).sin() * (r as f32 * 0.23).cos();
            for (x, y, top, k) in cones {
                h = h.max(top - k * ((c as f32 - x).hypot(r as f32 - y)));
            }
            z[(r * cols + c) as usize] = h;
        }
    }
    z
}

#[test]
fn horizons_along_grid_lines_equal_a_brute_force_walk() {
    let (cols, rows, cell) = (64u32, 48u32, 2.0);
    let z = bumpy(cols, rows);
    let field = field_of(&z, cols, rows, cell);
    for k in 0..8 {
        let az = f64::from(k) * PI / 4.0;
        let (dc, dr) = (az.cos().round() as i64, az.sin().round() as i64);
        let step = ((dc * dc + dr * dr) as f64).sqrt() * cell;
        let mut got = vec![f64::NAN; z.len()];
        sun::horizons(field, az, |i, t| got[i] = t);
        for r in 0..rows as i64 {
            for c in 0..cols as i64 {
                let h0 = f64::from(z[(r * cols as i64 + c) as usize]);
                let mut best = f64::NEG_INFINITY;
                let (mut x, mut y, mut n) = (c + dc, r + dr, 1.0);
                while x >= 0 && y >= 0 && x < cols as i64 && y < rows as i64 {
                    best = best.max((f64::from(z[(y * cols as i64 + x) as usize]) - h0) / (n * step));
                    (x, y, n) = (x + dc, y + dr, n + 1.0);
                }
                let g = got[(r * cols as i64 + c) as usize];
                // The sweep works in f32 (hull positions and per-cell sums).
                assert!(
                    g == best || (g - best).abs() < 2e-5 * (1.0 + best.abs()),
                    "azimuth {k}·45°, cell ({c}, {r}): sweep {g}, walk {best}"
                );
            }
        }
    }
}

#[test]
fn horizons_in_any_azimuth_are_close_to_a_ray_march() {
    let (cols, rows, cell) = (64u32, 48u32, 2.0);
    let z = bumpy(cols, rows);
    let field = field_of(&z, cols, rows, cell);
    for az_deg in [10.0, 33.0, 71.0, 100.0, 200.0, 287.0, 333.0] {
        let az = f64::to_radians(az_deg);
        let mut got = vec![0.0; z.len()];
        sun::horizons(field, az, |i, t| got[i] = t);
        let mut diffs = Vec::new();
        for r in 0..rows {
            for c in 0..cols {
                let a = sun::ray_march(field, az, c, r);
                let b = got[(r * cols + c) as usize];
                // At the grid's edge one may leave the grid where the other stays a step longer.
                if a.is_finite() && b.is_finite() {
                    diffs.push((a.atan() - b.atan()).abs().to_degrees());
                }
            }
        }
        diffs.sort_by(f64::total_cmp);
        let p95 = diffs[diffs.len() * 95 / 100];
        let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
        // Digital lines stray up to half a cell sideways from the exact ray, which next to a
        // steep peak is a large angle (the bench reports the largest); most cells agree closely.
        eprintln!(
            "azimuth {az_deg}°: mean {mean}°, 95th percentile {p95}°, largest {}°",
            diffs[diffs.len() - 1]
        );
        assert!(
            mean < 1.0 && p95 < 4.0,
            "azimuth {az_deg}°: mean {mean}°, 95th percentile {p95}°"
        );
    }
}

#[test]
fn direct_light_is_lambert_in_the_sun_and_exactly_zero_in_shadow() {
    let (cols, rows, cell) = (64u32, 48u32, 2.0);
    let z = bumpy(cols, rows);
    let field = field_of(&z, cols, rows, cell);
    let sun = Sun::degrees(180.0, 20.0, "sun").expect("a sun above the horizon");
    let light = sun::direct(field, sun);
    let tan = sun.elevation.tan();
    let (mut lit, mut dark) = (0, 0);
    for r in 0..rows as i64 {
        for c in 0..cols as i64 {
            // Towards the sun: −x, cell by cell.
            let h0 = f64::from(z[(r * cols as i64 + c) as usize]);
            let shadowed =
                (1..=c).any(|k| (f64::from(z[(r * cols as i64 + c - k) as usize]) - h0) / (k as f64 * cell) >= tan);
            let v = light[(r * cols as i64 + c) as usize];
            if shadowed {
                assert_eq!(v, 0.0, "cell ({c}, {r}) is in shadow");
                dark += 1;
            } else {
                // Lambert with a central-difference normal of the test's own, loosely.
                lit += 1;
                assert!((0.0..=1.0).contains(&v), "cell ({c}, {r}): {v}");
            }
        }
    }
    assert!(lit > 100 && dark > 20, "lit {lit}, dark {dark}");
    // On open flat ground Lambert is sin(elevation).
    let flat = vec![3.0f32; 30 * 20];
    let f = field_of(&flat, 30, 20, 1.0);
    for v in sun::direct(f, sun) {
        assert!((f64::from(v) - sun.elevation.sin()).abs() < 1e-6);
    }
    for v in sun::sky_view(f, 16) {
        assert_eq!(v, 1.0);
    }
}

#[test]
fn sky_view_of_a_pit_is_one_minus_the_mean_squared_sine_of_its_horizons() {
    let (cols, rows, cell) = (41u32, 41u32, 1.0);
    // A cone-shaped pit: z = |q − centre|, so from the centre every horizon is 45° (tangent 1
    // reached at the rim, the grid's edge).
    let z: Vec<f32> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| (c as f32 - 20.0).hypot(r as f32 - 20.0)))
        .collect();
    let field = field_of(&z, cols, rows, cell);
    let sky = sun::sky_view(field, 32);
    let centre = f64::from(sky[(20 * cols + 20) as usize]);
    // Along the 8 grid directions the horizon is exactly 45°; between them the digital line
    // strays, so allow a little: sin² 45° = ½.
    assert!((centre - 0.5).abs() < 0.05, "sky view at the pit's bottom {centre}");
}

/// The sky view by its definition, naively in f64: per azimuth the parallel lines `v = b + u·t`
/// along the dominant axis u, one per integer b, sampled at every u with the height
/// interpolated between rows `⌊v⌋` and `⌊v⌋ + 1`; each sample's horizon the largest tangent to
/// any sample ahead (O(n) each); its `sin² max(0, H)` added to both cells with their
/// interpolation weights (nothing ahead: 0); the weighted mean.
fn sky_by_definition(z: &[f32], cols: usize, rows: usize, cell: f64, k: usize) -> Vec<f64> {
    let (mut sum, mut weight) = (vec![0.0f64; z.len()], vec![0.0f64; z.len()]);
    for d in 0..k {
        let az = 2.0 * PI * d as f64 / k as f64;
        let (dx, dy) = (az.cos(), az.sin());
        let x_major = dx.abs() >= dy.abs();
        let (du, dv, nu, nv) = if x_major {
            (dx, dy, cols, rows)
        } else {
            (dy, dx, rows, cols)
        };
        let mut t = dv / du;
        for e in [-1.0, 0.0, 1.0] {
            if (t - e).abs() < 1e-12 {
                t = e;
            }
        }
        let spacing = (1.0 + t * t).sqrt() * cell;
        let at = |u: usize, v: usize| if x_major { v * cols + u } else { u * cols + v };
        for b in -(nu as i64) - 1..=(nv + nu) as i64 + 1 {
            // (u, lower row, upper row's weight, height)
            let samples: Vec<(usize, usize, f64, f64)> = (0..nu)
                .filter_map(|u| {
                    let v = b as f64 + u as f64 * t;
                    if v < 0.0 || v > (nv - 1) as f64 {
                        return None;
                    }
                    let v0 = v.floor() as usize;
                    let f = v - v0 as f64;
                    let h = if f > 0.0 {
                        f64::from(z[at(u, v0)]) * (1.0 - f) + f64::from(z[at(u, v0 + 1)]) * f
                    } else {
                        f64::from(z[at(u, v0)])
                    };
                    Some((u, v0, f, h))
                })
                .collect();
            for &(u, v0, f, h) in &samples {
                let horizon = samples
                    .iter()
                    .filter(|q| (q.0 as f64 - u as f64) * du > 0.0)
                    .map(|q| (q.3 - h) / ((q.0 as f64 - u as f64).abs() * spacing))
                    .fold(0.0f64, f64::max);
                let value = horizon * horizon / (1.0 + horizon * horizon);
                sum[at(u, v0)] += (1.0 - f) * value;
                weight[at(u, v0)] += 1.0 - f;
                if f > 0.0 {
                    sum[at(u, v0 + 1)] += f * value;
                    weight[at(u, v0 + 1)] += f;
                }
            }
        }
    }
    sum.iter().zip(&weight).map(|(s, w)| 1.0 - s / w).collect()
}

#[test]
fn sky_view_has_the_same_bits_on_any_number_of_threads() {
    // The sweep shares each direction's lines and columns among the threads; every cell's sum
    // must be added in the same order whatever the sharing.
    let (cols, rows, cell) = (150u32, 90u32, 1.5);
    let z = bumpy(cols, rows);
    let field = field_of(&z, cols, rows, cell);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        pool.install(|| sun::sky_view(field, 32))
    };
    let one = on(1);
    for threads in [2, 3, 5] {
        let got = on(threads);
        assert!(
            one.iter().zip(&got).all(|(a, b)| a.to_bits() == b.to_bits()),
            "{threads} threads differ from one"
        );
    }
}

#[test]
fn sky_view_is_its_definition_computed_naively() {
    let (cols, rows, cell) = (40u32, 28u32, 2.0);
    let z = bumpy(cols, rows);
    let field = field_of(&z, cols, rows, cell);
    for k in [5, 16, 32] {
        let want = sky_by_definition(&z, cols as usize, rows as usize, cell, k);
        let got = sun::sky_view(field, k as u32);
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            // The sweep works in f32.
            assert!(
                (f64::from(*g) - w).abs() < 1e-4,
                "{k} azimuths, cell ({}, {}): sweep {g}, definition {w}",
                i % cols as usize,
                i / cols as usize
            );
        }
    }
}

#[test]
fn growth_is_seeded_and_its_lines_run_downhill_from_the_ridge() {
    let (cols, rows, cell) = (80u32, 64u32, 1.0);
    let base = [Skeleton::polyline(
        &[[10.0, 32.0, 20.0], [40.0, 28.0, 28.0], [70.0, 36.0, 18.0]],
        0.5,
    )];
    let g = grow::Growth::new(2, 7, cell);
    let a = grow::grow(&base, (cols, rows, cell), Filter::DEFAULT, 30f64.to_radians(), g).expect("grows");
    let b = grow::grow(&base, (cols, rows, cell), Filter::DEFAULT, 30f64.to_radians(), g).expect("grows");
    assert_eq!(a, b, "same seed, same lines");
    let c = grow::grow(
        &base,
        (cols, rows, cell),
        Filter::DEFAULT,
        30f64.to_radians(),
        grow::Growth { seed: 8, ..g },
    )
    .expect("grows");
    assert_ne!(a.lines, c.lines, "another seed, other lines");
    assert!(a.lines.len() >= 6, "{} lines", a.lines.len());
    assert!((a.slope - 40f64.to_radians()).abs() < 1e-12);
    for l in &a.lines {
        // After the point on the segment it was dropped from, strictly down.
        for w in l[1..].windows(2) {
            assert!(w[1][2] < w[0][2], "a grown line climbs: {l:?}");
        }
    }
    let too_steep = grow::Growth { rounds: 20, ..g };
    assert!(matches!(
        grow::grow(
            &base,
            (cols, rows, cell),
            Filter::DEFAULT,
            30f64.to_radians(),
            too_steep
        ),
        Err(RidgeError::Slope { .. })
    ));
}

fn ridge_doc() -> penmodel_terrain::Document {
    use penmodel_terrain::document::{RidgeTree, Ridgeline, Ridges};
    use penmodel_terrain::{Document, Figure, FigureKind, Grid, Region};
    let mut d = Document::new(Grid {
        cols: 96,
        rows: 80,
        cell_size: 1.0,
    });
    // A seed-000 hill under part of the ridge, and a depression away from it.
    d.regions.push(Region {
        metric: None,
        boundary: vec![[5.0, 5.0], [45.0, 5.0], [45.0, 40.0], [5.0, 40.0], [5.0, 5.0]],
        figures: vec![Figure {
            kind: FigureKind::Point,
            points: vec![[25.0, 22.0]],
            height: 18.0,
            slope: 0.0,
            figures: vec![],
        }],
    });
    d.regions.push(Region {
        metric: None,
        boundary: vec![[60.0, 50.0], [90.0, 50.0], [90.0, 75.0], [60.0, 75.0], [60.0, 50.0]],
        figures: vec![Figure {
            kind: FigureKind::Point,
            points: vec![[75.0, 62.0]],
            height: -6.0,
            slope: 0.0,
            figures: vec![],
        }],
    });
    d.ridges = Some(Ridges {
        lines: vec![Ridgeline {
            points: vec![[10.0, 30.0, 12.0], [30.0, 26.0, 24.0], [50.0, 40.0, 16.0]],
        }],
        trees: vec![RidgeTree {
            nodes: vec![[20.0, 60.0], [35.0, 62.0], [45.0, 72.0], [40.0, 50.0]],
            edges: vec![[0, 1], [1, 2], [1, 3]],
            theta: 35.0,
            h_end: 2.0,
        }],
        ..Ridges::default()
    });
    d
}

#[test]
fn ridges_join_the_terrain_by_max_where_they_stand_above_the_ground() {
    use penmodel_terrain::generate;
    let d = ridge_doc();
    let with = generate(&d).expect("valid");
    let mut plain = d.clone();
    plain.ridges = None;
    let base = generate(&plain).expect("valid");
    // The layer alone, from the module.
    let r = d.ridges.as_ref().expect("ridges");
    let sk = penmodel_terrain::ridge::layer::skeletons(r).expect("valid ridges");
    let ids: Vec<(u32, &Skeleton)> = sk.iter().map(|(i, s)| (*i, s)).collect();
    let layer = Dtm::build(96, 80, 1.0, Filter::DEFAULT, &ids);
    let mut raised = 0;
    for (i, ((&w, &b), &l)) in with
        .heights()
        .iter()
        .zip(base.heights())
        .zip(layer.heights())
        .enumerate()
    {
        let want = if l > 0.0 { b.max(l) } else { b };
        assert_eq!(w, want, "cell {i}");
        raised += usize::from(w > b);
    }
    assert!(raised > 500, "{raised} cells raised");
    // The depression away from the ridges stays below 0.
    assert!(with.heights().iter().any(|&h| h < -1.0));
}

#[test]
fn ridge_edits_update_the_terrain_like_a_fresh_generation_and_undo() {
    use penmodel_terrain::{Edit, Editor, generate};
    let d = ridge_doc();
    let mut ed = Editor::new(d.clone()).expect("valid");
    let fresh = |doc: &penmodel_terrain::Document| generate(doc).expect("valid");
    assert_eq!(ed.heightmap(), &fresh(&d));
    let mut r = d.ridges.clone().expect("ridges");
    // Drag a node of the line, then of the tree, add a line, delete the first.
    r.lines[0].points[1] = [33.0, 28.0, 30.0];
    ed.apply(Edit::SetRidges {
        ridges: Some(r.clone()),
    })
    .expect("moved");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    r.trees[0].nodes[2] = [50.0, 75.0];
    ed.apply(Edit::SetRidges {
        ridges: Some(r.clone()),
    })
    .expect("moved");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    r.lines.push(penmodel_terrain::document::Ridgeline {
        points: vec![[70.0, 10.0, 8.0], [80.0, 20.0, 14.0]],
    });
    ed.apply(Edit::SetRidges {
        ridges: Some(r.clone()),
    })
    .expect("added");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    r.lines.remove(0);
    ed.apply(Edit::SetRidges {
        ridges: Some(r.clone()),
    })
    .expect("deleted");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    ed.apply(Edit::SetRidges { ridges: None }).expect("removed");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    for _ in 0..5 {
        ed.undo().expect("undo");
        assert_eq!(ed.heightmap(), &fresh(ed.document()));
    }
    assert_eq!(ed.document(), &d);
    // Bad input is refused by name and the document kept.
    let mut bad = d.ridges.clone().expect("ridges");
    bad.trees[0].edges.push([2, 3]);
    let e = ed.apply(Edit::SetRidges { ridges: Some(bad) }).expect_err("a cycle");
    assert!(
        e.to_string().contains("ridges.trees[0].edges[3]") && e.to_string().contains("cycle"),
        "{e}"
    );
    let mut bad = d.ridges.clone().expect("ridges");
    bad.slope = 90.0;
    let e = ed.apply(Edit::SetRidges { ridges: Some(bad) }).expect_err("α = 90°");
    assert!(e.to_string().contains("ridges.slope"), "{e}");
    let mut bad = d.ridges.clone().expect("ridges");
    bad.lines[0].points.truncate(1);
    let e = ed.apply(Edit::SetRidges { ridges: Some(bad) }).expect_err("one point");
    assert!(e.to_string().contains("ridges.lines[0]"), "{e}");
    assert_eq!(ed.document(), &d);
}

#[test]
fn ridges_round_trip_and_need_version_3() {
    use penmodel_terrain::Document;
    let d = ridge_doc();
    let text = d.to_json();
    assert_eq!(Document::from_json(&text).expect("loads"), d);
    let current = format!("\"version\": {}", penmodel_terrain::document::VERSION);
    let old = text.replacen(&current, "\"version\": 2", 1);
    assert_ne!(old, text);
    let e = Document::from_json(&old).expect_err("ridges need version 3");
    assert!(e.to_string().contains("ridges"), "{e}");
    // NaN cannot be written in JSON; an infinite elevation overflows and is refused by name.
    let bad = text.replacen("24.0", "1e999", 1);
    assert!(Document::from_json(&bad).is_err());
    // A version 2 document without ridges still loads.
    let mut plain = d.clone();
    plain.ridges = None;
    let v2 = plain.to_json().replacen("\"version\": 3", "\"version\": 2", 1);
    assert_eq!(Document::from_json(&v2).expect("a v2 document loads"), plain);
}

#[test]
fn a_ridge_preview_shows_each_frame_and_records_one_undoable_step() {
    use penmodel_terrain::{Edit, Editor, generate};
    let d = ridge_doc();
    let mut ed = Editor::new(d.clone()).expect("valid");
    let fresh = |doc: &penmodel_terrain::Document| generate(doc).expect("valid");
    let mut r = d.ridges.clone().expect("ridges");
    // A node dragged over three frames: each shown at once, none recorded.
    for k in 1..=3 {
        r.lines[0].points[1] = [30.0 + f64::from(k), 26.0, 24.0 + 2.0 * f64::from(k)];
        ed.preview_ridges(Some(r.clone())).expect("shown");
        assert!(ed.previewing());
        assert_eq!(ed.heightmap(), &fresh(ed.document()));
    }
    assert!(!ed.can_undo(), "a preview is not recorded");
    let edit = ed.commit_ridges_preview().expect("recorded").expect("a preview");
    assert_eq!(
        edit,
        Edit::SetRidges {
            ridges: Some(r.clone())
        }
    );
    assert!(!ed.previewing());
    ed.undo().expect("undo").expect("one step");
    assert_eq!(ed.document(), &d, "one undo returns to before the drag");
    assert!(!ed.can_undo());
    ed.redo().expect("redo");
    assert_eq!(ed.document().ridges.as_ref(), Some(&r));
    // A preview cancelled, or followed by another edit, is restored first.
    let mut s = r.clone();
    s.slope = 45.0;
    ed.preview_ridges(Some(s.clone())).expect("shown");
    ed.cancel_preview().expect("restored");
    assert_eq!(ed.document().ridges.as_ref(), Some(&r));
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    ed.preview_ridges(Some(s)).expect("shown");
    ed.apply(Edit::SetRidges { ridges: None }).expect("removed");
    ed.undo().expect("undo");
    assert_eq!(
        ed.document().ridges.as_ref(),
        Some(&r),
        "the preview did not leak into the undo"
    );
    // A refused preview leaves the document as it was.
    let mut bad = r.clone();
    bad.slope = 95.0;
    assert!(ed.preview_ridges(Some(bad)).is_err());
    assert_eq!(ed.document().ridges.as_ref(), Some(&r));
    assert!(!ed.previewing());
}

/// The lighting functions' view of `cols × rows` heights `z` of `cell`-metre cells.
fn field_of(z: &[f32], cols: u32, rows: u32, cell: f64) -> Field<'_> {
    Field { z, cols, rows, cell }
}
