//! The fuzz targets' corpora (modeler/terrain/fuzz/corpus/: the example documents, a version-2
//! document with a rock field, version-6 documents with every element kind, journals of the
//! edits the editor writes in versions 1 and 2, small, long and thin grids; grown by
//! `cargo +nightly fuzz`) replayed on stable through the same properties the targets check
//! (docs/reliability.md).

use std::fs;

use penmodel_terrain::fuzzing;

#[path = "../../../protocol/tests/corpus_replay.rs"]
mod corpus_replay;

/// Runs every file of the target's corpus through `property`; returns how many there were.
fn replay(target: &str, property: fn(&[u8])) -> usize {
    corpus_replay::replay(env!("CARGO_MANIFEST_DIR"), target, property)
}

#[test]
fn document_corpus() {
    // A corpus that vanished would make this pass vacuously.
    assert!(replay("document", fuzzing::document) >= 5);
}

#[test]
fn journal_corpus() {
    assert!(replay("journal", fuzzing::journal) >= 5);
}

#[test]
fn the_journal_seeds_replay_edits() {
    // The journal target is only worth its time if its seeds get past the open line and replay:
    // a seed of edits, undone and redone, opens with them applied.
    let seed = concat!(
        r#"{"op":"do","edit":{"op":"set_height","at":"regions[0].figures[0]","height":50.0}}"#,
        "\n",
        r#"{"op":"undo"}"#,
        "\n",
        r#"{"op":"redo"}"#,
        "\n",
    );
    fuzzing::journal(seed.as_bytes());
    let dir = tempfile::tempdir().expect("tempdir");
    let doc = dir.path().join("doc.json");
    fs::write(&doc, fuzzing::JOURNAL_BASE).expect("doc");
    fs::write(
        penmodel_terrain::journal::path_for(&doc),
        fuzzing::journal_open_line() + seed,
    )
    .expect("journal");
    let (editor, report) = penmodel_terrain::editor::Editor::open_read_only(&doc).expect("opens");
    assert_eq!(report.replayed, 3);
    let heights: Vec<f64> = editor.document().regions[0].figures.iter().map(|f| f.height).collect();
    assert_eq!(heights, [50.0]);
}

#[test]
fn grid_corpus() {
    assert!(replay("grid", fuzzing::grid) >= 5);
}

/// The corpus' documents of today's version with every element kind (issue 47 item 13: the
/// corpus held versions 1 and 2 only).
const EVERY_ELEMENT: [&str; 2] = ["v6-every-element.json", "v6-every-element-no-base.json"];

#[test]
fn the_document_seeds_hold_every_element_and_build() {
    let corpus = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/document");
    for name in EVERY_ELEMENT {
        let text = fs::read_to_string(corpus.join(name)).expect("seed");
        let doc = penmodel_terrain::Document::from_json(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.version, penmodel_terrain::document::VERSION, "{name}");
        let ridges = doc.ridges.as_ref().expect("ridges");
        let erosion = doc.terrain.erosion.as_ref().expect("erosion");
        let nested = doc
            .regions
            .iter()
            .flat_map(|r| &r.figures)
            .any(|f| !f.figures.is_empty());
        let kinds: Vec<_> = doc.regions.iter().flat_map(|r| &r.figures).map(|f| f.kind).collect();
        assert!(
            doc.regions.len() >= 2 && nested && kinds.len() >= 3,
            "{name}: regions and figures"
        );
        assert!(
            doc.regions.iter().any(|r| r.metric.is_some()),
            "{name}: a region's metric"
        );
        assert!(
            !doc.rocks.is_empty() && !doc.rivers.is_empty(),
            "{name}: rocks and rivers"
        );
        assert!(
            !ridges.lines.is_empty() && !ridges.trees.is_empty(),
            "{name}: ridge lines and trees"
        );
        assert!(
            doc.trees.len() >= 2 && !doc.groves.is_empty(),
            "{name}: trees and groves"
        );
        assert!(
            doc.trees.iter().any(|t| t.maps.is_some() && t.wind.is_some()),
            "{name}: a tree's maps, wind"
        );
        assert!(
            doc.terrain.detail.is_some() && erosion.fluvial.is_some(),
            "{name}: detail, fluvial"
        );
        assert!(
            doc.grid.cells() <= fuzzing::TERRAIN_CELLS,
            "{name}: the target builds its terrain"
        );
        // Beyond loading: the document target builds its terrain (a panic would fail here).
        fuzzing::document(text.as_bytes());
    }
    let with_base = fs::read_to_string(corpus.join(EVERY_ELEMENT[0])).expect("seed");
    let doc = penmodel_terrain::Document::from_json(&with_base).expect("loads");
    assert!(doc.terrain.base.is_some(), "the first seed has a base heightmap");
}

