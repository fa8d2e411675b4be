//! Rivers (issue 13, seed 003): the diamonds against the iterated cross, the curvature formula,
//! bank sides on a bend, oxbow lakes, the carved bed, determinism. Each property is checked by a
//! computation of its own here.
// Cells are addressed by window index in several parallel arrays.
#![allow(clippy::needless_range_loop)]

use glam::DVec2;
use penmodel_terrain::river::course::{self, Sample};
use penmodel_terrain::river::{self, Constants, Shape, carve, edt, level, morph};
use penmodel_terrain::{Grid, Heightmap, River};

/// A deterministic pseudo-random 0/1 image with about `fill` of its cells set.
fn noise(w: usize, h: usize, seed: u64, fill: f64) -> Vec<u8> {
    let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (0..w * h)
        .map(|_| {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            u8::from(((x >> 33) as f64 / (1u64 << 31) as f64) < fill)
        })
        .collect()
}

/// One step of the 4-neighbour cross: dilation (any of the five set) or erosion (all five set,
/// outside the image unset).
fn cross(img: &[u8], w: usize, h: usize, dilate: bool) -> Vec<u8> {
    let at = |c: i64, r: i64| -> u8 {
        if c < 0 || r < 0 || c >= w as i64 || r >= h as i64 {
            0
        } else {
            img[r as usize * w + c as usize]
        }
    };
    let mut out = vec![0; w * h];
    for r in 0..h as i64 {
        for c in 0..w as i64 {
            let five = [at(c, r), at(c - 1, r), at(c + 1, r), at(c, r - 1), at(c, r + 1)];
            out[r as usize * w + c as usize] = if dilate {
                u8::from(five.iter().any(|&v| v != 0))
            } else {
                u8::from(five.iter().all(|&v| v != 0))
            };
        }
    }
    out
}

#[test]
fn diamonds_equal_the_iterated_cross() {
    for level in 1..=morph::MAX_LEVEL {
        // The element itself: a single cell dilated n − 1 times.
        let side = 2 * level as usize - 1;
        let mut one = vec![0; side * side];
        one[side * side / 2] = 1;
        let mut grown = one.clone();
        for _ in 1..level {
            grown = cross(&grown, side, side, true);
        }
        assert_eq!(morph::diamond(level), grown, "level {level}");
        assert_eq!(morph::dilate(&one, side, side, level), grown, "level {level}");
        // The last is packed in two bands of rows (over 2^16 cells).
        let sizes = [
            (37, 23, 0.1, 1),
            (40, 40, 0.6, 2),
            (64, 17, 0.85, 3),
            (1, 9, 0.5, 4),
            (301, 229, 0.5, 5),
        ];
        for (w, h, fill, seed) in sizes {
            let img = noise(w, h, seed, fill);
            let (mut d, mut e) = (img.clone(), img.clone());
            for _ in 1..level {
                d = cross(&d, w, h, true);
                e = cross(&e, w, h, false);
            }
            assert_eq!(morph::dilate(&img, w, h, level), d, "dilation, level {level}, {w}x{h}");
            assert_eq!(morph::erode(&img, w, h, level), e, "erosion, level {level}, {w}x{h}");
        }
    }
}

#[test]
fn the_euclidean_distance_is_the_nearest_set_cell() {
    // Brute force: the least √(dx² + dy²) to a set cell; none: infinite.
    for (w, h, fill, seed) in [
        (31, 19, 0.02, 15),
        (40, 40, 0.3, 16),
        (23, 29, 0.9, 17),
        (1, 12, 0.3, 18),
        (9, 1, 0.3, 19),
    ] {
        for img in [noise(w, h, seed, fill), vec![0; w * h], vec![1; w * h]] {
            let d = edt::euclidean(&img, w, h);
            for i in 0..w * h {
                let (c, r) = ((i % w) as f64, (i / w) as f64);
                let want = (0..w * h)
                    .filter(|&j| img[j] != 0)
                    .map(|j| ((j % w) as f64 - c).hypot((j / w) as f64 - r))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    (f64::from(d[i]) - want).abs() <= 1e-5 * want.max(1.0)
                        || (want.is_infinite() && d[i].is_infinite()),
                    "{w}x{h} fill {fill}, cell ({c}, {r}): {} against {want}",
                    d[i]
                );
            }
        }
    }
}

