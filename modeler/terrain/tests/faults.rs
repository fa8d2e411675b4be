//! Faults on purpose in documents and journals (issue 17): numbers that are not finite or too
//! large, a grid of 10⁶ × 10⁶ cells, negative sizes, 10,000 levels of nesting, 10 MB strings,
//! truncated text, a journal cut mid-line, a garbage line, a journal for another document.
//!
//! Expectation for each: an error naming the element (or the line and column where the text
//! stops being JSON), of bounded length, no panic, no allocation the size of the claim (a grid
//! of 10¹² cells would abort the process if anything allocated it), and whatever was committed
//! still there.

use std::fs;
use std::path::Path;

use penmodel_terrain::editor::{Editor, EditorError};
use penmodel_terrain::{Document, Edit, FigurePath, LoadError, journal};

fn volcano() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/04-volcano.json");
    fs::read_to_string(path).expect("the example document")
}

/// The example with `from` replaced by `to` (which must occur).
fn volcano_with(from: &str, to: &str) -> String {
    let text = volcano();
    assert!(text.contains(from), "{from} in the example");
    text.replacen(from, to, 1)
}

/// An error message fit to show: short whatever the input's size (a cut 200-character element,
/// the cut message and serde's list of the document's ten keys).
const MAX_MESSAGE: usize = 480;

/// Loads `text`, expecting an error naming `element` (a document path, or "" for the text
/// itself) and saying `says`.
#[track_caller]
fn refused(text: &str, element: &str, says: &str) {
    let e = Document::from_json(text).expect_err("refused");
    let message = e.to_string();
    let path = match &e {
        LoadError::Parse { path, .. } => path.clone(),
        LoadError::Invalid(v) => v.path.clone(),
        LoadError::Io { .. } => panic!("not read from a file: {message}"),
    };
    assert_eq!(path, element, "{message}");
    assert!(message.contains(says), "{message:.2000}");
    assert!(message.len() <= MAX_MESSAGE, "{} bytes: {message:.2000}", message.len());
}

