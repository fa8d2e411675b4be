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
        .expect_err("save_as over a held document is refused");
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

#[test]
fn a_save_through_a_link_writes_the_0600_target_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let real_dir = dir.path().join("real");
    fs::create_dir(&real_dir).unwrap();
    let target = real_dir.join("doc.json");
    sample().save(&target).unwrap();
    set_mode(&target, 0o600);
    let link = dir.path().join("link.json");
    std::os::unix::fs::symlink("real/doc.json", &link).unwrap();

    let (mut editor, _) = Editor::open(&link).unwrap();
    editor.apply(set_height(50.0)).unwrap();
    editor.save().unwrap();
    // The link is still a link to the same target, which holds the edit and kept its mode.
    assert!(
        fs::symlink_metadata(&link).unwrap().file_type().is_symlink(),
        "the link was replaced"
    );
    assert_eq!(fs::read_link(&link).unwrap(), std::path::Path::new("real/doc.json"));
    assert_eq!(mode(&target), 0o600);
    assert_eq!(height(&Document::load(&target).unwrap()), 50.0);
    // Its journal and lock are beside the target (one document, whichever name opens it), and
    // a second writer by the target's own name is refused.
    assert_eq!(mode(&journal::path_for(&target)), 0o600);
    assert!(!journal::path_for(&link).exists());
    assert!(matches!(Editor::open(&target), Err(EditorError::Locked(_))));
    drop(editor);

    // A journal that is a link: followed, its target written in place, the link kept.
    let jtarget = real_dir.join("elsewhere.journal");
    fs::rename(journal::path_for(&target), &jtarget).unwrap();
    std::os::unix::fs::symlink(&jtarget, journal::path_for(&target)).unwrap();
    let (mut editor, _) = Editor::open(&link).unwrap();
    editor.apply(set_height(60.0)).unwrap();
    editor.save().unwrap();
    let jlink = journal::path_for(&target);
    assert!(
        fs::symlink_metadata(&jlink).unwrap().file_type().is_symlink(),
        "the journal link was replaced"
    );
    assert_eq!(mode(&jtarget), 0o600);
    editor.apply(set_height(70.0)).unwrap();
    drop(editor);
    let journal_text = fs::read_to_string(&jtarget).unwrap();
    assert!(journal_text.contains("70.0"), "{journal_text}");
    let (reopened, report) = Editor::open_read_only(&link).unwrap();
    assert_eq!((report.replayed, height(reopened.document())), (1, 70.0));
}

/// `load(path)`'s error, or a failure if it takes more than 5 s (a FIFO blocking, /dev/zero
/// being read whole).
fn refused_quickly(path: &std::path::Path) -> String {
    let (tx, rx) = std::sync::mpsc::channel();
    let owned = path.to_owned();
    std::thread::spawn(move || {
        let _ = tx.send(Editor::open_read_only(&owned).err().map(|e| e.to_string()));
    });
    match rx.recv_timeout(std::time::Duration::from_secs(5)) {
        Ok(Some(msg)) => msg,
        Ok(None) => panic!("{} opened as a document", path.display()),
        Err(_) => panic!("reading {} did not return within 5 s", path.display()),
    }
}

/// Makes a FIFO at `path` with mkfifo(3), not by running `mkfifo`: a child forked while another
/// test holds a document lock holds that lock too until it execs, and that test's next open
/// would find its own document locked.
fn mkfifo(path: &std::path::Path) {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: `c` is a NUL-terminated path that lives across the call.
    #[allow(unsafe_code)]
    let made = unsafe { libc::mkfifo(c.as_ptr(), 0o600) };
    assert_eq!(made, 0, "mkfifo {}", path.display());
}

#[test]
fn dev_zero_a_fifo_and_a_folder_are_refused_before_reading() {
    let msg = refused_quickly(std::path::Path::new("/dev/zero"));
    assert_eq!(
        msg,
        "cannot read /dev/zero: a character device, not a regular file: penmodel reads regular files only"
    );

    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.json");
    mkfifo(&fifo);
    let msg = refused_quickly(&fifo);
    assert!(msg.contains("a FIFO (named pipe), not a regular file"), "{msg}");

    let msg = refused_quickly(dir.path());
    assert!(msg.contains("a directory, not a regular file"), "{msg}");

    // A journal that is a FIFO is refused the same way, naming the journal.
    let doc = dir.path().join("d.json");
    sample().save(&doc).unwrap();
    mkfifo(&journal::path_for(&doc));
    let msg = refused_quickly(&doc);
    assert!(msg.contains("d.json.journal") && msg.contains("a FIFO"), "{msg}");
}

#[test]
fn a_document_over_the_limit_is_refused_by_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.json");
    // Sparse: the size is there without the bytes.
    let file = fs::File::create(&path).unwrap();
    file.set_len(penmodel_terrain::persist::MAX_DOCUMENT_BYTES + 1).unwrap();
    let msg = refused_quickly(&path);
    assert!(msg.contains("268435457 bytes, more than the 256 MiB"), "{msg}");
}

/// A document with three journaled edits (heights 50, 109 and 130, lines 2 to 4) and its journal.
fn three_edits(dir: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let path = dir.join("d.json");
    let mut editor = Editor::create(&path, sample()).unwrap();
    for h in [50.0, 109.0, 130.0] {
        editor.apply(set_height(h)).unwrap();
    }
    drop(editor);
    (path.clone(), journal::path_for(&path))
}