#[test]
fn the_distance_to_the_other_value_is_the_nearest_cell_of_it() {
    // Brute force: the least |dx| + |dy| to a cell of the other value, none: u16::MAX.
    for (w, h, fill, seed) in [
        (31, 19, 0.05, 5),
        (40, 40, 0.5, 6),
        (23, 29, 0.95, 7),
        (1, 12, 0.4, 8),
        (9, 1, 0.4, 9),
    ] {
        for img in [noise(w, h, seed, fill), vec![0; w * h], vec![1; w * h]] {
            let d = morph::distance_to_other(&img, w, h);
            for i in 0..w * h {
                let (c, r) = ((i % w) as i64, (i / w) as i64);
                let want = (0..w * h)
                    .filter(|&j| (img[j] != 0) != (img[i] != 0))
                    .map(|j| ((j % w) as i64 - c).abs() + ((j / w) as i64 - r).abs())
                    .min()
                    .map_or(u16::MAX, |m| m as u16);
                assert_eq!(d[i], want, "{w}x{h} fill {fill}, cell ({c}, {r})");
            }
        }
    }
}

#[test]
fn curvature_of_a_circle_is_one_over_r_and_of_a_line_zero() {
    for r in [0.5, 3.0, 40.0] {
        for k in 0..16 {
            let a = k as f64 * 0.4;
            // x = r cos a, y = r sin a.
            let d1 = DVec2::new(-r * a.sin(), r * a.cos());
            let d2 = DVec2::new(-r * a.cos(), -r * a.sin());
            assert!((course::curvature(d1, d2) - 1.0 / r).abs() < 1e-12);
        }
    }
    assert_eq!(course::curvature(DVec2::new(3.0, -1.0), DVec2::ZERO), 0.0);
    assert_eq!(course::curvature(DVec2::new(3.0, -1.0), DVec2::new(6.0, -2.0)), 0.0);
    // Sampled: a straight course, and a circle of radius 50 by four cubic quarters (handle
    // 0.5523 r: within 0.03 % of the circle), through the course sampler.
    let line = course::sample(&[DVec2::new(5.0, 5.0), DVec2::new(60.0, 30.0)], 1.0);
    assert!(line.iter().all(|s| s.curvature() == 0.0));
    let r = 50.0;
    let k = 0.552_284_75 * r;
    let c = DVec2::new(100.0, 100.0);
    let pts = [
        c + DVec2::new(r, 0.0),
        c + DVec2::new(r, k),
        c + DVec2::new(k, r),
        c + DVec2::new(0.0, r),
        c + DVec2::new(-k, r),
        c + DVec2::new(-r, k),
        c + DVec2::new(-r, 0.0),
    ];
    let samples = course::sample(&pts, 1.0);
    assert!(samples.len() > 150);
    for s in &samples {
        assert!((s.p.distance(c) - r).abs() < 0.02 * r);
        // The cubic quarter's curvature strays more than its radius does (by up to 2.5 %).
        assert!((s.curvature() * r - 1.0).abs() < 0.03, "{}", s.curvature() * r);
    }
    // By differences over a polyline on the circle (the later iterations' centre lines).
    let ring: Vec<DVec2> = (0..200).map(|i| c + DVec2::from_angle(i as f64 * 0.01) * r).collect();
    for s in &course::differentiate(&ring, 3)[3..197] {
        assert!((s.curvature() * r - 1.0).abs() < 0.01);
    }
}

fn grid(n: u32) -> Grid {
    Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    }
}

fn river(points: Vec<[f64; 2]>, width: f64, iterations: u32) -> River {
    River {
        points,
        width,
        depth: 1.5,
        water: 60.0,
        hardness: 1.0,
        iterations,
    }
}

/// A half circle of radius `r` around `c` by two cubic quarters, from the left to the right over the top.
fn bend(c: [f64; 2], r: f64) -> Vec<[f64; 2]> {
    let k = 0.552_284_75 * r;
    vec![
        [c[0] - r, c[1]],
        [c[0] - r, c[1] - k],
        [c[0] - k, c[1] - r],
        [c[0], c[1] - r],
        [c[0] + k, c[1] - r],
        [c[0] + r, c[1] - k],
        [c[0] + r, c[1]],
    ]
}

