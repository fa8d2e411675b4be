//! Trees and groves in the document (version 4): older versions load, validation names the
//! element, edits undo and journal, trees stand on the terrain and follow it, groves.

use penmodel_terrain::document::{Grove, GroveSpecies, Sway, Tree, VERSION, Wind};
use penmodel_terrain::trees::grove;
use penmodel_terrain::trees::{Preset, Source};
use penmodel_terrain::{Document, Edit, Editor, FigurePath, Region};

use crate::common::{document, point, polygon};

fn tree(at: [f64; 2]) -> Tree {
    Tree {
        at,
        height: 12.0,
        preset: Some("table-3.1".into()),
        maps: None,
        seed: 7,
        wind: None,
    }
}

fn a_grove() -> Grove {
    Grove {
        region: polygon([90.0, 90.0], 25.0, 16, 0.2),
        density: 150.0,
        mix: vec![
            GroveSpecies {
                preset: "oak".into(),
                weight: 2.0,
            },
            GroveSpecies {
                preset: "fir".into(),
                weight: 1.0,
            },
        ],
        height: 9.0,
        seed: 3,
        wind: None,
    }
}

fn doc() -> Document {
    // Through JSON, so that fields a region gains later take their defaults.
    let region: Region = serde_json::from_value(serde_json::json!({
        "boundary": polygon([64.0, 64.0], 60.0, 24, 0.1),
        "figures": [point([64.0, 64.0], 30.0, 0.0)],
    }))
    .expect("a region");
    document(128, vec![region])
}

const V1: &str = r#"{"version": 1, "grid": {"cols": 32, "rows": 32, "cell_size": 1.0},
  "regions": [{"boundary": [[2.0, 2.0], [30.0, 2.0], [30.0, 30.0], [2.0, 2.0]],
    "figures": [{"kind": "point", "points": [[20.0, 10.0]], "height": 5.0}]}]}"#;

