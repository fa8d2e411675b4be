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