#[test]
fn on_a_bend_the_outer_bank_moves_out_and_the_inner_bank_in() {
    let (c, r) = ([64.0, 70.0], 20.0);
    for iterations in 0..3 {
        let rv = river(bend(c, r), 4.0, iterations);
        let shape = Shape::process(&rv, &grid(128), &Constants::default());
        let before = shape.mask.clone();
        let mut next = shape.clone();
        next.step();
        let win = shape.window;
        let centre = DVec2::new(c[0] - 0.5, c[1] - 0.5) - win.origin();
        let line: Vec<DVec2> = shape.line.iter().map(|s| s.p - win.origin()).collect();
        let (mut out, mut inn) = (0, 0);
        for i in 0..win.len() {
            let p = DVec2::new((i % win.width) as f64, (i / win.width) as f64);
            // Only the arc: above the centre, away from the fixed ends.
            if p.y > centre.y - 0.5 * r {
                continue;
            }
            // The bank's side: farther from the bend's centre than the nearest point of the
            // course (outer) or nearer (inner).
            let nearest = line
                .iter()
                .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)))
                .copied()
                .unwrap_or(p);
            let (radial, course) = (p.distance(centre), nearest.distance(centre));
            match (before[i], next.mask[i]) {
                (0, 1) => {
                    assert!(
                        radial > course,
                        "bank cut on the inside at {p} ({radial} against {course})"
                    );
                    out += 1;
                }
                (1, 0) => {
                    assert!(
                        radial < course,
                        "sediment on the outside at {p} ({radial} against {course})"
                    );
                    inn += 1;
                }
                _ => {}
            }
        }
        assert!(out > 0 && inn > 0, "the bend moved: {out} cells cut, {inn} filled");
        // The preview shows exactly the next step's changes.
        let preview = shape.preview();
        for i in 0..win.len() {
            assert_eq!(preview.erosion[i], u8::from(before[i] == 0 && next.mask[i] == 1));
            assert_eq!(preview.deposition[i], u8::from(before[i] == 1 && next.mask[i] == 0));
        }
    }
}

/// An Ω: up from the bottom, a loop of radius 28 round (100, 70), back down; its neck (the two
/// legs at the loop's foot) `neck` cells wide.
pub fn omega(neck: f64) -> Vec<[f64; 2]> {
    let (c, r) = (DVec2::new(100.0, 70.0), 28.0);
    let a0 = (neck / 2.0 / r).asin();
    let foot = c.y + r * a0.cos();
    let mut stroke = vec![
        DVec2::new(c.x - neck / 2.0, 190.0),
        DVec2::new(c.x - neck / 2.0, foot + 10.0),
    ];
    // From the foot's left side (angle π/2 + a0, y down) round the left, the top and the right.
    for k in 0..=64 {
        let a = std::f64::consts::FRAC_PI_2 + a0 + k as f64 * (2.0 * std::f64::consts::PI - 2.0 * a0) / 64.0;
        stroke.push(c + DVec2::new(a.cos(), a.sin()) * r);
    }
    stroke.extend([
        DVec2::new(c.x + neck / 2.0, foot + 10.0),
        DVec2::new(c.x + neck / 2.0, 190.0),
    ]);
    course::fit(&stroke, 16).iter().map(|p| [p.x, p.y]).collect()
}

#[test]
fn a_sharp_bend_forms_an_oxbow_lake() {
    let rv = river(omega(18.0), 3.0, 12);
    let shape = Shape::process(&rv, &grid(200), &Constants::default());
    let cut = shape.history.iter().position(|it| !it.oxbows.is_empty());
    let Some(k) = cut else {
        panic!("no oxbow in {:?}", shape.history);
    };
    // Standing water away from the river: lake cells, none of them river cells, none next to the
    // river's course, and the river's course no longer goes round the loop.
    let lake: Vec<usize> = (0..shape.window.len()).filter(|&i| shape.lakes[i] != 0).collect();
    assert!(!lake.is_empty() && shape.history[k].oxbows.iter().all(|&a| a > 0));
    assert!(lake.iter().all(|&i| shape.mask[i] == 0));
    let win = shape.window;
    for &i in &lake {
        let p = DVec2::new((i % win.width) as f64, (i / win.width) as f64) + win.origin();
        let d = shape.line.iter().map(|s| s.p.distance(p)).fold(f64::INFINITY, f64::min);
        assert!(
            d > shape.radius + river::PLUG - 1.0,
            "lake cell {p} is {d} from the river"
        );
    }
    let top = shape.line.iter().map(|s| s.p.y).fold(f64::INFINITY, f64::min);
    assert!(top > 60.0, "the course still reaches y = {top}: the loop was not cut");
}

