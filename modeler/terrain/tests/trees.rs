//! Fractal trees (seed 004): the IFS maps, the full tree against the map recursion, the LOD walk
//! against the seed's data-volume law, the choice of Q, wind, groves.

use glam::{DAffine3, DVec3};
use penmodel_terrain::document::{IfsMap, Sway, Wind};
use penmodel_terrain::trees::lod::law;
use penmodel_terrain::trees::nodes::{self, STOP};
use penmodel_terrain::trees::silhouette::{self, View};
use penmodel_terrain::trees::{Drawn, NodeTree, Preset, Roughness, Species, fit, wind};

fn drawn(tree: &NodeTree, q: f64) -> Drawn {
    let mut out = Drawn::default();
    tree.draw(q, &DAffine3::IDENTITY, None, &mut out);
    out
}

#[test]
fn table_3_1_is_the_seeds() {
    let s = Species::preset(Preset::Table31);
    let got: Vec<[f64; 4]> = s.maps.iter().map(|m| [m.y, m.s, m.theta_z, m.theta_y]).collect();
    let seed = [
        [0.40, 0.60, 10.0, 0.0],
        [0.24, 0.55, 40.0, 60.0],
        [0.16, 0.45, -40.0, 120.0],
        [0.08, 0.40, 50.0, 180.0],
        [0.08, 0.30, -60.0, 50.0],
    ];
    assert_eq!(got, seed);
    assert!((s.lambda() - 0.46).abs() < 1e-12);
    // ln 5 / ln 0.46 = −2.07 (the figure for the law).
    assert!((s.law_exponent() + 2.07).abs() < 0.005, "{}", s.law_exponent());
}

#[test]
fn every_preset_contracts_and_its_maps_are_the_seeds_composition() {
    for p in Preset::ALL {
        let s = Species::preset(p);
        assert_eq!(Preset::named(p.name()), Some(p));
        for m in &s.maps {
            assert!(m.s > 0.0 && m.s < 1.0, "{}: s = {}", p.name(), m.s);
            let a = m.affine();
            // Trans·Rot_y·Rot_z(−θz)·Scale by hand: the image of (0, 1, 0) leans by θz from +Y
            // in the plane turned θy about Y, and the base goes to (0, y, 0).
            let (tz, ty) = (m.theta_z.to_radians(), m.theta_y.to_radians());
            let lean = DVec3::new(tz.sin(), tz.cos(), 0.0) * m.s;
            let turned = DVec3::new(lean.x * ty.cos(), lean.y, -lean.x * ty.sin());
            let tip = a.transform_point3(DVec3::Y);
            assert!(
                (tip - (DVec3::new(0.0, m.y, 0.0) + turned)).length() < 1e-12,
                "{}: {tip}",
                p.name()
            );
            assert!((a.transform_point3(DVec3::ZERO) - DVec3::new(0.0, m.y, 0.0)).length() < 1e-12);
            // A similarity of ratio s: every vector's length scales by s.
            for v in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::new(1.0, -2.0, 0.5)] {
                let r = a.transform_vector3(v).length() / v.length();
                assert!((r - m.s).abs() < 1e-12);
            }
        }
    }
}

/// Polygons of the full tree by the map recursion alone: 6 quads per branch, a rhombus for
/// each map whose branch falls below 2 %.
fn polygons_by_recursion(maps: &[IfsMap], scale: f64) -> u64 {
    6 + maps
        .iter()
        .map(|m| {
            let s = scale * m.s;
            if s < STOP { 1 } else { polygons_by_recursion(maps, s) }
        })
        .sum::<u64>()
}

#[test]
fn the_full_tree_has_the_polygons_of_the_map_recursion() {
    for p in Preset::ALL {
        let s = Species::preset(p);
        let tree = NodeTree::build(&s);
        let want = polygons_by_recursion(&s.maps, 1.0);
        assert_eq!(tree.polygons(), want, "{}", p.name());
        // Two triangles per polygon (quads and rhombi).
        assert_eq!(tree.indices.len() as u64, 6 * want, "{}", p.name());
        assert_eq!(
            nodes::count_nodes(&s, STOP, u64::MAX),
            Some(tree.nodes.len() as u64),
            "{}",
            p.name()
        );
        // Every node's scale is its maps' product, at least 2 % of the tree.
        assert!(tree.nodes.iter().all(|n| n.scale >= STOP));
    }
}