#[test]
fn a_flipped_bit_in_a_journal_line_is_refused_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let (path, jpath) = three_edits(dir.path());
    let text = fs::read_to_string(&jpath).unwrap();
    assert!(text.lines().all(|l| l.starts_with("{\"seq\":")), "{text}");
    // 109.0 → 108.0 is one bit ('9' is 0x39, '8' 0x38): valid JSON, a valid edit.
    fs::write(&jpath, text.replace("109.0", "108.0")).unwrap();
    let err = Editor::open(&path).err().expect("refused");
    let msg = err.to_string();
    assert!(
        msg.starts_with(&format!("journal {} line 3: checksum mismatch", jpath.display())),
        "{msg}"
    );
    // Readers refuse it too, rather than show a terrain that was never modeled.
    assert!(Editor::open_read_only(&path).is_err());

    // A line lost: the sequence numbers say so.
    let lines: Vec<&str> = text.lines().collect();
    fs::write(&jpath, format!("{}\n{}\n{}\n", lines[0], lines[1], lines[3])).unwrap();
    let msg = Editor::open(&path).err().expect("refused").to_string();
    assert!(msg.contains("line 3: sequence number 4 where 3 belongs"), "{msg}");
}

#[test]
fn recovering_keeps_the_edits_before_the_bad_line() {
    let dir = tempfile::tempdir().unwrap();
    let (path, jpath) = three_edits(dir.path());
    let original = fs::read_to_string(&jpath).unwrap().replace("109.0", "108.0");
    fs::write(&jpath, &original).unwrap();

    let (mut editor, report) = Editor::open_recovering(&path).unwrap();
    assert_eq!(height(editor.document()), 50.0, "the edit before the bad line");
    assert_eq!(report.replayed, 1);
    let recovered = report.recovered.expect("says what it dropped");
    assert_eq!((recovered.dropped.line, recovered.dropped.lines), (3, 2));
    assert!(
        recovered.dropped.reason.starts_with("checksum mismatch"),
        "{:?}",
        recovered.dropped
    );
    // The journal as it was is kept; the bad lines are cut off, and later edits follow the
    // good ones with the next sequence number.
    assert_eq!(fs::read_to_string(&recovered.copy).unwrap(), original);
    editor.apply(set_height(77.0)).unwrap();
    drop(editor);
    let (mut editor, report) = Editor::open(&path).expect("a clean journal again");
    assert_eq!((report.replayed, height(editor.document())), (2, 77.0));
    assert!(report.recovered.is_none());
    editor.undo().unwrap();
    assert_eq!(height(editor.document()), 50.0);
}

#[test]
fn a_version_1_journal_still_replays_and_is_continued_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.json");
    let bytes = sample().save(&path).unwrap();
    let jpath = journal::path_for(&path);
    let v1 = format!(
        "{{\"op\":\"open\",\"journal\":1,\"base\":\"{}\"}}\n{}\n",
        journal::fingerprint(&bytes),
        r#"{"op":"do","edit":{"op":"set_height","at":"regions[0].figures[0]","height":42.5}}"#
    );
    fs::write(&jpath, &v1).unwrap();
    let (mut editor, report) = Editor::open(&path).unwrap();
    assert_eq!((report.replayed, height(editor.document())), (1, 42.5));
    editor.apply(set_height(43.0)).unwrap();
    drop(editor);
    let text = fs::read_to_string(&jpath).unwrap();
    assert!(
        text.starts_with(&v1) && text.lines().nth(2).is_some_and(|l| l.starts_with("{\"op\":\"do\"")),
        "{text}"
    );
    let (mut editor, report) = Editor::open(&path).unwrap();
    assert_eq!((report.replayed, height(editor.document())), (2, 43.0));
    // Saving starts a version-2 journal.
    editor.save().unwrap();
    let text = fs::read_to_string(&jpath).unwrap();
    assert!(
        text.starts_with("{\"seq\":1,\"crc32\":\"") && text.contains("\"journal\":2"),
        "{text}"
    );
}

#[test]
fn the_version_2_example_of_docs_document_md_reads() {
    // docs/document.md's example, whose checksums were computed apart (zlib's crc32).
    let text = concat!(
        r#"{"seq":1,"crc32":"b7cdd160","op":"open","journal":2,"base":"fnv1a64:3c0a5e6f4b2d9e11"}"#,
        "\n",
        r#"{"seq":2,"crc32":"42c10edc","op":"do","edit":{"op":"set_height","at":"regions[0].figures[1]","height":42.5}}"#,
        "\n",
        r#"{"seq":3,"crc32":"3b8b156e","op":"undo"}"#,
        "\n",
        r#"{"seq":4,"crc32":"3493be07","op":"redo"}"#,
        "\n",
    );
    let docs = include_str!("../../../docs/document.md");
    assert!(docs.contains(text), "docs/document.md's example changed");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("example.journal");
    fs::write(&path, text).unwrap();
    match journal::read(&path, "fnv1a64:3c0a5e6f4b2d9e11").unwrap() {
        journal::Replay::Entries { entries, version, .. } => {
            assert_eq!((entries.len(), version), (3, 2));
            assert_eq!(entries[1], journal::Entry::Undo);
        }
        other => panic!("{other:?}"),
    }
}