#[test]
fn versions_1_to_3_load_without_trees() {
    let v2 = V1.replace("\"version\": 1", "\"version\": 2");
    let v3 = include_str!("../../examples/rivers/omega.json");
    for (v, text) in [(1, V1), (2, v2.as_str()), (3, v3)] {
        assert!(text.contains(&format!("\"version\": {v}")));
        let d = Document::from_json(text).unwrap_or_else(|e| panic!("version {v}: {e}"));
        assert_eq!(d.version, VERSION);
        assert!(d.trees.is_empty() && d.groves.is_empty(), "version {v}");
    }
    // Trees and groves need version 4.
    let with_trees = V1.replacen('{', r#"{"trees": [{"at": [10.0, 10.0], "height": 5.0}], "#, 1);
    let e = Document::from_json(&with_trees.replace("\"version\": 1", "\"version\": 3")).expect_err("v3 trees");
    assert_eq!(e.to_string(), "trees: needs document version 4");
    let with_groves = V1.replacen(
        '{',
        r#"{"groves": [{"region": [[3.0, 3.0], [9.0, 3.0], [9.0, 9.0], [3.0, 3.0]], "density": 100.0}], "#,
        1,
    );
    let e = Document::from_json(&with_groves).expect_err("v1 groves");
    assert_eq!(e.to_string(), "groves: needs document version 4");
    // In version 4 both load; left-out fields take their defaults.
    let v4 = with_trees.replace("\"version\": 1", "\"version\": 4");
    let d = Document::from_json(&v4).expect("v4 trees");
    assert_eq!(d.trees[0].seed, 0);
    assert_eq!(d.trees[0].preset, None);
    let d = Document::from_json(&with_groves.replace("\"version\": 1", "\"version\": 4")).expect("v4 groves");
    assert_eq!(d.groves[0].height, 10.0);
}

#[test]
fn trees_and_groves_round_trip() {
    let mut d = doc();
    let mut swaying = tree([30.0, 40.0]);
    swaying.preset = None;
    swaying.maps = Some(Preset::Cypress.maps());
    swaying.wind = Some(Wind {
        direction: 45.0,
        generations: vec![Sway {
            amplitude: 3.0,
            frequency: 0.5,
            rest: 1.0,
        }],
    });
    d.trees = vec![tree([20.0, 20.0]), swaying];
    d.groves = vec![a_grove()];
    let back = Document::from_json(&d.to_json()).expect("loads");
    assert_eq!(back, d);
}

fn refused(d: &Document) -> String {
    Document::from_json(&d.to_json()).expect_err("invalid").to_string()
}

#[test]
fn bad_trees_and_groves_are_named() {
    let mut d = doc();
    d.trees = vec![tree([20.0, 20.0])];
    d.trees[0].at = [500.0, 10.0];
    assert_eq!(
        refused(&d),
        "trees[0].at: (500, 10) lies outside the grid [0, 128) × [0, 128) m"
    );
    d.trees[0].at = [20.0, 20.0];
    d.trees[0].preset = Some("baobab".into());
    assert_eq!(
        refused(&d),
        "trees[0].preset: unknown preset \"baobab\"; the presets are table-3.1, sample-3.2, cypress, oak, fir"
    );
    d.trees[0].preset = None;
    let mut maps = Preset::Table31.maps();
    maps[1].s = 1.2;
    d.trees[0].maps = Some(maps.clone());
    assert_eq!(
        refused(&d),
        "trees[0].maps[1].s: |s| = 1.2 is not below 1: the IFS does not contract"
    );
    maps[1].s = 0.97;
    d.trees[0].maps = Some(maps);
    assert!(refused(&d).starts_with("trees[0].maps: the tree would have more than 100000 branches"));
    d.trees[0].maps = Some(vec![]);
    assert_eq!(refused(&d), "trees[0].maps: a tree needs 1 to 8 maps, found 0");
    d.trees[0].maps = Some(Preset::Oak.maps());
    d.trees[0].preset = Some("oak".into());
    assert_eq!(refused(&d), "trees[0]: give either a preset or maps, not both");
    d.trees[0].maps = None;
    d.trees[0].height = 0.0;
    assert_eq!(
        refused(&d),
        "trees[0].height: a tree's height must be above 0 and at most 1000 m, got 0"
    );
    d.trees[0].height = 10.0;
    d.trees[0].wind = Some(Wind {
        direction: 0.0,
        generations: vec![Sway {
            amplitude: 3.0,
            frequency: 50.0,
            rest: 0.0,
        }],
    });
    assert_eq!(
        refused(&d),
        "trees[0].wind.generations[0].frequency: 50 must be from 0 to 20"
    );
    d.trees[0].wind = None;
    d.groves = vec![a_grove()];
    d.groves[0].density = 1e7;
    assert!(
        refused(&d).starts_with("groves[0].density: 10000000 trees per hectare over "),
        "{}",
        refused(&d)
    );
    d.groves[0].density = 100.0;
    d.groves[0].mix[1].weight = 0.0;
    assert_eq!(refused(&d), "groves[0].mix[1].weight: 0 must be above 0");
    d.groves[0].mix[1].weight = 1.0;
    d.groves[0].region.pop();
    assert!(
        refused(&d).starts_with("groves[0].region: the curve is open"),
        "{}",
        refused(&d)
    );
}

#[test]
fn tree_and_grove_edits_undo_and_journal() {
    let d = doc();
    let dir = tempfile::tempdir().expect("a directory");
    let path = dir.path().join("trees.json");
    let mut ed = Editor::create(&path, d.clone()).expect("created");
    ed.apply(Edit::AddTree {
        index: 0,
        tree: tree([20.0, 20.0]),
    })
    .expect("added");
    ed.apply(Edit::MoveTree {
        index: 0,
        by: [5.0, -3.0],
    })
    .expect("moved");
    assert_eq!(ed.document().trees[0].at, [25.0, 17.0]);
    let mut taller = ed.document().trees[0].clone();
    taller.height = 20.0;
    ed.apply(Edit::ReplaceTree { index: 0, tree: taller }).expect("taller");
    ed.apply(Edit::AddGrove {
        index: 0,
        grove: a_grove(),
    })
    .expect("grove");
    ed.apply(Edit::MoveGrove {
        index: 0,
        by: [-10.0, 0.0],
    })
    .expect("grove moved");
    // Off the grid: refused, nothing changes.
    let before = ed.document().clone();
    let e = ed
        .apply(Edit::MoveTree {
            index: 0,
            by: [500.0, 0.0],
        })
        .expect_err("off the grid");
    assert!(
        e.to_string().contains("trees[0].at: (525, 17) lies outside the grid"),
        "{e}"
    );
    assert_eq!(ed.document(), &before);
    let e = ed.apply(Edit::DeleteTree { index: 3 }).expect_err("no tree 3");
    assert_eq!(e.to_string(), "there is no trees[3]");
    // The journal replays the edits into the same document (read-only: `ed` is its writer).
    let (reopened, report) = Editor::open_read_only(&path).expect("reopened");
    assert_eq!(report.replayed, 5);
    assert_eq!(reopened.document(), ed.document());
    drop(reopened);
    for _ in 0..5 {
        ed.undo().expect("undo");
    }
    assert_eq!(ed.document(), &d);
    let e = Edit::MoveTree {
        index: 0,
        by: [1.0, 2.0],
    };
    let line = serde_json::to_string(&e).expect("json");
    assert_eq!(line, r#"{"op":"move_tree","index":0,"by":[1.0,2.0]}"#);
    assert_eq!(serde_json::from_str::<Edit>(&line).expect("parses"), e);
}

#[test]
fn trees_stand_on_the_terrain_and_follow_it() {
    let mut d = doc();
    // At cell centres, where the terrain's surface is the cell's height exactly.
    d.trees = vec![tree([64.5, 64.5]), tree([40.5, 70.5])];
    let mut ed = Editor::new(d).expect("valid");
    let base = |ed: &Editor, i: usize| ed.trees().trees()[i].base;
    let cell = |ed: &Editor, c: u32, r: u32| f64::from(ed.heightmap().get(c, r));
    assert_eq!(base(&ed, 0), cell(&ed, 64, 64));
    assert_eq!(base(&ed, 1), cell(&ed, 40, 70));
    assert!(base(&ed, 0) > 25.0, "on the peak: {}", base(&ed, 0));
    let at = FigurePath::new(0, 0);
    ed.apply(Edit::SetHeight { at, height: 50.0 }).expect("pulled");
    assert_eq!(base(&ed, 0), cell(&ed, 64, 64));
    assert_eq!(base(&ed, 1), cell(&ed, 40, 70));
    assert!(base(&ed, 0) > 45.0);
    // Moved, it stands on the ground where it went.
    ed.apply(Edit::MoveTree {
        index: 1,
        by: [3.0, -20.0],
    })
    .expect("moved");
    assert_eq!(base(&ed, 1), cell(&ed, 43, 50));
    // The placement puts the trunk's foot there and the top at the tree's height.
    let t = &ed.trees().trees()[1];
    let foot = t.place().transform_point3(glam::DVec3::ZERO);
    assert_eq!([foot.x, foot.y, foot.z], [43.5, base(&ed, 1), 50.5]);
    let top = t.place().transform_vector3(glam::DVec3::new(0.0, t.nodes.height, 0.0));
    assert!((top.length() - 12.0).abs() < 1e-9);
}

#[test]
fn groves_are_deterministic_spaced_and_at_their_density() {
    let g = a_grove();
    let trees = grove::trees(&g);
    assert_eq!(trees, grove::trees(&g), "the same grove, the same trees");
    let mut other = g.clone();
    other.seed = 4;
    assert_ne!(trees, grove::trees(&other));
    let area = grove::area(&g.region);
    let expected = g.density / 10_000.0 * area;
    let n = trees.len() as f64;
    // Found: 33 trees for 28.7 expected (a small grove: its edge and the draw's spread).
    assert!((n / expected - 1.0).abs() < 0.2, "{n} trees, {expected:.1} expected");
    let (pixel, _, _) = grove::image(&g);
    let min = grove::spacing(g.density) - pixel * 2f64.sqrt();
    for (i, a) in trees.iter().enumerate() {
        assert_eq!(
            penmodel_terrain::geometry::locate(&g.region, a.at),
            penmodel_terrain::geometry::Side::Inside
        );
        assert!((0.8 * g.height..=1.2 * g.height).contains(&a.height));
        assert!(matches!(a.preset, Preset::Oak | Preset::Fir));
        for b in &trees[i + 1..] {
            let d = ((a.at[0] - b.at[0]).powi(2) + (a.at[1] - b.at[1]).powi(2)).sqrt();
            assert!(d >= min, "{d} < {min}");
        }
    }
    // The editor stands every grove tree after the document's own trees.
    let mut d = doc();
    d.trees = vec![tree([20.5, 20.5])];
    d.groves = vec![g];
    let ed = Editor::new(d).expect("valid");
    let standing = ed.trees().trees();
    assert_eq!(standing.len(), 1 + trees.len());
    assert_eq!(standing[0].source, Source::Tree(0));
    assert_eq!(standing[1].source, Source::Grove(0, 0));
    assert_eq!(standing[1].at, trees[0].at);
}

#[test]
fn a_large_weighted_mix_draws_presets_by_weight() {
    let mut g = a_grove();
    g.region = polygon([64.0, 64.0], 60.0, 24, 0.1);
    g.density = 800.0;
    let trees = grove::trees(&g);
    let oaks = trees.iter().filter(|t| t.preset == Preset::Oak).count() as f64;
    let share = oaks / trees.len() as f64;
    let expected = g.density / 10_000.0 * grove::area(&g.region);
    // Found: 876 trees for 894.5 expected (−2 %: on the pixel lattice no two seeds are exactly
    // r apart, so the least distance is a little more than r).
    let n = trees.len() as f64;
    assert!((n / expected - 1.0).abs() < 0.05, "{n} trees, {expected:.1} expected");
    // Weights 2 : 1 (found 0.667); a binomial share of ~900 trees is within 0.06 of 2/3 at 3 sigma.
    assert!((share - 2.0 / 3.0).abs() < 0.06, "{share} of {}", trees.len());
}

/// Whether two forests stand the same trees, bit for bit (the species' node trees by their
/// height and size: each forest builds its own).
fn same_forest(a: &penmodel_terrain::trees::Forest, b: &penmodel_terrain::trees::Forest) -> Result<(), String> {
    let (a, b) = (a.trees(), b.trees());
    if a.len() != b.len() {
        return Err(format!("{} trees against {}", a.len(), b.len()));
    }
    for (k, (s, t)) in a.iter().zip(b).enumerate() {
        let key = |x: &penmodel_terrain::trees::Standing| {
            (
                x.source,
                x.at.map(f64::to_bits),
                x.base.to_bits(),
                x.height.to_bits(),
                x.turn.to_bits(),
                x.nodes.height.to_bits(),
                x.nodes.nodes.len(),
                x.wind.as_deref().cloned(),
            )
        };
        if key(s) != key(t) {
            return Err(format!("tree {k}: {:?} against {:?}", key(s), key(t)));
        }
    }
    Ok(())
}

/// Trees over a whole 128² grid: single trees (some at its edges) and a grove.
fn forest_doc() -> Document {
    let mut d = doc();
    let mut state = 12345u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    d.trees = (0..60)
        .map(|_| tree([0.5 + 127.0 * next(), 0.5 + 127.0 * next()]))
        .collect();
    d.trees
        .extend([tree([0.1, 0.1]), tree([127.9, 64.0]), tree([64.0, 127.9])]);
    d.groves = vec![a_grove()];
    d
}

/// A change of the terrain in a rectangle re-stands only the trees over it (found through the
/// forest's squares of the ground), and the forest is what standing every tree afresh on the
/// changed terrain gives, bit for bit; a rectangle that misses the change leaves it stale.
#[test]
fn a_local_change_of_the_terrain_restands_the_trees_over_it_as_a_whole_forest_would() {
    use penmodel_terrain::Heightmap;
    use penmodel_terrain::trees::Forest;
    let n = 128u32;
    let d = forest_doc();
    let hill = |x: f64, y: f64| (5.0 * (x / 17.0).sin() * (y / 23.0).cos()) as f32;
    let heights: Vec<f32> = (0..n * n).map(|i| hill(f64::from(i % n), f64::from(i / n))).collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights.clone()).expect("heights");
    // Raised: cells 50..85 × 60..100 (the grove's west side and single trees) and, at the grid's
    // corner, 0..3 × 0..3 (the ground beyond the edge is held at them: a tree outside still reads
    // them).
    let mut raised = heights;
    let cells = [(50u32, 60u32, 35u32, 40u32), (0, 0, 3, 3)];
    for &(c0, r0, w, h) in &cells {
        for r in r0..r0 + h {
            for c in c0..c0 + w {
                raised[(r * n + c) as usize] += 3.0;
            }
        }
    }
    let changed = Heightmap::from_heights(n, n, 1.0, raised).expect("heights");
    let fresh = Forest::of(&d, &changed);
    let before = Forest::of(&d, &map);
    let moved = fresh
        .trees()
        .iter()
        .zip(before.trees())
        .filter(|(a, b)| a.base != b.base)
        .count();
    assert!(moved > 10, "the change moves {moved} trees");
    let mut forest = before.clone();
    for &rect in &cells {
        forest.follow(&d, &changed, Some(rect));
    }
    same_forest(&forest, &fresh).expect("the same as standing afresh");
    // A rectangle elsewhere: the trees over the change keep their old bases.
    let mut stale = before.clone();
    stale.follow(&d, &changed, Some((100, 10, 8, 8)));
    assert!(
        same_forest(&stale, &fresh).is_err(),
        "the trees over the change were skipped"
    );
    // A tree of the document moved: it alone is stood again, where it went.
    let mut d2 = d.clone();
    d2.trees[3].at = [20.5, 110.5];
    d2.trees[4].height = 30.0;
    forest.follow(&d2, &changed, Some((0, 0, 0, 0)));
    same_forest(&forest, &Forest::of(&d2, &changed)).expect("a changed tree stood again");
    // And the terrain changed under where it went: it is found in its new square.
    let mut raised2: Vec<f32> = changed.heights().to_vec();
    raised2[(110 * n + 20) as usize] -= 2.0;
    let changed2 = Heightmap::from_heights(n, n, 1.0, raised2).expect("heights");
    forest.follow(&d2, &changed2, Some((20, 110, 1, 1)));
    same_forest(&forest, &Forest::of(&d2, &changed2)).expect("found where it went");
}

/// Random edits through the editor (figures' heights that change the terrain locally, trees
/// moved, resized, added and removed, a grove changed, undo): after each, the editor's forest is
/// a fresh one on its terrain, bit for bit.
#[test]
fn the_editors_forest_follows_random_edits_as_a_fresh_one() {
    use penmodel_terrain::trees::Forest;
    use rand::{RngExt, SeedableRng};
    let mut d = forest_doc();
    d.regions[0].figures.extend([
        point([30.0, 40.0], 8.0, 0.0),
        point([90.0, 30.0], -6.0, 0.0),
        point([40.0, 95.0], 12.0, 0.0),
    ]);
    let mut ed = Editor::new(d).expect("valid");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for step in 0..40 {
        let doc = ed.document();
        let edit = match rng.random_range(0..6) {
            0 | 1 => Edit::SetHeight {
                at: FigurePath::new(0, rng.random_range(0..doc.regions[0].figures.len())),
                height: rng.random_range(-20.0..40.0),
            },
            2 => Edit::MoveTree {
                index: rng.random_range(0..doc.trees.len()),
                by: [rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0)],
            },
            3 => {
                let index = rng.random_range(0..doc.trees.len());
                let mut tree = doc.trees[index].clone();
                tree.height = rng.random_range(2.0..30.0);
                Edit::ReplaceTree { index, tree }
            }
            4 => Edit::AddTree {
                index: rng.random_range(0..=doc.trees.len()),
                tree: tree([rng.random_range(5.0..120.0), rng.random_range(5.0..120.0)]),
            },
            _ => {
                let mut grove = doc.groves[0].clone();
                grove.height = rng.random_range(5.0..15.0);
                Edit::ReplaceGrove { index: 0, grove }
            }
        };
        if ed.apply(edit.clone()).is_err() {
            // Refused (a tree moved off the grid): nothing changed.
            continue;
        }
        if step % 7 == 6 {
            ed.undo().expect("undo");
        }
        same_forest(ed.trees(), &Forest::of(ed.document(), ed.heightmap()))
            .unwrap_or_else(|e| panic!("step {step} ({edit:?}): {e}"));
    }
}