/// The journal seeds the editor wrote (`write_fuzz_seeds`): each version-2 one, and its
/// version-1 twin, replays every line it holds.
#[test]
fn the_journal_seeds_of_rivers_ridges_trees_and_groves_replay() {
    let corpus = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/journal");
    for (name, _) in journal_seeds() {
        for (file, open) in [
            (format!("v2-{name}"), fuzzing::journal_open_line_v2()),
            (format!("v1-{name}"), fuzzing::journal_open_line()),
        ] {
            let lines = fs::read_to_string(corpus.join(&file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            let dir = tempfile::tempdir().expect("tempdir");
            let doc = dir.path().join("doc.json");
            fs::write(&doc, fuzzing::JOURNAL_BASE).expect("doc");
            fs::write(penmodel_terrain::journal::path_for(&doc), open + &lines).expect("journal");
            let (_, report) = penmodel_terrain::editor::Editor::open_read_only(&doc)
                .unwrap_or_else(|e| panic!("{file} does not open: {e}"));
            assert_eq!(report.replayed, lines.lines().count(), "{file}: every line replays");
        }
    }
    // The damaged ones are refused at their bad line (3: a changed digit; 4: seq 5 after 3), and
    // open recovering up to it.
    for (file, line) in [("v2-damaged-changed-digit", 3), ("v2-damaged-lost-line", 4)] {
        let lines = fs::read_to_string(corpus.join(file)).expect("seed");
        let dir = tempfile::tempdir().expect("tempdir");
        let doc = dir.path().join("doc.json");
        fs::write(&doc, fuzzing::JOURNAL_BASE).expect("doc");
        fs::write(
            penmodel_terrain::journal::path_for(&doc),
            fuzzing::journal_open_line_v2() + &lines,
        )
        .expect("journal");
        let refused = penmodel_terrain::editor::Editor::open_read_only(&doc)
            .err()
            .expect("refused");
        assert!(
            refused.to_string().contains(&format!("line {line}:")),
            "{file}: {refused}"
        );
        let (_, report) = penmodel_terrain::editor::Editor::open_recovering(&doc).expect("recovers");
        assert_eq!(report.replayed, line - 2, "{file}: the lines before the bad one");
        assert_eq!(report.recovered.expect("recovered").dropped.line, line, "{file}");
    }
}

/// The edits of each journal seed, as the editor applies them: `undo` and `redo` as such.
fn journal_seeds() -> Vec<(&'static str, Vec<&'static str>)> {
    vec![
        (
            "rivers",
            vec![
                r#"{"op":"add_river","index":0,"river":{"points":[[100.0,160.0],[130.0,150.0],[150.0,175.0],[200.0,160.0]],"width":3.0,"depth":1.5,"iterations":2}}"#,
                r#"{"op":"replace_river","index":0,"river":{"points":[[100.0,160.0],[130.0,140.0],[150.0,175.0],[210.0,165.0]],"width":4.0,"depth":1.0,"water":80.0,"hardness":3.0,"iterations":3}}"#,
                "undo",
                "redo",
                r#"{"op":"add_river","index":1,"river":{"points":[[160.0,60.0],[160.0,120.0]],"width":2.0,"depth":1.0}}"#,
                r#"{"op":"delete_river","index":0}"#,
                "undo",
            ],
        ),
        (
            "ridges",
            vec![
                r#"{"op":"set_ridges","ridges":{"slope":30.0,"filter_radius":1,"filter_passes":2,"lines":[{"points":[[60.0,200.0,40.0],[160.0,180.0,110.0],[260.0,215.0,90.0]]}]}}"#,
                r#"{"op":"set_ridges","ridges":{"slope":35.0,"filter_radius":2,"filter_passes":1,"lines":[{"points":[[60.0,200.0,40.0],[160.0,180.0,110.0],[260.0,215.0,90.0]]}],"trees":[{"nodes":[[160.0,100.0],[110.0,80.0],[210.0,80.0],[160.0,40.0]],"edges":[[0,1],[0,2],[0,3]],"theta":25.0,"h_end":5.0}]}}"#,
                "undo",
                "redo",
                r#"{"op":"set_ridges","ridges":null}"#,
                "undo",
            ],
        ),
        (
            "trees",
            vec![
                r#"{"op":"add_tree","index":0,"tree":{"at":[160.0,160.0],"height":12.0,"preset":"oak","seed":7}}"#,
                r#"{"op":"add_tree","index":1,"tree":{"at":[120.0,140.0],"height":9.0,"seed":2,"maps":[{"y":0.4,"s":0.6,"theta_z":10.0,"theta_y":0.0},{"y":0.24,"s":0.55,"theta_z":40.0,"theta_y":60.0}],"wind":{"direction":30.0,"generations":[{"amplitude":2.0,"frequency":0.3},{"amplitude":6.0,"frequency":0.8,"rest":1.0}]}}}"#,
                r#"{"op":"move_tree","index":0,"by":[5.0,-3.0]}"#,
                r#"{"op":"replace_tree","index":0,"tree":{"at":[165.0,157.0],"height":15.0,"preset":"fir","seed":8}}"#,
                "undo",
                r#"{"op":"delete_tree","index":1}"#,
                "undo",
                "redo",
            ],
        ),
        (
            "groves",
            vec![
                r#"{"op":"add_grove","index":0,"grove":{"region":[[120.0,120.0],[200.0,120.0],[200.0,200.0],[120.0,120.0]],"density":100.0,"mix":[{"preset":"oak","weight":2.0},{"preset":"fir"}],"height":10.0,"seed":3}}"#,
                r#"{"op":"move_grove","index":0,"by":[4.0,6.0]}"#,
                r#"{"op":"replace_grove","index":0,"grove":{"region":[[124.0,126.0],[204.0,126.0],[204.0,206.0],[124.0,126.0]],"density":50.0,"height":12.0,"seed":4,"wind":{"direction":90.0,"generations":[{"amplitude":3.0,"frequency":0.5}]}}}"#,
                "undo",
                "redo",
                r#"{"op":"delete_grove","index":0}"#,
                "undo",
            ],
        ),
    ]
}

/// Writes the journal seeds (the lines after the `open` one that the editor journals for each
/// of [`journal_seeds`], in version 2 and the same entries in version 1; and two damaged
/// version-2 ones: a changed digit, a line lost) and the grid seeds into the corpora:
/// `cargo test -p penmodel-terrain --test main write_fuzz_seeds -- --ignored`.
#[test]
#[ignore = "writes the corpora's seeds"]
fn write_fuzz_seeds() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    for (name, edits) in journal_seeds() {
        let dir = tempfile::tempdir().expect("tempdir");
        let doc = dir.path().join("doc.json");
        fs::write(&doc, fuzzing::JOURNAL_BASE).expect("doc");
        {
            let (mut editor, _) = penmodel_terrain::editor::Editor::open(&doc).expect("opens");
            for edit in edits {
                match edit {
                    "undo" => assert!(editor.undo().expect("undo").is_some()),
                    "redo" => assert!(editor.redo().expect("redo").is_some()),
                    _ => {
                        let edit: penmodel_terrain::Edit = serde_json::from_str(edit).expect("an edit");
                        editor.apply(edit).unwrap_or_else(|e| panic!("{name}: {e}"));
                    }
                }
            }
        }
        let journal = fs::read_to_string(penmodel_terrain::journal::path_for(&doc)).expect("journal");
        let (open, lines) = journal.split_once('\n').expect("an open line");
        assert_eq!(
            format!("{open}\n"),
            fuzzing::journal_open_line_v2(),
            "the editor's open line"
        );
        fs::write(root.join(format!("journal/v2-{name}")), lines).expect("write");
        // The same entries without their sequence numbers and checksums: version 1.
        let plain: String = lines
            .lines()
            .map(|l| {
                let body = &l[l.find("\"op\"").expect("an op")..];
                format!("{{{body}\n")
            })
            .collect();
        fs::write(root.join(format!("journal/v1-{name}")), plain).expect("write");
        if name == "rivers" {
            // A digit changed in the second line (its checksum fails), and the third line lost.
            let changed = lines.replacen("130.0,140.0", "130.0,141.0", 1);
            assert_ne!(changed, lines);
            fs::write(root.join("journal/v2-damaged-changed-digit"), changed).expect("write");
            let lost: Vec<&str> = lines.lines().collect();
            let lost = [&lost[..2], &lost[3..]].concat().join("\n") + "\n";
            fs::write(root.join("journal/v2-damaged-lost-line"), lost).expect("write");
        }
    }
    fs::create_dir_all(root.join("grid")).expect("grid corpus");
    for (name, bytes) in grid_seeds() {
        fs::write(root.join("grid").join(name), bytes).expect("write");
    }
}

/// A `grid` target input ([`fuzzing::grid_of`]): the long and short sides, whether the long side
/// runs down the rows, the cell-size byte, the sun and the sky directions, the heights.
fn grid_input(long: u16, short: u8, down: bool, cell: u8, sun: [u8; 2], k: u8, heights: &[i16]) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&(long - 1).to_le_bytes());
    b.extend_from_slice(&[short - 1, u8::from(down), cell, sun[0], sun[1], k - 1]);
    for h in heights {
        b.extend_from_slice(&h.to_le_bytes());
    }
    b
}