/// Rolling ground sloping down to the right with a ridge across the course.
fn ground(n: u32) -> Heightmap {
    let heights = (0..n * n)
        .map(|i| {
            let (x, y) = (f64::from(i % n), f64::from(i / n));
            (40.0 - 0.1 * x + 3.0 * (x / 9.0).sin() * (y / 13.0).cos() + 6.0 * (-(x - 120.0).powi(2) / 60.0).exp())
                as f32
        })
        .collect();
    Heightmap::from_heights(n, n, 1.0, heights).expect("n² heights")
}

#[test]
fn the_carved_bed_never_rises_along_the_course() {
    let g = ground(200);
    for (points, iterations) in [(omega(18.0), 12), (omega(40.0), 3), (bend([100.0, 120.0], 50.0), 2)] {
        let rv = river(points, 3.0, iterations);
        let shape = Shape::process(&rv, &grid(200), &Constants::default());
        let carve = carve::carve(&shape, rv.width, rv.depth, &g);
        let mut map = g.clone();
        carve.apply(&mut map);
        let mut last = f32::INFINITY;
        for s in &shape.line {
            let (c, r) = (s.p.x.round() as u32, s.p.y.round() as u32);
            let h = map.get(c, r);
            assert!(
                h <= last,
                "the bed rises to {h} at ({c}, {r}) after {last} (ground {})",
                g.get(c, r)
            );
            last = h;
        }
        // Carving only lowers, and every river cell is under water.
        for i in 0..g.heights().len() {
            assert!(map.heights()[i] <= g.heights()[i]);
        }
        let win = carve.window;
        for i in 0..win.len() {
            if shape.mask[i] != 0 {
                let (c, r) = (win.c0 + (i % win.width) as u32, win.r0 + (i / win.width) as u32);
                assert!(carve.water[i] > map.get(c, r), "dry river cell ({c}, {r})");
            }
        }
    }
}

#[test]
fn rivers_are_deterministic() {
    let rv = river(omega(18.0), 3.0, 8);
    let a = Shape::process(&rv, &grid(200), &Constants::default());
    let b = Shape::process(&rv, &grid(200), &Constants::default());
    assert_eq!(a, b);
    let g = ground(200);
    let (ca, cb) = (carve::carve(&a, 3.0, 1.5, &g), carve::carve(&b, 3.0, 1.5, &g));
    assert_eq!(
        ca.target.iter().map(|t| t.to_bits()).collect::<Vec<_>>(),
        cb.target.iter().map(|t| t.to_bits()).collect::<Vec<_>>()
    );
    // Iterating one step at a time is processing with more iterations.
    let mut stepwise = Shape::process(&river(omega(18.0), 3.0, 0), &grid(200), &Constants::default());
    let full = Shape::process(&rv, &grid(200), &Constants::default());
    for _ in 0..8 {
        stepwise.step();
    }
    assert_eq!(
        stepwise.mask.iter().filter(|&&m| m != 0).count(),
        full.history.last().map_or(0, |h| h.area)
    );
}

#[test]
fn the_level_grows_with_curvature_flow_and_softer_ground() {
    let c = Constants::default();
    let base = river(vec![[0.0, 0.0], [1.0, 0.0]], 3.0, 0);
    let mut seen = std::collections::BTreeSet::new();
    for (i, kappa) in [0.0, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 5.0]
        .windows(2)
        .map(|w| (w[0], w[1]))
        .enumerate()
    {
        let _ = i;
        for water in [10.0, 60.0, 200.0] {
            for hardness in [0.5, 1.0, 3.0] {
                let mut r = base.clone();
                r.water = water;
                r.hardness = hardness;
                let (a, b) = (level::level(kappa.0, &r, 1.0, &c), level::level(kappa.1, &r, 1.0, &c));
                assert!(a <= b && (1..=morph::MAX_LEVEL).contains(&a) && b <= level::max_level(&r, 1.0, &c));
                seen.insert(b);
                let mut more = r.clone();
                more.water *= 2.0;
                assert!(level::level(kappa.1, &more, 1.0, &c) >= b);
                let mut harder = r.clone();
                harder.hardness *= 2.0;
                assert!(level::level(kappa.1, &harder, 1.0, &c) <= b);
                let mut deeper = r.clone();
                deeper.depth *= 2.0;
                assert!(level::level(kappa.1, &deeper, 1.0, &c) >= b);
            }
        }
    }
    assert!(seen.len() >= 3, "levels used: {seen:?}");
    assert_eq!(
        level::level(0.0, &base, 1.0, &c),
        1,
        "a straight course does not change"
    );
}

