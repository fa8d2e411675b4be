//! The fuzz target's corpus (firmware/core/fuzz/corpus/replay: replays of a pen moving over the
//! golden configuration's receivers, the simulated pen's recorded cycles (`sim-*`), grown by
//! `cargo +nightly fuzz`) replayed on stable through the same property the target checks
//! (docs/reliability.md).

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

#[test]
fn the_corpus_reaches_the_solver() {
    // The property is only worth its time if the corpus's capture times give fixes: count them.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/replay");
    let mut fixes = 0;
    for entry in fs::read_dir(&dir).expect("corpus") {
        let bytes = fs::read(entry.expect("entry").path()).expect("file");
        let mut src = bytes.as_slice();
        let Ok(header) = pen_core::replay::read_header(&mut src) else {
            continue;
        };
        let version = pen_protocol::FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        };
        let mut engine = pen_core::Engine::new(Some(header.config), version, *b"penscape-fuz");
        engine.set_head_emitter_fitted(header.head.is_some());
        engine.set_head(header.head);
        let mut samples = [0u8; 4096];
        while let Ok(Some(head)) = pen_core::replay::read_cycle(&mut src, &header, &mut samples) {
            let cycle = pen_core::Cycle {
                t0_us: head.t0_us,
                arrival_ns: head.arrival_ns,
            };
            let result = match head.emitter {
                pen_core::Emitter::Pen => engine.on_cycle(&cycle),
                pen_core::Emitter::Head => engine.on_head_cycle(&cycle),
            };
            fixes += usize::from(result.reported_mm.is_some());
        }
    }
    assert!(fixes >= 50, "only {fixes} reported positions");
}