/// `Editor::preview_tree` shows a tree's or grove's replacement unrecorded: a preview of another
/// element first restores the one shown, `commit_tree_preview` records what is shown as one step
/// whose undo returns to the element before the preview, and any other edit restores it first.
#[test]
fn tree_previews_restore_commit_once_and_give_way() {
    let mut d = doc();
    d.trees = vec![tree([20.5, 20.5]), tree([40.5, 40.5])];
    d.groves = vec![a_grove()];
    let original = d.clone();
    let mut ed = Editor::new(d).expect("valid");
    let taller = |ed: &Editor, i: usize, h: f64| Edit::ReplaceTree {
        index: i,
        tree: Tree {
            height: h,
            ..ed.document().trees[i].clone()
        },
    };
    for h in [15.0, 20.0, 18.0] {
        let e = taller(&ed, 0, h);
        ed.preview_tree(&e).expect("shown");
        assert_eq!(ed.document().trees[0].height, h);
        assert_eq!(ed.trees().trees()[0].height, h, "the forest shows it");
    }
    // Another element: the first is restored before the second shows.
    let e = taller(&ed, 1, 30.0);
    ed.preview_tree(&e).expect("shown");
    assert_eq!(ed.document().trees[0], original.trees[0]);
    assert_eq!(ed.document().trees[1].height, 30.0);
    // A grove, then committed: one step.
    let mut g = ed.document().groves[0].clone();
    g.height = 12.0;
    ed.preview_tree(&Edit::ReplaceGrove {
        index: 0,
        grove: g.clone(),
    })
    .expect("shown");
    assert_eq!(ed.document().trees, original.trees);
    let done = ed.commit_tree_preview().expect("recorded");
    assert_eq!(
        done,
        Some(Edit::ReplaceGrove {
            index: 0,
            grove: g.clone()
        })
    );
    assert!(!ed.previewing());
    assert_eq!(ed.commit_tree_preview().expect("nothing"), None);
    ed.undo().expect("undo");
    assert_eq!(ed.document(), &original);
    assert!(!ed.can_undo(), "one step");
    // Another edit while a preview shows restores it first; only that edit is recorded.
    let e = taller(&ed, 0, 25.0);
    ed.preview_tree(&e).expect("shown");
    ed.apply(Edit::MoveTree {
        index: 1,
        by: [1.0, 0.0],
    })
    .expect("moved");
    assert_eq!(ed.document().trees[0], original.trees[0]);
    ed.undo().expect("undo");
    assert_eq!(ed.document(), &original);
    // Cancelled: as before; only replacements of trees and groves preview.
    let e = taller(&ed, 0, 25.0);
    ed.preview_tree(&e).expect("shown");
    ed.cancel_preview().expect("cancelled");
    assert_eq!(ed.document(), &original);
    assert!(
        ed.preview_tree(&Edit::MoveTree {
            index: 0,
            by: [1.0, 0.0]
        })
        .is_err()
    );
}