#[test]
fn a_fitted_course_passes_through_the_stroke() {
    let stroke: Vec<DVec2> = (0..100)
        .map(|i| DVec2::new(i as f64, 20.0 * (i as f64 / 15.0).sin()))
        .collect();
    let pts = course::fit(&stroke, 8);
    assert_eq!(pts.len(), 3 * 7 + 1);
    let samples: Vec<Sample> = course::sample(&pts, 0.5);
    for p in &stroke {
        let d = samples.iter().map(|s| s.p.distance(*p)).fold(f64::INFINITY, f64::min);
        assert!(d < 1.5, "the course is {d} from the stroke at {p}");
    }
}

/// A document with one region (a hill) and the Ω river across it.
fn river_doc() -> penmodel_terrain::Document {
    use penmodel_terrain::{Document, Figure, FigureKind, Region};
    let mut d = Document::new(grid(200));
    d.regions.push(Region {
        metric: None,
        boundary: vec![[2.0, 2.0], [198.0, 2.0], [198.0, 198.0], [2.0, 198.0], [2.0, 2.0]],
        figures: vec![Figure {
            kind: FigureKind::Point,
            points: vec![[100.0, 20.0]],
            height: 30.0,
            slope: 0.0,
            figures: Vec::new(),
        }],
    });
    d.rivers.push(river(omega(18.0), 3.0, 4));
    d
}

#[test]
fn river_entries_load_validate_and_name_the_element() {
    use penmodel_terrain::Document;
    let d = river_doc();
    let back = Document::from_json(&d.to_json()).expect("valid");
    assert_eq!(back, d);
    // Rivers need version 3.
    let current = format!("\"version\": {}", penmodel_terrain::document::VERSION);
    let v2 = d.to_json().replace(&current, "\"version\": 2");
    let e = Document::from_json(&v2).expect_err("a v2 file with rivers");
    assert_eq!(e.to_string(), "rivers: needs document version 3");
    // Defaults: water 60, hardness 1, no iterations.
    let text = d.to_json();
    let start = text.find("\"rivers\"").expect("rivers in the file");
    let bare = format!(
        "{}\"rivers\": [{{\"points\": [[10.0, 10.0], [50.0, 60.0]], \"width\": 2.0, \"depth\": 1.0}}]\n}}\n",
        &text[..start]
    );
    let doc = Document::from_json(&bare).expect("defaults");
    assert_eq!(
        (doc.rivers[0].water, doc.rivers[0].hardness, doc.rivers[0].iterations),
        (60.0, 1.0, 0)
    );
    let bad = |f: &dyn Fn(&mut River), want: &str| {
        let mut d = river_doc();
        f(&mut d.rivers[0]);
        let e = Document::from_json(&d.to_json()).expect_err(want);
        assert_eq!(e.to_string(), want);
    };
    bad(
        &|r| r.points.truncate(1),
        "rivers[0].points: a river's course needs at least two control points, found 1",
    );
    bad(&|r| r.width = 0.0, "rivers[0].width: 0 must be above 0");
    bad(&|r| r.depth = -1.0, "rivers[0].depth: -1 must be above 0");
    bad(&|r| r.hardness = 0.0, "rivers[0].hardness: 0 must be above 0");
    bad(
        &|r| r.width = 65.0,
        "rivers[0].width: 65 m is more than the 64 m (64 cells) a river may be wide",
    );
    bad(
        &|r| r.points[2] = [250.0, 10.0],
        "rivers[0].points[2]: (250, 10) lies outside the grid [0, 200) × [0, 200) m",
    );
    bad(
        &|r| r.iterations = river::MAX_ITERATIONS + 1,
        "rivers[0].iterations: 21 iterations is more than the 20 a river may have",
    );
}

