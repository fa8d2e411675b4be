//! Rock fields in the document (version 2): loading old documents, validation naming the
//! element, edits with undo, and rocks standing on the terrain as it changes — the ground
//! checked against the terrain's triangles by a computation of the test's own.

use penmodel_terrain::document::{RockField, RockLayer, VERSION};
use penmodel_terrain::rocks::cache::Rocks;
use penmodel_terrain::{Document, Edit, Editor, FigurePath, Heightmap, Region};

use crate::common::{document, point, polygon};

fn field(at: [f64; 2]) -> RockField {
    RockField {
        at,
        outline: vec![[0.0, 0.0], [50.0, 0.0], [50.0, 40.0], [0.0, 40.0], [0.0, 0.0]],
        cell_size: 0.5,
        layers: vec![
            RockLayer {
                radius: 8.0,
                fraction: Some(0.3),
                count: None,
                widths: [0.0, 0.3, 0.3],
                heights: [0.3, 0.3, 0.1],
            },
            RockLayer {
                radius: 3.0,
                fraction: Some(0.3),
                count: None,
                widths: [0.0, 0.0, 0.0],
                heights: [0.3, 0.0, 0.1],
            },
        ],
        seed: 7,
    }
}

/// A 128 m square grid, one region over most of it with a peak, and a rock field on its flank.
fn doc() -> Document {
    let region = Region {
        metric: None,
        boundary: polygon([64.0, 64.0], 60.0, 24, 0.1),
        figures: vec![point([64.0, 64.0], 30.0, 0.0)],
    };
    let mut d = document(128, vec![region]);
    d.rocks.push(field([40.0, 30.0]));
    d
}

#[test]
fn a_version_1_document_loads_as_the_current_version() {
    let text = include_str!("../../examples/04-volcano.json");
    assert!(text.contains("\"version\": 1"), "the example is a version 1 file");
    let doc = Document::from_json(text).expect("version 1 loads");
    assert_eq!(doc.version, VERSION);
    assert!(doc.rocks.is_empty());
    assert!(doc.to_json().contains(&format!("\"version\": {VERSION}")));
    // Rock fields need version 2; a version 2 file with them loads.
    let mut v2 = doc.clone();
    v2.rocks.push(field([40.0, 30.0]));
    // Written as an older version: without version 4's terrain settings (it loads as taxicab).
    let mut older = v2.clone();
    older.terrain = Default::default();
    let current = format!("\"version\": {VERSION}");
    let with_rocks = older.to_json().replace(&current, "\"version\": 1");
    let e = Document::from_json(&with_rocks).expect_err("rocks in a version 1 file");
    assert_eq!(e.to_string(), "rocks: needs document version 2");
    let as_v2 = Document::from_json(&older.to_json().replace(&current, "\"version\": 2")).expect("version 2 loads");
    assert_eq!(as_v2, v2);
    let unknown = format!("\"version\": {}", VERSION + 1);
    let e = Document::from_json(&text.replace("\"version\": 1", &unknown)).expect_err("a future version");
    assert!(e.to_string().contains(&format!("reads versions 1 to {VERSION}")), "{e}");
}

#[test]
fn a_rock_field_round_trips() {
    let d = doc();
    let back = Document::from_json(&d.to_json()).expect("valid");
    assert_eq!(back, d);
}

#[test]
fn bad_fields_are_named() {
    type Change = Box<dyn Fn(&mut RockField)>;
    let cases: Vec<(Change, &str)> = vec![
        (
            Box::new(|f| f.layers[1].radius = 0.0),
            "rocks[0].layers[1].radius: 0 must be above 0",
        ),
        (
            Box::new(|f| f.layers[0].radius = 90.0),
            "rocks[0].layers[0].radius: 90 cells leaves no room for one rock",
        ),
        (
            Box::new(|f| f.layers[1].fraction = Some(0.8)),
            "rocks[0].layers: the fractions add up to 1.1",
        ),
        (
            Box::new(|f| f.layers[1].count = Some(3)),
            "rocks[0].layers[1]: give either a fraction or a count",
        ),
        (
            Box::new(|f| f.layers[0].heights[2] = -1.0),
            "rocks[0].layers[0].heights[2]: -1 must be from 0 to 10",
        ),
        (
            Box::new(|f| f.at = [200.0, 30.0]),
            "rocks[0].outline[0]: (200, 30) lies outside the grid",
        ),
        (
            Box::new(|f| f.outline.pop().map(|_| ()).unwrap_or(())),
            "rocks[0].outline: the curve is open",
        ),
        (Box::new(|f| f.cell_size = 0.0), "rocks[0].cell_size"),
    ];
    for (change, words) in cases {
        let mut d = doc();
        change(&mut d.rocks[0]);
        let e = Document::from_json(&d.to_json()).expect_err(words);
        assert!(e.to_string().starts_with(words), "{e} — expected {words}");
    }
    // Outside every region: a field in a corner the region does not reach.
    let mut d = doc();
    d.rocks[0].at = [0.5, 0.5];
    d.rocks[0].outline = vec![[0.0, 0.0], [8.0, 0.0], [8.0, 8.0], [0.0, 0.0]];
    d.rocks[0].layers.truncate(1);
    d.rocks[0].layers[0].radius = 2.0;
    let e = Document::from_json(&d.to_json()).expect_err("outside");
    assert_eq!(
        e.to_string(),
        "rocks[0]: lies outside every region: draw the field inside a region"
    );
}