#[test]
fn instanced_trees_are_each_species_once_at_every_trees_place() {
    use glam::{DAffine3, DQuat, DVec3};
    use penmodel_terrain::Heightmap;
    use penmodel_terrain::trees::Forest;
    use penmodel_terrain::trees::planted::bark_and_leaves;
    let n = 128u32;
    let d = forest_doc();
    let heights: Vec<f32> = (0..n * n).map(|i| (f64::from(i % n) * 0.05).sin() as f32).collect();
    let map = Heightmap::from_heights(n, n, 1.0, heights).expect("heights");
    let forest = Forest::of(&d, &map);
    let shared = forest.instanced(nodes_stop());
    let total: usize = shared.iter().map(|s| s.instances.len()).sum();
    assert_eq!(total, forest.trees().len());
    // Trees of the same species share: fewer meshes than trees, one per node tree.
    let species: std::collections::HashSet<*const _> = forest
        .trees()
        .iter()
        .map(|t| std::sync::Arc::as_ptr(&t.nodes))
        .collect();
    assert_eq!(shared.len(), species.len());
    assert!(shared.len() < total);
    // Each instance's TRS is its tree's placement, and the shared mesh is the tree's unit drawing.
    // In order of each species' first tree.
    let mut k = vec![0usize; shared.len()];
    let mut firsts: Vec<*const penmodel_terrain::trees::NodeTree> = Vec::new();
    for t in forest.trees() {
        let p = std::sync::Arc::as_ptr(&t.nodes);
        let s = firsts.iter().position(|&q| q == p).unwrap_or_else(|| {
            firsts.push(p);
            firsts.len() - 1
        });
        let i = &shared[s].instances[k[s]];
        k[s] += 1;
        let [x, y, z, w] = i.rotation.map(f64::from);
        let trs = DAffine3::from_scale_rotation_translation(
            DVec3::from(i.scale.map(f64::from)),
            DQuat::from_xyzw(x, y, z, w),
            DVec3::from(i.translation.map(f64::from)),
        );
        let p = DVec3::new(0.3, 2.0, -0.7);
        assert!((trs.transform_point3(p) - t.place().transform_point3(p)).length() < 1e-3);
    }
    // Bark and leaves split every triangle of the drawing, none lost.
    let t = &forest.trees()[0];
    let mut drawn = penmodel_terrain::trees::Drawn::default();
    t.nodes.draw(nodes_stop(), &DAffine3::IDENTITY, None, &mut drawn);
    let (bark, leaves) = bark_and_leaves(&drawn.mesh);
    assert_eq!(bark.indices.len() + leaves.indices.len(), drawn.mesh.indices.len());
    assert!(!bark.indices.is_empty() && !leaves.indices.is_empty());
    assert!(bark.colors.is_empty() && leaves.colors.is_empty());
}

fn nodes_stop() -> f64 {
    penmodel_terrain::trees::nodes::STOP
}
