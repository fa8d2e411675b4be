//! The properties the fuzz targets (`modeler/terrain/fuzz/`) check, in one place so that the
//! stable test that replays their corpora (`tests/fuzz_corpus.rs`) checks exactly the same
//! thing. Not part of the crate's API: hidden, and free to change with the targets.

use std::fs;
use std::path::PathBuf;

use crate::document::Document;
use crate::editor::Editor;
use crate::journal;
use crate::validate;

/// Any bytes as a document file (either version): never a panic, and a document that loads is
/// valid, and saves as text that loads to the same document and saves to the same text.
pub fn document(bytes: &[u8]) {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return;
    };
    let Ok(doc) = Document::from_json(text) else {
        return;
    };
    check_document(&doc, "the document read");
}

fn check_document(doc: &Document, what: &str) {
    if let Err(e) = validate::document(doc) {
        panic!("{what} is not valid: {e}");
    }
    let saved = doc.to_json();
    let again = match Document::from_json(&saved) {
        Ok(again) => again,
        Err(e) => panic!("{what} saves as text that does not load: {e}\n{saved}"),
    };
    assert_eq!(&again, doc, "{what} loads back different");
    assert_eq!(again.to_json(), saved, "save → load → save is not a fixed point");
}

/// The document the journal target edits: small, so that an execution stays cheap.
pub const JOURNAL_BASE: &str = include_str!("../../examples/04-volcano.json");

/// The journal's first line for [`JOURNAL_BASE`]: the fuzzed bytes follow it, so that the
/// fuzzer need not guess the document's fingerprint to get past the first line.
pub fn journal_open_line() -> String {
    format!(
        "{{\"op\":\"open\",\"journal\":1,\"base\":\"{}\"}}\n",
        journal::fingerprint(JOURNAL_BASE.as_bytes())
    )
}

/// Any bytes as the journal of [`JOURNAL_BASE`] after its `open` line, opened (read-only) as
/// `penmodel open` does after a crash: never a panic; if it opens, the edited document is valid
/// and saves and loads like any other; and the same files open to the same document again.
pub fn journal(bytes: &[u8]) {
    let scratch = Scratch::new();
    let dir = &scratch.0;
    let doc = dir.join("doc.json");
    let mut text = journal_open_line().into_bytes();
    text.extend_from_slice(bytes);
    let written = fs::write(&doc, JOURNAL_BASE).and_then(|()| fs::write(journal::path_for(&doc), &text));
    if let Err(e) = written {
        panic!("cannot write the scratch files in {}: {e}", dir.display());
    }
    let Ok((editor, report)) = Editor::open_read_only(&doc) else {
        return;
    };
    check_document(editor.document(), "the journalled document");
    match Editor::open_read_only(&doc) {
        Ok((again, report_again)) => {
            assert_eq!(again.document(), editor.document(), "the journal replays differently");
            assert_eq!(report_again.replayed, report.replayed);
        }
        Err(e) => panic!("the journal opened once, then not: {e}"),
    }
}

/// A directory of this thread's own (tests run in parallel threads), removed when dropped: an
/// execution leaves nothing behind, whichever way it ends.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Scratch {
        let thread = format!("{:?}", std::thread::current().id());
        let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
        let dir = std::env::temp_dir().join(format!("penscape-fuzz-journal-{}-{thread}", std::process::id()));
        if let Err(e) = fs::create_dir_all(&dir) {
            panic!("cannot create {}: {e}", dir.display());
        }
        Scratch(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}