#[test]
fn at_q0_near_the_viewer_the_walk_is_the_full_geometry() {
    let s = Species::preset(Preset::Table31);
    let tree = NodeTree::build(&s);
    for q in [0.001, 0.01, STOP * 0.999] {
        let d = drawn(&tree, q);
        assert!(d.impostors.is_empty());
        assert_eq!(d.polygons, tree.polygons());
        assert_eq!(d.mesh.positions, tree.positions);
        assert_eq!(d.mesh.colors, tree.colors);
        assert_eq!(d.mesh.indices.len(), tree.indices.len());
    }
}

#[test]
fn simplified_shapes_stand_for_groups_no_larger_than_q() {
    let tree = NodeTree::build(&Species::preset(Preset::Table31));
    for q in [0.05, 0.1, 0.3] {
        let d = drawn(&tree, q);
        for imp in &d.impostors {
            let n = tree.nodes[imp.node as usize];
            // Its extent: the node frame's image of (0, S_tree, 0), measured independently.
            let e = imp
                .transform
                .transform_vector3(DVec3::new(0.0, tree.height, 0.0))
                .length();
            assert!((e - imp.extent).abs() < 1e-9 * tree.height);
            assert!(e <= q * tree.height * (1.0 + 1e-12), "q {q}: {e}");
            // Its parent was drawn: bigger than Q.
            let i = imp.node as usize;
            let parent = (0..i)
                .rev()
                .find(|&j| tree.nodes[j].depth + 1 == n.depth && tree.nodes[j].end as usize > i);
            assert!(parent.is_some_and(|j| tree.nodes[j].scale > q), "q {q}: node {i}");
        }
        // Every part of the tree is drawn once: drawn nodes + the subtrees of the shapes.
        let covered: u64 = d
            .impostors
            .iter()
            .map(|i| {
                let n = tree.nodes[i.node as usize];
                u64::from(n.end) - u64::from(i.node)
            })
            .sum();
        assert_eq!(d.nodes + covered, tree.nodes.len() as u64);
    }
}

#[test]
fn equal_scales_follow_the_law_exactly_at_powers_of_lambda() {
    // M = 4 maps of one scale λ = 0.5: at Q = λ^k the walk copies levels 0..k−1 and draws level k
    // as shapes: (M^(k+1) − 1)/(M − 1), which the law approximates as (M/(M−1))·M^k.
    let maps: Vec<IfsMap> = (0..4)
        .map(|i| IfsMap {
            y: 0.2 + 0.05 * f64::from(i),
            s: 0.5,
            theta_z: 35.0,
            theta_y: 90.0 * f64::from(i),
        })
        .collect();
    let tree = NodeTree::build(&Species { maps: maps.clone() });
    for k in 1..=5u32 {
        let q = 0.5f64.powi(k as i32) * (1.0 + 1e-9);
        let d = drawn(&tree, q);
        let want = (4u64.pow(k + 1) - 1) / 3;
        assert_eq!(d.volume(), want, "k = {k}");
        let l = law(4, 0.5, q);
        // The law leaves out the −1/(M−1): within 1/M^(k+1) of it.
        assert!(
            (d.volume() as f64 / l - 1.0).abs() < 1.0 / 4f64.powi(k as i32 + 1) + 1e-6,
            "k {k}: {} vs {l}",
            d.volume()
        );
    }
}

/// Least-squares slope of ln N against ln Q.
fn fitted_exponent(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (sx, sy) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (q, v)| (a + q.ln(), b + v.ln()));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), (q, v)| {
        (a + (q.ln() - mx) * (v.ln() - my), b + (q.ln() - mx).powi(2))
    });
    num / den
}

