//! A document's safety on disk (issue 47): one writer at a time, journals and lock files no more
//! readable than the document, saves through links that keep the link and the target's mode,
//! inputs that are not regular files or are too big refused before reading, and journal lines
//! that carry a sequence number and a checksum.

use crate::common;

use std::fs;

use common::*;
use penmodel_terrain::editor::{Editor, EditorError};
use penmodel_terrain::{Document, Edit, FigurePath, journal, lock};

fn sample() -> Document {
    document(
        40,
        vec![penmodel_terrain::Region {
            metric: None,
            boundary: polygon([20.0, 20.0], 15.0, 8, 0.1),
            figures: vec![point([14.2, 18.3], 30.0, -1.0)],
        }],
    )
}

fn set_height(height: f64) -> Edit {
    Edit::SetHeight {
        at: FigurePath::new(0, 0),
        height,
    }
}

fn height(doc: &Document) -> f64 {
    doc.regions[0].figures[0].height
}

#[test]
fn a_second_writer_is_refused_naming_the_holder() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.json");
    let mut first = Editor::create(&path, sample()).unwrap();
    first.apply(set_height(50.0)).unwrap();

    let err = Editor::open(&path).err().expect("a second writer is refused");
    assert!(matches!(err, EditorError::Locked(_)), "{err:?}");
    let msg = err.to_string();
    let pid = format!("PID {}", std::process::id());
    assert!(msg.contains(&pid) && msg.contains("d.json"), "{msg}");
    // Saving over it from a new editor is refused the same way.
    let mut other = Editor::new(sample()).unwrap();
    let err = other
        .save_as(&path)
        .err()
        .expect("save_as over a held document is refused");
    assert!(err.to_string().contains(&pid), "{err}");
    // Readers are not blocked, and see the first's journaled edit.
    let (reader, _) = Editor::open_read_only(&path).unwrap();
    assert_eq!(height(reader.document()), 50.0);

    // The refused writers changed nothing: the first's edits survive its save and a reopen.
    first.apply(set_height(60.0)).unwrap();
    first.save().unwrap();
    assert_eq!(height(&Document::load(&path).unwrap()), 60.0);
    drop(first);
    let (again, _) = Editor::open(&path).expect("free again once the first is gone");
    assert_eq!(height(again.document()), 60.0);
    assert!(lock::path_for(&path).exists());
}

fn mode(path: &std::path::Path) -> u32 {
    use std::os::unix::fs::PermissionsExt;
    fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

fn set_mode(path: &std::path::Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    fs::set_permissions(path, fs::Permissions::from_mode(mode)).unwrap();
}

#[test]
fn a_0600_document_gets_a_0600_journal_and_lock() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("secret.json");
    sample().save(&path).unwrap();
    set_mode(&path, 0o600);
    let jpath = journal::path_for(&path);

    let mut editor = Editor::open(&path).unwrap();
    assert_eq!(mode(&jpath), 0o600, "a new journal");
    assert_eq!(mode(&lock::path_for(&path)), 0o600, "a new lock file");
    editor.0.apply(set_height(50.0)).unwrap();
    editor.0.save().unwrap();
    assert_eq!(mode(&path), 0o600, "the saved document");
    assert_eq!(mode(&jpath), 0o600, "the journal started by the save");
    editor.0.apply(set_height(55.0)).unwrap();
    drop(editor);

    // A journal left more readable (by an older penmodel) is given the document's mode when
    // it is continued, its edits kept.
    set_mode(&jpath, 0o644);
    let (editor, report) = Editor::open(&path).unwrap();
    assert_eq!(report.replayed, 1);
    assert_eq!(height(editor.document()), 55.0);
    assert_eq!(mode(&jpath), 0o600, "a continued journal");
}