fn grid_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let ramp: Vec<i16> = (0..64).map(|i| i * 10).collect();
    let wall: Vec<i16> = (0..97).map(|i| if i == 48 { 200 } else { 0 }).collect();
    let rough: Vec<i16> = (0..61i32).map(|i| ((i * 7919) % 601 - 300) as i16).collect();
    let cone: Vec<i16> = (0..256i32)
        .map(|i| (200 - ((i % 16 - 8).abs() + (i / 16 - 8).abs()) * 20) as i16)
        .collect();
    vec![
        ("one-cell", grid_input(1, 1, false, 7, [0, 30], 8, &[10])),
        ("flat-4096x1", grid_input(4096, 1, false, 7, [32, 20], 8, &[])),
        ("flat-1x4096", grid_input(4096, 1, true, 7, [96, 20], 8, &[])),
        ("ramp-4096x16", grid_input(4096, 16, false, 3, [160, 10], 16, &ramp)),
        ("wall-16x4096", grid_input(4096, 16, true, 7, [0, 15], 4, &wall)),
        ("rough-2x3", grid_input(2, 3, false, 0, [200, 45], 3, &rough)),
        ("rough-1000x1", grid_input(1000, 1, false, 255, [64, 5], 7, &rough)),
        ("cone-16x16", grid_input(16, 16, false, 7, [10, 40], 16, &cone)),
        ("wall-97x2", grid_input(97, 2, false, 1, [128, 3], 2, &wall)),
    ]
}