#[test]
fn river_edits_undo_and_recarve_incrementally() {
    use penmodel_terrain::{Edit, Editor, generate};
    let d = river_doc();
    let mut ed = Editor::new(d.clone()).expect("valid");
    let fresh = |doc: &penmodel_terrain::Document| generate(doc).expect("valid");
    assert_eq!(ed.heightmap(), &fresh(&d));
    // A carved river lowers the ground.
    let mut dry = d.clone();
    dry.rivers.clear();
    let ground = fresh(&dry);
    assert!(
        ed.heightmap()
            .heights()
            .iter()
            .zip(ground.heights())
            .any(|(c, g)| c < g)
    );
    let mut more = d.rivers[0].clone();
    more.iterations += 1;
    more.width = 4.0;
    ed.apply(Edit::ReplaceRiver {
        index: 0,
        river: more.clone(),
    })
    .expect("replaced");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    ed.apply(Edit::AddRiver {
        index: 1,
        river: river(bend([100.0, 150.0], 30.0), 2.0, 1),
    })
    .expect("added");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    ed.apply(Edit::DeleteRiver { index: 0 }).expect("deleted");
    assert_eq!(ed.heightmap(), &fresh(ed.document()));
    for _ in 0..3 {
        ed.undo().expect("undo");
    }
    assert_eq!(ed.document(), &d);
    assert_eq!(ed.heightmap(), &fresh(&d));
    // A bad river is refused and the document kept.
    let mut bad = more;
    bad.depth = 0.0;
    let e = ed
        .apply(Edit::ReplaceRiver { index: 0, river: bad })
        .expect_err("refused");
    assert!(e.to_string().contains("rivers[0].depth"), "{e}");
    assert_eq!(ed.document(), &d);
    // The journal's form.
    let e = Edit::DeleteRiver { index: 2 };
    let line = serde_json::to_string(&e).expect("json");
    assert_eq!(line, r#"{"op":"delete_river","index":2}"#);
    assert_eq!(serde_json::from_str::<Edit>(&line).expect("parses"), e);
}

#[test]
fn the_nearest_sample_field_is_the_distance_to_the_course() {
    use penmodel_terrain::river::near::{self, NONE};
    // The Ω's sampled course (sharp bends and a neck) and a zigzag with 127° turns.
    let omega: Vec<DVec2> = course::sample(&omega(18.0).iter().map(|p| DVec2::from(*p)).collect::<Vec<_>>(), 1.0)
        .iter()
        .map(|s| s.p)
        .collect();
    let zigzag: Vec<DVec2> = (0..40)
        .map(|i| DVec2::new(10.0 + 3.0 * i as f64, 60.0 + 6.0 * (i % 2) as f64))
        .collect();
    let win = river::Window {
        c0: 0,
        r0: 0,
        width: 200,
        height: 200,
    };
    // A shallow zigzag: turns of 37°, under the 45° past which a joint's wedge is a rectangle.
    let shallow: Vec<DVec2> = (0..40)
        .map(|i| DVec2::new(10.0 + 3.0 * i as f64, 120.0 + (i % 2) as f64))
        .collect();
    for (line, reach) in [(omega, 9.0), (zigzag, 7.0), (shallow, 8.0)] {
        let field = near::nearest(&win, &line, reach);
        // The owner is the nearer end of a nearest segment: within half the longest segment of
        // the nearest point.
        let half = line.windows(2).map(|w| w[0].distance(w[1])).fold(0.0, f64::max) / 2.0;
        for i in 0..win.len() {
            let p = DVec2::new((i % 200) as f64, (i / 200) as f64);
            // Brute force over every segment: the distance and the side (the sign of the cross
            // product) of each.
            let mut near: Vec<(f64, i8)> = line
                .windows(2)
                .map(|w| {
                    let ab = w[1] - w[0];
                    let t = ((p - w[0]).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                    let cross = ab.perp_dot(p - w[0]);
                    (
                        p.distance(w[0] + ab * t),
                        i8::from(cross > 1e-9) - i8::from(cross < -1e-9),
                    )
                })
                .collect();
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            let d = near[0].0;
            if d <= reach - 1e-9 {
                let o = field.owner[i];
                assert_ne!(o, NONE, "{p} at {d} has no sample");
                assert!(
                    (f64::from(field.dist[i]) - d).abs() < 1e-4,
                    "{p}: {} against {d}",
                    field.dist[i]
                );
                let to_owner = p.distance(line[o as usize]);
                assert!(
                    to_owner <= (d * d + half * half).sqrt() + 1e-6,
                    "{p}: sample {o} is {to_owner} away, the line {d}"
                );
                // Where one segment is clearly the nearest and the cell is off the line, its side.
                if d > 1e-3 && near.get(1).is_none_or(|n| n.0 > d + 1e-3 || n.1 == near[0].1) {
                    assert_eq!(field.side[i], near[0].1, "{p}: the side");
                }
            } else if d > reach + 1e-9 {
                assert_eq!(field.owner[i], NONE, "{p} at {d} is beyond the reach");
            }
        }
    }
}

#[test]
fn the_nearest_sample_field_is_the_same_filled_in_two_bands() {
    use penmodel_terrain::river::near;
    // 100 × 300 cells is filled as two bands of rows (split at row 150), 100 × 160 in one pass;
    // their common rows 0..160 have the same local coordinates, so they must agree bit for bit,
    // the band boundary included. The Ω's course, moved to cross row 150.
    let line: Vec<DVec2> = course::sample(
        &omega(18.0)
            .iter()
            .map(|p| DVec2::new(p[0] - 50.0, p[1] + 20.0))
            .collect::<Vec<_>>(),
        1.0,
    )
    .iter()
    .map(|s| s.p)
    .collect();
    let (tall, short) = (
        river::Window {
            c0: 0,
            r0: 0,
            width: 100,
            height: 300,
        },
        river::Window {
            c0: 0,
            r0: 0,
            width: 100,
            height: 160,
        },
    );
    let (a, b) = (near::nearest(&tall, &line, 9.0), near::nearest(&short, &line, 9.0));
    let n = short.len();
    assert!(
        b.owner.iter().filter(|&&o| o != near::NONE).count() > 1000,
        "the course is in the window"
    );
    assert_eq!(a.owner[..n], b.owner[..]);
    assert_eq!(a.side[..n], b.side[..]);
    let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.dist[..n]), bits(&b.dist));
}

