//! The examples in `docs/document.md` are real: its document loads, its journal lines parse.

use penmodel_terrain::journal::Entry;
use penmodel_terrain::{Document, generate};

const DOC: &str = include_str!("../../../docs/document.md");

/// The body of the first fenced block opened with `fence`.
fn block(fence: &str) -> &'static str {
    let start = DOC.find(fence).unwrap() + fence.len();
    let end = start + DOC[start..].find("```").unwrap();
    &DOC[start..end]
}

#[test]
fn document_example_loads_and_generates() {
    let doc = Document::from_json(block("```json\n")).unwrap();
    let map = generate(&doc).unwrap();
    // The nested point stands at its absolute height 55 m, on the closed figure's 30 m plateau.
    assert_eq!(map.range(), (0.0, 55.0));
}

/// The version-1 journal example (version 2's is checked in `document_safety.rs`: its lines
/// are not plain entries).
#[test]
fn journal_example_lines_parse() {
    let fence = "```text\n";
    let start = DOC.find("```text\n{\"op\":\"open\",\"journal\":1").unwrap() + fence.len();
    let end = start + DOC[start..].find("```").unwrap();
    let lines: Vec<&str> = DOC[start..end].lines().filter(|l| !l.contains('…')).collect();
    assert_eq!(lines.len(), 2);
    for line in lines {
        let entry: Entry = serde_json::from_str(line).unwrap_or_else(|e| panic!("{line}: {e}"));
        // And they are written back the same way.
        assert_eq!(serde_json::to_string(&entry).unwrap(), line);
    }
}