#[test]
fn sample_3_2_is_the_seeds_and_its_volume_follows_its_dimension() {
    let s = Species::preset(Preset::Sample32);
    let got: Vec<[f64; 4]> = s.maps.iter().map(|m| [m.y, m.s, m.theta_z, m.theta_y]).collect();
    // Table 3.1, the block of Sample 3.2 (λ 0.45, OS 0.52, M 6).
    let seed = [
        [0.52, 0.52, -32.6, 40.2],
        [0.44, 0.52, 33.9, 40.5],
        [0.44, 0.38, 7.3, 45.0],
        [0.40, 0.47, 56.4, 45.2],
        [0.52, 0.28, 62.8, 180.0],
        [0.36, 0.55, -59.3, 134.8],
    ];
    assert_eq!(got, seed);
    assert!((s.lambda() - 0.45).abs() < 0.005, "λ {}", s.lambda());
    assert!((s.trunk() - 0.52).abs() < 1e-12, "OS {}", s.trunk());
    let tree = NodeTree::build(&s);
    let points: Vec<(f64, f64)> = [0.02, 0.03, 0.05, 0.07, 0.1, 0.14, 0.2]
        .into_iter()
        .map(|q| (q, drawn(&tree, q).volume() as f64))
        .collect();
    let slope = fitted_exponent(&points);
    eprintln!(
        "sample-3.2: fitted exponent {slope:.3}, law {:.3}, −D {:.3} (the seed fitted −2.39)",
        s.law_exponent(),
        -s.dimension()
    );
    // As for Sample 3.1, the count follows the similarity dimension of the unequal scales.
    assert!(
        (slope + s.dimension()).abs() < 0.05,
        "fitted {slope:.3}, −D = {:.3}",
        -s.dimension()
    );
}

#[test]
fn table_3_1_volume_against_the_law() {
    let s = Species::preset(Preset::Table31);
    let tree = NodeTree::build(&s);
    let qs = [0.02, 0.03, 0.05, 0.07, 0.1, 0.14, 0.2];
    let mut points = Vec::new();
    for q in qs {
        let v = drawn(&tree, q).volume() as f64;
        let l = law(s.m(), s.lambda(), q);
        // Found: N / law from 0.75 to 1.8 over these Q (λ is the mean of unequal scales).
        let r = v / l;
        eprintln!("Q {q}: N {v}, law {l:.0}, ratio {r:.2}");
        // Found: N / law from 2.88 (Q = 0.2) to 3.63 (Q = 0.02): λ = 0.46 is the mean of unequal
        // scales, and the larger ones (0.60, 0.55) branch deeper than a tree of mean scale would.
        assert!((2.85..3.7).contains(&r), "Q {q}: N {v}, law {l:.0}, ratio {r:.2}");
        points.push((q, v));
    }
    let slope = fitted_exponent(&points);
    eprintln!(
        "fitted exponent {slope:.3}, law {:.3}, −D {:.3}",
        s.law_exponent(),
        -s.dimension()
    );
    // The law's exponent is −2.07, the seed fitted −2.18 and −2.39; Moran's dimension of the
    // unequal scales is 2.16.
    assert!(
        (slope + s.dimension()).abs() < 0.03,
        "fitted {slope:.3}, −D = {:.3}",
        -s.dimension()
    );
    assert!((-2.45..-1.95).contains(&slope), "fitted {slope:.3}");
}

