//! The fuzz targets' corpora (modeler/terrain/fuzz/corpus/: the example documents, a version-2
//! document with a rock field, journals of the edits the editor writes, grown by
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