#[test]
fn field_edits_undo_and_journal() {
    let mut d = doc();
    let f = d.rocks.pop().expect("a field");
    let mut ed = Editor::new(d.clone()).expect("valid");
    ed.apply(Edit::AddRocks {
        index: 0,
        field: f.clone(),
    })
    .expect("added");
    ed.apply(Edit::MoveRocks {
        index: 0,
        by: [5.0, -3.0],
    })
    .expect("moved");
    assert_eq!(ed.document().rocks[0].at, [45.0, 27.0]);
    let mut denser = ed.document().rocks[0].clone();
    denser.layers[1].fraction = Some(0.5);
    ed.apply(Edit::ReplaceRocks {
        index: 0,
        field: denser,
    })
    .expect("denser");
    ed.undo().expect("undo");
    ed.undo().expect("undo");
    assert_eq!(ed.document().rocks[0], f);
    ed.undo().expect("undo");
    assert_eq!(ed.document(), &d);
    // The edits as the journal writes them.
    let e = Edit::MoveRocks {
        index: 0,
        by: [1.0, 2.0],
    };
    let line = serde_json::to_string(&e).expect("json");
    assert_eq!(line, r#"{"op":"move_rocks","index":0,"by":[1.0,2.0]}"#);
    assert_eq!(serde_json::from_str::<Edit>(&line).expect("parses"), e);
    // Deleting the region under a field is refused: the document would not load.
    let mut ed = Editor::new(doc()).expect("valid");
    let e = ed.apply(Edit::DeleteRegion { index: 0 }).expect_err("refused");
    assert!(e.to_string().contains("rocks[0]: lies outside every region"), "{e}");
    assert_eq!(ed.document(), &doc());
}

/// The terrain's height at (x, z) on its mesh, found by locating the point in one of the two
/// triangles of its square and weighting the corners by the areas opposite them.
fn on_terrain(map: &Heightmap, x: f64, z: f64) -> f64 {
    let s = map.cell_size();
    let centre = |c: u32, r: u32| {
        (
            (f64::from(c) + 0.5) * s,
            (f64::from(r) + 0.5) * s,
            f64::from(map.get(c, r)),
        )
    };
    let c = (((x / s) - 0.5).floor().max(0.0) as u32).min(map.cols() - 2);
    let r = (((z / s) - 0.5).floor().max(0.0) as u32).min(map.rows() - 2);
    let (a, b, d, e) = (centre(c, r), centre(c + 1, r), centre(c, r + 1), centre(c + 1, r + 1));
    let area = |p: (f64, f64, f64), q: (f64, f64, f64), t: (f64, f64)| {
        ((q.0 - p.0) * (t.1 - p.1) - (q.1 - p.1) * (t.0 - p.0)) / 2.0
    };
    for [p, q, t] in [[a, d, b], [b, d, e]] {
        let whole = area(p, q, (t.0, t.1));
        let (wp, wq, wt) = (
            area(q, t, (x, z)) / whole,
            area(t, p, (x, z)) / whole,
            area(p, q, (x, z)) / whole,
        );
        if wp >= -1e-9 && wq >= -1e-9 && wt >= -1e-9 {
            return wp * p.2 + wq * q.2 + wt * t.2;
        }
    }
    panic!("({x}, {z}) is in neither triangle of square ({c}, {r})");
}

/// Checks that every rim vertex (a cell's own, 0 above the ground) of every field stands on the
/// terrain, and every vertex is at least on it.
fn check_seated(rocks: &Rocks, map: &Heightmap) -> usize {
    let seated = rocks.seated(map);
    let mut rims = 0;
    for (f, (_, mesh)) in rocks.fields().iter().zip(&seated) {
        let mut at = 0;
        // The mesh lists the rocks in the flat order (by place); every rock once.
        let mut seen = f.flat.order.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..f.scatter.rocks.len() as u32));
        for rock in f.flat.order.iter().filter_map(|&i| f.scatter.rocks.get(i as usize)) {
            for (k, v) in rock.mesh.vertices.iter().enumerate() {
                let p = mesh.positions[at + k];
                let ground = on_terrain(map, f64::from(p[0]), f64::from(p[2]));
                let expected = ground + v[2] * f.field.cell_size;
                assert!(
                    (f64::from(p[1]) - expected).abs() < 1e-3,
                    "vertex at {p:?}: {} on ground {ground}",
                    p[1]
                );
                if k < rock.polygon.len() {
                    rims += 1;
                }
            }
            at += rock.mesh.vertices.len();
        }
        assert_eq!(at, mesh.positions.len());
    }
    rims
}

