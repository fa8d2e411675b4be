//! docs/reliability.md's corpus counts match the committed corpora: the files in each crate's
//! `fuzz/corpus/<target>/`, which the crates' `fuzz_corpus` tests replay (issue 47 item 13: the
//! page had drifted). `PEN_UPDATE_DOCS=1` rewrites the table, as for docs/protocol.md.

use crate::splice::splice;
use std::path::Path;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

/// Every fuzz target: its crate's folder and name.
const TARGETS: &[(&str, &str)] = &[
    ("protocol", "message"),
    ("protocol", "stream"),
    ("host-driver", "socket_line"),
    ("host-driver", "calibration"),
    ("modeler/terrain", "document"),
    ("modeler/terrain", "journal"),
    ("modeler/terrain", "grid"),
    ("firmware/core", "replay"),
];

fn files_in(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter(|e| e.as_ref().is_ok_and(|e| e.file_type().is_ok_and(|t| t.is_file())))
        .count()
}

#[test]
fn the_corpus_counts_are_current() {
    let path = Path::new(ROOT).join("docs/reliability.md");
    let doc = std::fs::read_to_string(&path).expect("docs/reliability.md");
    let mut table = String::from("\n| Target | Files |\n|---|---:|\n");
    for (krate, target) in TARGETS {
        let n = files_in(&Path::new(ROOT).join(krate).join("fuzz/corpus").join(target));
        assert!(n > 0, "{krate}'s {target} corpus is empty");
        table += &format!("| `{target}` ({krate}) | {n} |\n");
    }
    // Every target in a corpus folder is in the table: a new one is not left out.
    for (krate, _) in TARGETS {
        let corpora = Path::new(ROOT).join(krate).join("fuzz/corpus");
        for entry in std::fs::read_dir(&corpora).expect("corpus folder").flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            assert!(
                TARGETS.iter().any(|(k, t)| k == krate && *t == name),
                "{krate}'s corpus {name} is not counted here"
            );
        }
    }
    let fresh = splice(&doc, "corpus-counts", &table);
    if fresh != doc {
        if std::env::var_os("PEN_UPDATE_DOCS").is_some() {
            std::fs::write(&path, &fresh).expect("write docs/reliability.md");
        } else {
            panic!(
                "docs/reliability.md's corpus counts are stale: run `PEN_UPDATE_DOCS=1 cargo test -p pen-host --test main reliability_doc`"
            );
        }
    }
}