#[test]
fn numbers_that_are_not_finite_or_too_large_are_refused_by_element() {
    // JSON has no NaN or Infinity: the text stops being JSON there.
    refused(
        &volcano_with(r#""cell_size": 2.0"#, r#""cell_size": NaN"#),
        "",
        "line 4",
    );
    refused(
        &volcano_with(r#""cell_size": 2.0"#, r#""cell_size": Infinity"#),
        "",
        "line 4",
    );
    // 1e400 is no f64; 1e308 is one, and out of every range.
    refused(
        &volcano_with(r#""cell_size": 2.0"#, r#""cell_size": 1e400"#),
        "",
        "line 4",
    );
    refused(
        &volcano_with(r#""cell_size": 2.0"#, r#""cell_size": 1e308"#),
        "grid.cell_size",
        "",
    );
    refused(
        &volcano_with("[305.6, 160.0]", "[1e308, 160.0]"),
        "regions[0].boundary[0]",
        "",
    );
}

#[test]
fn a_huge_or_negative_grid_is_refused_before_anything_is_allocated() {
    let grid = r#""grid": {"cols": 160, "rows": 160, "cell_size": 2.0}"#;
    refused(
        &volcano_with(grid, r#""grid": {"cols": 1000000, "rows": 1000000, "cell_size": 2.0}"#),
        "grid",
        "",
    );
    refused(
        &volcano_with(grid, r#""grid": {"cols": -160, "rows": 160, "cell_size": 2.0}"#),
        "grid.cols",
        "",
    );
    refused(
        &volcano_with(grid, r#""grid": {"cols": 160, "rows": 160, "cell_size": -2.0}"#),
        "grid.cell_size",
        "",
    );
    refused(
        &volcano_with(grid, r#""grid": {"cols": 0, "rows": 160, "cell_size": 2.0}"#),
        "grid",
        "",
    );
}

#[test]
fn ten_thousand_levels_of_nesting_are_refused_without_overflowing_the_stack() {
    let deep = format!("{}{}", "[".repeat(10_000), "]".repeat(10_000));
    // Where the version is read (as any JSON value, to say which version it is not).
    refused(
        &volcano_with(r#""version": 1"#, &format!(r#""version": {deep}"#)),
        "",
        "nested too deeply",
    );
    // Where a point's number is expected: refused at the first bracket, without descending.
    refused(
        &volcano_with("[305.6, 160.0]", &deep),
        "regions[0].boundary[0][0]",
        "expected a number",
    );
    let objects = format!("{}{}", r#"{"figures": ["#.repeat(10_000), "]}".repeat(10_000));
    refused(
        &volcano_with(r#""regions": ["#, &format!(r#""regions": [{objects}, "#)),
        "",
        "nested too deeply",
    );
}

#[test]
fn ten_megabyte_strings_give_a_short_message() {
    let long = "x".repeat(10 << 20);
    refused(
        &volcano_with(r#""version": 1"#, &format!(r#""version": "{long}""#)),
        "version",
        "",
    );
    refused(
        &volcano_with(r#""cell_size": 2.0"#, &format!(r#""cell_size": "{long}""#)),
        "grid.cell_size",
        "",
    );
    // A 10 MB key: the element is the key, cut short.
    let e = Document::from_json(&volcano_with(r#""note""#, &format!(r#""{long}": 1, "note""#))).expect_err("refused");
    assert!(e.to_string().len() <= MAX_MESSAGE, "{:.2000}", e.to_string());
    // A note is free text: a long one is kept, not refused.
    let text = volcano_with(r#""note": ""#, &format!(r#""note": "{long}"#));
    assert!(Document::from_json(&text).is_ok());
}

#[test]
fn truncated_text_is_an_error_at_every_length() {
    let text = volcano();
    // Every 7th length and the last 64 before the closing brace: each a syntax error, located.
    let end = text.trim_end().len() - 1;
    let lengths = (0..end).step_by(7).chain(end - 64..end);
    for n in lengths.filter(|&n| text.is_char_boundary(n)) {
        let e = Document::from_json(&text[..n]).expect_err("truncated");
        assert!(matches!(e, LoadError::Parse { .. }), "cut at {n}: {e}");
        assert!(e.to_string().len() <= MAX_MESSAGE, "cut at {n}: {e}");
    }
}

/// A document in `dir` with two committed edits in its journal; returns its path and the
/// document after them.
fn edited(dir: &Path) -> (std::path::PathBuf, Document) {
    let path = dir.join("volcano.json");
    let doc = Document::from_json(&volcano()).expect("the example loads");
    let mut editor = Editor::create(&path, doc).expect("created");
    editor
        .apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 300.0,
        })
        .expect("edit");
    editor
        .apply(Edit::SetSlope {
            at: FigurePath::new(0, 0),
            slope: 1.5,
        })
        .expect("edit");
    let after = editor.document().clone();
    drop(editor); // a crash: no save
    (path, after)
}

#[test]
fn a_journal_cut_anywhere_in_its_last_line_keeps_every_edit_before_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (path, after) = edited(dir.path());
    let jpath = journal::path_for(&path);
    let whole = fs::read(&jpath).expect("journal");
    // The edit before the last one, for cuts inside the last line.
    let last_start = whole[..whole.len() - 1]
        .iter()
        .rposition(|&b| b == b'\n')
        .expect("several lines")
        + 1;
    let one_edit = {
        fs::write(&jpath, &whole[..last_start]).expect("write");
        Editor::open_read_only(&path).expect("opens").0.document().clone()
    };
    assert_ne!(one_edit, after);
    for cut in last_start + 1..whole.len() - 1 {
        fs::write(&jpath, &whole[..cut]).expect("write");
        let (editor, report) = Editor::open_read_only(&path).unwrap_or_else(|e| panic!("cut at {cut}: {e}"));
        assert!(report.dropped_torn_line, "cut at {cut}");
        assert_eq!(editor.document(), &one_edit, "cut at {cut}: the first edit is kept");
    }
    fs::write(&jpath, &whole).expect("write");
    assert_eq!(Editor::open_read_only(&path).expect("opens").0.document(), &after);
}

#[test]
fn a_garbage_line_is_refused_by_line_and_nothing_on_disk_changes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (path, _) = edited(dir.path());
    let jpath = journal::path_for(&path);
    let mut bytes = fs::read(&jpath).expect("journal");
    let garbage_line = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
    bytes.extend_from_slice(b"\x13\x37 not an edit at all \x7f{{{\n");
    // An edit after the garbage: committed, but beyond a line that cannot be trusted.
    bytes.extend_from_slice(b"{\"op\":\"undo\"}\n");
    fs::write(&jpath, &bytes).expect("write");
    let document_before = fs::read(&path).expect("document");
    let e = Editor::open(&path).map(|_| ()).expect_err("refused");
    let message = e.to_string();
    assert!(
        matches!(e, EditorError::Journal(_) | EditorError::Replay { .. }),
        "{message}"
    );
    assert!(message.contains(&format!("line {garbage_line}")), "{message}");
    assert!(message.len() <= MAX_MESSAGE, "{message}");
    assert_eq!(
        fs::read(&path).expect("document"),
        document_before,
        "the document is untouched"
    );
    assert_eq!(
        fs::read(&jpath).expect("journal"),
        bytes,
        "the journal is kept for repair"
    );
}

#[test]
fn a_journal_for_another_document_is_set_aside_not_replayed_nor_lost() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (path, after) = edited(dir.path());
    let jpath = journal::path_for(&path);
    let journal_bytes = fs::read(&jpath).expect("journal");
    // The base hash in the open line no longer matches: the document was saved by someone else.
    let saved_elsewhere = volcano_with(r#""note": ""#, r#""note": "changed elsewhere. "#);
    fs::write(&path, &saved_elsewhere).expect("write");
    let (editor, report) = Editor::open(&path).expect("opens");
    assert_eq!(report.replayed, 0);
    assert_ne!(
        editor.document(),
        &after,
        "the other document's edits are not applied to this one"
    );
    let aside = report.stale_journal.expect("the journal is set aside");
    assert_eq!(fs::read(aside).expect("kept"), journal_bytes, "and kept whole");
}

#[test]
fn a_second_stale_journal_does_not_overwrite_the_first() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (path, _) = edited(dir.path());
    let jpath = journal::path_for(&path);
    let first = fs::read(&jpath).expect("journal");
    fs::write(
        &path,
        volcano_with(r#""note": ""#, r#""note": "saved elsewhere once. "#),
    )
    .expect("write");
    let (mut editor, report) = Editor::open(&path).expect("opens");
    let first_aside = report.stale_journal.expect("set aside");
    // Edits journaled against this version, then the document replaced again.
    editor
        .apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 123.0,
        })
        .expect("edit");
    drop(editor);
    let second = fs::read(&jpath).expect("journal");
    fs::write(
        &path,
        volcano_with(r#""note": ""#, r#""note": "saved elsewhere twice. "#),
    )
    .expect("write");
    let (_, report) = Editor::open(&path).expect("opens");
    let second_aside = report.stale_journal.expect("set aside");
    assert_ne!(first_aside, second_aside);
    assert_eq!(
        fs::read(&first_aside).expect("kept"),
        first,
        "the first journal set aside is kept"
    );
    assert_eq!(fs::read(&second_aside).expect("kept"), second);
}

#[test]
fn a_byte_order_mark_before_a_document_is_skipped() {
    // Issue 47: a UTF-8 BOM gave "expected value (line 1, column 1)".
    let plain = Document::from_json(&volcano()).expect("the example loads");
    let marked = format!("\u{feff}{}", volcano());
    assert_eq!(Document::from_json(&marked).expect("loads with a BOM"), plain);
    let dir = tempfile::tempdir().expect("a scratch folder");
    let path = dir.path().join("bom.json");
    fs::write(&path, marked.as_bytes()).expect("written");
    assert_eq!(Document::load(&path).expect("a BOM file loads"), plain);
    // The checks on the text after it still apply: terrain settings need version 4.
    let old = "\u{feff}{\"version\": 3, \"grid\": {\"cols\": 4, \"rows\": 4, \"cell_size\": 1.0}, \"regions\": [], \"terrain\": {}}";
    let err = Document::from_json(old).expect_err("version 3 with terrain settings");
    assert!(err.to_string().contains("terrain"), "{err}");
}