#[test]
fn rocks_stand_on_the_terrain_and_follow_it() {
    let mut ed = Editor::new(doc()).expect("valid");
    let mut rocks = Rocks::of(ed.document());
    assert!(!rocks.fields()[0].scatter.rocks.is_empty());
    assert!(check_seated(&rocks, ed.heightmap()) > 100);
    // The peak rises: no scattering, the rocks follow.
    ed.apply(Edit::SetHeight {
        at: FigurePath::new(0, 0),
        height: 60.0,
    })
    .expect("pulled");
    assert_eq!(rocks.update(ed.document()), 0);
    check_seated(&rocks, ed.heightmap());
    // Moved: the same rocks, shifted.
    let before = rocks.seated(ed.heightmap());
    ed.apply(Edit::MoveRocks {
        index: 0,
        by: [6.0, 4.0],
    })
    .expect("moved");
    assert_eq!(rocks.update(ed.document()), 0, "a move scatters nothing");
    let after = rocks.seated(ed.heightmap());
    for (p, q) in before[0].1.positions.iter().zip(&after[0].1.positions) {
        assert!((q[0] - p[0] - 6.0).abs() < 1e-3 && (q[2] - p[2] - 4.0).abs() < 1e-3);
    }
    check_seated(&rocks, ed.heightmap());
    // Denser: scattered again.
    let mut denser = ed.document().rocks[0].clone();
    denser.layers[1].fraction = Some(0.5);
    ed.apply(Edit::ReplaceRocks {
        index: 0,
        field: denser,
    })
    .expect("denser");
    assert_eq!(rocks.update(ed.document()), 1);
    // Every kept cell lies inside the outline: its pixels' centres are.
    let f = &rocks.fields()[0];
    for rock in &f.scatter.rocks {
        for v in rock.polygon {
            let p = [v[0] * 0.5 + f.image.origin[0], v[1] * 0.5 + f.image.origin[1]];
            assert!(
                (-0.6..=50.6).contains(&p[0]) && (-0.6..=40.6).contains(&p[1]),
                "{p:?} outside the outline"
            );
        }
    }
}

#[test]
fn an_edit_away_from_a_field_leaves_its_rocks_alone() {
    let square = |x0: f64| vec![[x0, 5.0], [x0 + 90.0, 5.0], [x0 + 90.0, 95.0], [x0, 95.0], [x0, 5.0]];
    let mut d = Document::new(penmodel_terrain::Grid {
        cols: 200,
        rows: 100,
        cell_size: 1.0,
    });
    d.regions.push(Region {
        metric: None,
        boundary: square(5.0),
        figures: vec![point([50.0, 50.0], 30.0, 0.0)],
    });
    d.regions.push(Region {
        metric: None,
        boundary: square(105.0),
        figures: vec![point([150.0, 50.0], 30.0, 0.0)],
    });
    d.rocks.push(field([20.0, 20.0]));
    let mut ed = Editor::new(d).expect("valid");
    let before = ed.rocks().shared();
    // The other region's peak: its terrain is not under the field.
    ed.apply(Edit::SetHeight {
        at: FigurePath::new(1, 0),
        height: 50.0,
    })
    .expect("pulled");
    assert!(
        std::sync::Arc::ptr_eq(&before, &ed.rocks().shared()),
        "re-seated for a change elsewhere"
    );
    // The field's own region: its rocks follow.
    ed.apply(Edit::SetHeight {
        at: FigurePath::new(0, 0),
        height: 50.0,
    })
    .expect("pulled");
    let after = ed.rocks().shared();
    assert!(!std::sync::Arc::ptr_eq(&before, &after));
    assert_ne!(before[0].1.positions, after[0].1.positions);
    check_seated(&Rocks::of(ed.document()), ed.heightmap());
    // What the editor keeps up to date is what seating everything afresh gives.
    assert_eq!(
        ed.rocks().meshes(),
        &Rocks::of(ed.document()).seated(ed.heightmap())[..]
    );
    ed.apply(Edit::SetHeight {
        at: FigurePath::new(1, 0),
        height: 10.0,
    })
    .expect("pulled");
    ed.apply(Edit::MoveRocks {
        index: 0,
        by: [3.0, 2.0],
    })
    .expect("moved");
    assert_eq!(
        ed.rocks().meshes(),
        &Rocks::of(ed.document()).seated(ed.heightmap())[..]
    );
}