#[test]
fn a_pull_under_a_river_recarves_it() {
    use penmodel_terrain::{Edit, Editor, FigurePath, generate};
    let d = river_doc();
    let mut ed = Editor::new(d).expect("valid");
    // The hill the course runs past, pulled up and then down: the ground under the river
    // changes, and the carving follows it as a fresh generation would.
    for height in [60.0, 5.0] {
        ed.apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height,
        })
        .expect("pulled");
        assert_eq!(
            ed.heightmap(),
            &generate(ed.document()).expect("valid"),
            "height {height}"
        );
        let water = ed.water().expect("water");
        let wet = (0..water.level.len()).filter(|&i| !water.level[i].is_nan());
        assert!(wet.clone().count() > 0);
        assert!(wet.into_iter().all(|i| water.level[i] > ed.heightmap().heights()[i]));
    }
}

/// Components of the cells where `keep` holds, 4-connected (a flood fill of the test's own);
/// per cell its component or `usize::MAX`.
fn components(w: usize, h: usize, keep: impl Fn(usize) -> bool) -> (usize, Vec<usize>) {
    let mut label = vec![usize::MAX; w * h];
    let mut count = 0;
    for start in 0..w * h {
        if label[start] != usize::MAX || !keep(start) {
            continue;
        }
        let mut stack = vec![start];
        label[start] = count;
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            let mut next = Vec::with_capacity(4);
            if x > 0 {
                next.push(i - 1);
            }
            if x + 1 < w {
                next.push(i + 1);
            }
            if y > 0 {
                next.push(i - w);
            }
            if y + 1 < h {
                next.push(i + w);
            }
            for j in next {
                if label[j] == usize::MAX && keep(j) {
                    label[j] = count;
                    stack.push(j);
                }
            }
        }
        count += 1;
    }
    (count, label)
}