#[test]
fn wind_at_rest_is_the_rest_pose_and_tips_move_most() {
    let tree = NodeTree::build(&Species::preset(Preset::Table31));
    let place = DAffine3::from_translation(DVec3::new(3.0, 1.0, 2.0)) * DAffine3::from_scale(DVec3::splat(8.0));
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
    let mut still = Drawn::default();
    tree.draw(0.02, &place, None, &mut still);
    let mut rest = Drawn::default();
    tree.draw(0.02, &place, Some(&wind::pose(&gusty, 0.0)), &mut rest);
    assert_eq!(still.mesh.positions, rest.mesh.positions);
    // At t = 0.4 s every generation leans: the trunk's base stays, tips move further than the
    // trunk's top.
    let pose = wind::pose(&gusty, 0.4);
    assert!(pose.angles.iter().all(|a| a.abs() > 1e-3));
    let mut moved = Drawn::default();
    tree.draw(0.02, &place, Some(&pose), &mut moved);
    let shift = |i: usize| {
        let (a, b) = (still.mesh.positions[i], moved.mesh.positions[i]);
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    // The trunk's base ring (even vertices 0..10) turns about its centre, which stays.
    let centre = |m: &Drawn| {
        (0..6).fold(DVec3::ZERO, |c, k| {
            c + DVec3::from(m.mesh.positions[2 * k].map(f64::from))
        }) / 6.0
    };
    assert!(
        (centre(&still) - centre(&moved)).length() < 1e-5,
        "the trunk's base stays"
    );
    let trunk_top = shift(1);
    let max = (0..moved.mesh.positions.len()).map(shift).fold(0.0f32, f32::max);
    assert!(
        trunk_top > 1e-3 && max > 2.0 * trunk_top,
        "trunk top {trunk_top}, max {max}"
    );
    // The same time, the same pose.
    let mut again = Drawn::default();
    tree.draw(0.02, &place, Some(&wind::pose(&gusty, 0.4)), &mut again);
    assert_eq!(again.mesh.positions, moved.mesh.positions);
}

#[test]
fn q_by_distance_and_gaze() {
    let r = Roughness::default();
    let l0 = 10.0;
    let b = Roughness::near(l0);
    assert_eq!(b, 20.0);
    assert_eq!(r.by_distance(5.0, l0), r.q0);
    assert_eq!(r.by_distance(b, l0), r.q0);
    // Continuous at B: −a·L0/B + b = Q0.
    assert!((r.by_distance(b * (1.0 + 1e-9), l0) - r.q0).abs() < 1e-9);
    // −a·L0/D + b by hand.
    let d = 100.0;
    let want = -r.a * l0 / d + (r.q0 + r.a / 2.0);
    assert!((r.by_distance(d, l0) - want).abs() < 1e-15);
    // Rising with distance towards b.
    assert!(r.by_distance(1e6, l0) < r.b() && r.by_distance(1e6, l0) > r.by_distance(200.0, l0));
    // Gaze: full acuity within 6°, e^−1 at 6° + n.
    assert_eq!(r.acuity(3.0), 1.0);
    assert!((r.acuity(6.0 + r.n) - (-1.0f64).exp()).abs() < 1e-15);
    assert!((r.by_gaze(6.0 + 2.0 * r.n) - r.q0 * 2.0f64.exp()).abs() < 1e-15);
    // Kept within (0, 1].
    assert_eq!(r.by_gaze(90.0), 1.0);
    assert!(r.choose(5.0, l0, 0.0) == r.q0);
}

#[test]
fn fitting_noisy_silhouettes_of_nudged_presets() {
    // The bench's experiment (30 steps, release) found table-3.1 0.827/0.907 -> 0.962/0.971 and
    // cypress 0.945/0.872 -> 0.952/0.946 (docs/trees.md); here 4 steps from the best template
    // only (a debug build is slow).
    for (p, seed) in [(Preset::Table31, 11u64), (Preset::Cypress, 5)] {
        let truth = fit::nudged(&Species::preset(p), 1.5, seed);
        let front = fit::speckled(&silhouette::render(&truth, View::Front, 128, STOP), 0.02, seed);
        let side = fit::speckled(&silhouette::render(&truth, View::Side, 128, STOP), 0.02, seed + 1);
        let f = fit::fit(
            &front,
            &side,
            fit::Options {
                iterations: 4,
                starts: 1,
                ..fit::Options::default()
            },
        )
        .expect("fits");
        // The correlations of the result, measured again here.
        let framed = |img: &silhouette::Image| img.framed(fit::SIZE).expect("framed").blurred(2);
        let again = [
            silhouette::ncc(
                &silhouette::render(&f.species, View::Front, fit::SIZE, fit::FIT_STOP).blurred(2),
                &framed(&front),
            ),
            silhouette::ncc(
                &silhouette::render(&f.species, View::Side, fit::SIZE, fit::FIT_STOP).blurred(2),
                &framed(&side),
            ),
        ];
        assert_eq!(again, f.reached);
        assert!(
            f.reached[0] + f.reached[1] > f.start[0] + f.start[1] + 0.02,
            "{p:?}: {:?} from {:?}",
            f.reached,
            f.start
        );
        assert!(f.reached.iter().all(|&c| c > 0.9), "{:?}", f.reached);
    }
}

#[test]
fn ncc_is_one_for_equal_images_up_to_contrast_and_zero_when_flat() {
    let img = silhouette::render(&Species::preset(Preset::Oak), View::Front, 48, 0.05);
    let mut brighter = img.clone();
    brighter.data.iter_mut().for_each(|v| *v = 0.2 + 0.5 * *v);
    assert!((silhouette::ncc(&img, &brighter) - 1.0).abs() < 1e-6);
    let flat = silhouette::Image {
        width: 48,
        height: 48,
        data: vec![0.3; 48 * 48],
    };
    assert_eq!(silhouette::ncc(&img, &flat), 0.0);
    // A PNG written and read back frames to the same silhouette.
    let mut bytes = Vec::new();
    img.write_png(&mut bytes).expect("written");
    let back = silhouette::Image::read_png(std::io::Cursor::new(bytes)).expect("read");
    let (a, b) = (img.framed(32).expect("a"), back.framed(32).expect("b"));
    assert!(silhouette::ncc(&a, &b) > 0.99);
}

#[test]
fn coloured_meshes_export_to_obj_glb_and_ply() {
    use penmodel_terrain::export;
    let tree = NodeTree::build(&Species::preset(Preset::Fir));
    let d = drawn(&tree, 0.1);
    let cards = penmodel_terrain::trees::lod::cards(&tree, &d.impostors);
    assert_eq!(cards.indices.len(), 12 * d.impostors.len());
    let meshes = [("trees", &d.mesh), ("simplified shapes", &cards)];
    // OBJ: `v x y z r g b`, the bark and leaf colours.
    let mut obj = Vec::new();
    export::write_meshes(meshes.iter().map(|(n, m)| (*n, *m)), &mut obj).expect("obj");
    let text = String::from_utf8(obj).expect("utf-8");
    let first = text.lines().find(|l| l.starts_with("v ")).expect("a vertex");
    let f: Vec<f32> = first
        .split_whitespace()
        .skip(1)
        .map(|v| v.parse().expect("a number"))
        .collect();
    assert_eq!(f.len(), 6);
    assert_eq!([f[3], f[4], f[5]], penmodel_terrain::trees::shapes::BARK);
    // glTF: an independent reader finds COLOR_0 on both meshes.
    let mut glb = Vec::new();
    export::write_glb_meshes(&meshes, &mut glb).expect("glb");
    let gltf = gltf::Gltf::from_slice(&glb).expect("a valid glb");
    let blob = gltf.blob.clone().expect("a binary chunk");
    for (mesh, (_, m)) in gltf.meshes().zip(&meshes) {
        let prim = mesh.primitives().next().expect("a primitive");
        let reader = prim.reader(|_| Some(&blob));
        let colours: Vec<[f32; 3]> = reader.read_colors(0).expect("COLOR_0").into_rgb_f32().collect();
        assert_eq!(&colours, &m.colors);
        assert_eq!(
            reader.read_indices().expect("indices").into_u32().count(),
            m.indices.len()
        );
    }
    // PLY: the header's counts and the body's size.
    let mut ply = Vec::new();
    export::write_ply(&meshes, &mut ply).expect("ply");
    let end = ply.windows(11).position(|w| w == b"end_header\n").expect("a header") + 11;
    let head = String::from_utf8(ply[..end].to_vec()).expect("ascii");
    let vertices = d.mesh.positions.len() + cards.positions.len();
    let faces = (d.mesh.indices.len() + cards.indices.len()) / 3;
    assert!(head.contains(&format!("element vertex {vertices}\n")));
    assert!(head.contains(&format!("element face {faces}\n")));
    assert_eq!(ply.len() - end, vertices * (24 + 3) + faces * 13);
}