/// Pulls under a field one after another (the editor finds where each vertex reads the
/// heightmap on its second seat at a place and reads only the heights after that), moves
/// between them: after each edit the editor's rocks are what seating afresh gives, and stand on
/// the terrain by the test's own interpolation.
#[test]
fn rocks_follow_successive_pulls_and_moves() {
    let mut ed = Editor::new(doc()).expect("valid");
    let pull = |ed: &mut Editor, height: f64| {
        ed.apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height,
        })
        .expect("pulled");
    };
    let same = |ed: &Editor| {
        assert_eq!(
            ed.rocks().meshes(),
            &Rocks::of(ed.document()).seated(ed.heightmap())[..]
        );
        assert!(check_seated(&Rocks::of(ed.document()), ed.heightmap()) > 100);
    };
    for (k, height) in [40.0, 55.0, 20.0, 65.0].into_iter().enumerate() {
        pull(&mut ed, height);
        same(&ed);
        if k == 1 {
            ed.apply(Edit::MoveRocks {
                index: 0,
                by: [1.3, -0.7],
            })
            .expect("moved");
            same(&ed);
        }
    }
}

/// A change of the terrain in a small rectangle re-seats only the blocks of rocks over it
/// (`Flat::seat_on_within`), and the mesh is what seating everything afresh on the changed
/// terrain gives, bit for bit; a rectangle that misses the change would leave it stale.
#[test]
fn a_local_change_of_the_terrain_reseats_the_rocks_over_it_as_a_whole_reseat_would() {
    use penmodel_terrain::rocks::place::{self, Flat, Placement, Samples};
    use penmodel_terrain::rocks::{Recipe, scatter};
    let n = 128u32;
    let s = scatter(&Recipe::figure_1(n, n, 3), None).expect("a valid recipe");
    let flat = Flat::of(&s);
    let hill = |x: f64, y: f64| (5.0 * (x / 17.0).sin() * (y / 23.0).cos()) as f32;
    let heights: Vec<f32> = (0..n * n).map(|i| hill(f64::from(i % n), f64::from(i / n))).collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights.clone()).expect("heights");
    let at = Placement {
        origin: [0.0, 0.0],
        cell_size: 1.0,
    };
    let (mut mesh, mut samples) = (Default::default(), Samples::default());
    // Twice at the place: the second finds the samples, so the next reads only the heights.
    flat.seat_on(at, &map, &mut samples, &mut mesh);
    flat.seat_on(at, &map, &mut samples, &mut mesh);
    // Cells 40..50 × 60..70 raised.
    let mut raised = heights;
    for r in 60..70 {
        for c in 40..50 {
            raised[(r * n + c) as usize] += 3.0;
        }
    }
    let changed = Heightmap::from_heights(n, n, 1.0, raised).expect("heights");
    let fresh = flat.seat(at, place::ground(&changed).surface());
    let mut stale = mesh.clone();
    let mut stale_samples = samples.clone();
    flat.seat_on_within(at, &changed, &mut samples, &mut mesh, Some([40.0, 60.0, 50.0, 70.0]));
    assert_eq!(mesh, fresh);
    flat.seat_on_within(
        at,
        &changed,
        &mut stale_samples,
        &mut stale,
        Some([100.0, 100.0, 110.0, 110.0]),
    );
    assert_ne!(stale, fresh, "the blocks over the change were skipped");
}