/// Twenty years of a gentle meander (six bends, 3 m wide on 256²): the bends grow for years
/// before a neck closes, the water stays one river from source to mouth for 15 years, and the
/// lakes stay few — the seed shows one oxbow lake at a sharp bend; read over one width, the
/// bends' small wiggles grew into chains of loops and this meander left 84 lakes.
#[test]
fn a_meander_ages_into_few_oxbow_lakes_and_stays_one_river() {
    let rv = river::meander(256, 14, 3.0, 20);
    let mut shape = Shape::new(&rv, &grid(256), &Constants::default());
    let (w, h) = (shape.window.width, shape.window.height);
    let origin = shape.window.origin();
    let cell = |p: DVec2| {
        let q = (p - origin).round();
        q.y as usize * w + q.x as usize
    };
    for year in 1..=20 {
        shape.step();
        // (From about year 17 the bends have wandered so far from the fixed ends that the water
        // there can part from the rest; docs/rivers.md, limits. Read over one width, year 6.)
        if year <= 15 {
            let (_, water) = components(w, h, |i| shape.mask[i] != 0);
            let (source, mouth) = (shape.line[0].p, shape.line[shape.line.len() - 1].p);
            let (a, b) = (water[cell(source)], water[cell(mouth)]);
            assert!(
                a != usize::MAX && a == b,
                "year {year}: the water no longer joins source and mouth"
            );
        }
        if year <= 5 {
            assert!(
                !shape.lakes.iter().any(|&l| l != 0),
                "year {year}: a neck closed before the bends grew"
            );
        }
    }
    let (lakes, _) = components(w, h, |i| shape.lakes[i] != 0);
    assert!((1..=20).contains(&lakes), "{lakes} lakes after 20 years");
}

/// The cells of `c` as a sorted list of `(erosion?, column, row)`, for comparing as sets.
fn cell_set(c: &river::drag::Cells) -> std::collections::BTreeSet<(bool, u32, u32)> {
    let tag = |e: bool| move |p: &[u32; 2]| (e, p[0], p[1]);
    c.erosion
        .iter()
        .map(tag(true))
        .chain(c.deposition.iter().map(tag(false)))
        .collect()
}

/// A drag's preview (`river::drag`) processes only the part of the course the held point
/// reaches, and takes the rest from the river as grabbed. Against the whole moved river's
/// preview (`Shape::process` here) it differs in at most 2 % of the cells as drawn, and 12.5 % after
/// three years (or twice the most that nudging the point a further 5 cm changes in the exact
/// preview: the years' resampling makes it that sensitive); when the reach is the whole course it
/// is that preview exactly.
#[test]
fn a_drag_preview_is_the_moved_rivers_where_the_point_reaches() {
    use river::drag::{Cells, Drag};
    let g = grid(512);
    let c = Constants::default();
    for years in [0, 3] {
        let r = river::meander(512, 14, 4.0, years);
        for k in [19, 20, 21] {
            let drag = Drag::new(&r, k, &g, &c);
            let part = drag.part().expect("part of a 40-point course");
            assert!(part.first <= k && k <= part.last && part.last - part.first < r.points.len() - 1);
            let mut moved = r.clone();
            moved.points[k] = [moved.points[k][0] + 6.0, moved.points[k][1] - 4.0];
            let full = cell_set(&Cells::of(&Shape::process(&moved, &g, &c)));
            let got = cell_set(&drag.preview(&moved));
            // The exact preview's own sensitivity: the most a 5 cm nudge of the point changes.
            let sensitive = [[0.05, 0.0], [-0.05, 0.0], [0.0, 0.05], [0.0, -0.05]]
                .iter()
                .map(|d| {
                    let mut nudged = moved.clone();
                    nudged.points[k] = [moved.points[k][0] + d[0], moved.points[k][1] + d[1]];
                    let nudge = cell_set(&Cells::of(&Shape::process(&nudged, &g, &c)));
                    full.symmetric_difference(&nudge).count()
                })
                .max()
                .unwrap_or(0);
            let differ = full.symmetric_difference(&got).count();
            eprintln!(
                "{years} years, point {k}: points {}..={} processed; {} cells, {differ} differ (a 5 cm nudge: {sensitive})",
                part.first,
                part.last,
                full.len()
            );
            // As drawn, only the cells at the cut's seams differ; after years the part's own
            // resampling drifts from the whole line's, about as much as a nudge moves it.
            let limit = if years == 0 { full.len() / 50 } else { full.len() / 8 };
            assert!(differ <= limit.max(2 * sensitive), "{differ} of {} differ", full.len());
        }
    }
    // Ten years reach the whole course: the whole river, exactly.
    let r = river::meander(256, 6, 4.0, 10);
    let drag = Drag::new(&r, 7, &g, &c);
    assert_eq!(drag.part(), None);
    let mut moved = r.clone();
    moved.points[7][0] += 3.0;
    assert_eq!(drag.preview(&moved), Cells::of(&Shape::process(&moved, &g, &c)));
}
