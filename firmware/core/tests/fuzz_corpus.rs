//! The fuzz target's corpus (firmware/core/fuzz/corpus/replay: replays of a pen moving over the
//! golden configuration's receivers, grown by `cargo +nightly fuzz`) replayed on stable through
//! the same property the target checks (docs/reliability.md).

use std::fs;
use std::path::Path;

use pen_core::fuzzing;

#[test]
fn replay_corpus() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/replay");
    let mut n = 0;
    for entry in fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("corpus entry").path();
        let bytes = fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        // A failing file is named, so it can be run alone with `cargo fuzz run replay <file>`.
        if let Err(panic) = std::panic::catch_unwind(|| fuzzing::replay(&bytes)) {
            panic!("{}: {panic:?}", path.display());
        }
        n += 1;
    }
    // A corpus that vanished would make this pass vacuously.
    assert!(n >= 5);
}