/// A seated mesh's normals are its triangles' area-weighted normals (summed here in f64 from
/// its positions), on a slope and at a field cell of 0.7 m away from the origin, moved or not.
#[test]
fn seated_rocks_have_their_triangles_area_weighted_normals() {
    use penmodel_terrain::rocks::place::{Flat, Placement, Samples};
    use penmodel_terrain::rocks::{Recipe, scatter};
    let n = 96u32;
    let s = scatter(&Recipe::figure_1(n, n, 5), None).expect("a valid recipe");
    let flat = Flat::of(&s);
    let hill = |x: f64, y: f64| (4.0 * (x / 13.0).sin() * (y / 19.0).cos() + 0.3 * x) as f32;
    let heights: Vec<f32> = (0..n * n).map(|i| hill(f64::from(i % n), f64::from(i / n))).collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights).expect("heights");
    let (mut mesh, mut samples) = (Default::default(), Samples::default());
    for origin in [[3.0, 5.0], [3.25, 5.5], [3.25, 5.5]] {
        let at = Placement { origin, cell_size: 0.7 };
        flat.seat_on(at, &map, &mut samples, &mut mesh);
        let p: Vec<[f64; 3]> = mesh.positions.iter().map(|p| p.map(f64::from)).collect();
        let mut sums = vec![[0.0f64; 3]; p.len()];
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| p[i as usize]);
            let (u, w) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let cross = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            for &i in t {
                for k in 0..3 {
                    sums[i as usize][k] += cross[k];
                }
            }
        }
        let mut checked = 0;
        for (s, m) in sums.iter().zip(&mesh.normals) {
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            // Sums of area near 0 (a sliver's vertex) leave the direction to rounding.
            if len < 1e-3 {
                continue;
            }
            let dot = (s[0] * f64::from(m[0]) + s[1] * f64::from(m[1]) + s[2] * f64::from(m[2])) / len;
            assert!(dot > 1.0 - 1e-4, "normal {m:?} against the sum {s:?} at {origin:?}");
            checked += 1;
        }
        assert!(
            checked * 100 >= sums.len() * 99,
            "{checked} of {} normals checked",
            sums.len()
        );
    }
}

/// A moving field (every seat at a new place) stands where a fresh seat through the ground's
/// general height puts it, bit for bit, whether its rocks lie wholly within the terrain's squares
/// (seated without holding each vertex in) or across the terrain's edges; and its rim vertices
/// within the squares stand on the terrain's triangles.
#[test]
fn a_moving_field_seats_as_a_fresh_seat_does_within_the_terrain_and_across_its_edges() {
    use penmodel_terrain::rocks::place::{self, Flat, Placement, Samples};
    use penmodel_terrain::rocks::{Recipe, scatter};
    let n = 96u32;
    let s = scatter(&Recipe::figure_1(n, n, 7), None).expect("a valid recipe");
    let flat = Flat::of(&s);
    let (m, step) = (64u32, 1.5);
    let hill = |x: f64, y: f64| (6.0 * (x / 11.0).sin() * (y / 7.0).cos() - 0.2 * y) as f32;
    let heights: Vec<f32> = (0..m * m).map(|i| hill(f64::from(i % m), f64::from(i / m))).collect();
    let map = Heightmap::from_heights(m, m, step, heights).expect("heights");
    // The outer centres: beyond them the terrain is held flat.
    let within = |v: f64| (0.5 * step..=(f64::from(m) - 0.5) * step).contains(&v);
    let (mut mesh, mut samples) = (Default::default(), Samples::default());
    let (mut whole, mut across, mut rims) = (0, 0, 0);
    for origin in [
        [-9.7, 3.1],
        [0.0, 0.0],
        [1.0 / 3.0, 2.0 / 3.0],
        [30.2, 41.9],
        [-20.0, -20.0],
    ] {
        let at = Placement { origin, cell_size: 0.9 };
        flat.seat_on(at, &map, &mut samples, &mut mesh);
        assert_eq!(mesh, flat.seat(at, place::ground(&map).surface()), "at {origin:?}");
        let mut first = 0;
        for rock in flat.order.iter().filter_map(|&i| s.rocks.get(i as usize)) {
            let p = &mesh.positions[first..first + rock.mesh.vertices.len()];
            let inside = |q: &[f32; 3]| within(f64::from(q[0])) && within(f64::from(q[2]));
            if p.iter().all(inside) {
                whole += 1;
            } else if p.iter().any(inside) {
                across += 1;
            }
            for q in p[..rock.polygon.len()].iter().filter(|q| inside(q)) {
                let ground = on_terrain(&map, f64::from(q[0]), f64::from(q[2]));
                assert!(
                    (f64::from(q[1]) - ground).abs() < 1e-3,
                    "rim vertex {q:?} on ground {ground}"
                );
                rims += 1;
            }
            first += rock.mesh.vertices.len();
        }
    }
    assert!(
        whole > 1000 && across > 20 && rims > 10_000,
        "{whole} rocks within, {across} across, {rims} rims"
    );
}
