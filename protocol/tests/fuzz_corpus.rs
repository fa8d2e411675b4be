//! The fuzz targets' corpora (protocol/fuzz/corpus/, seeded from pen-sim's serial traffic and
//! the golden reports, grown by `cargo +nightly fuzz`) replayed on stable through the same
//! properties the targets check, so what fuzzing once found stays fixed (docs/reliability.md).

use pen_protocol::fuzzing;

#[path = "corpus_replay.rs"]
mod corpus_replay;

/// Runs every file of the target's corpus through `property`; returns how many there were.
fn replay(target: &str, property: fn(&[u8])) -> usize {
    corpus_replay::replay(env!("CARGO_MANIFEST_DIR"), target, property)
}

#[test]
fn message_corpus() {
    // A corpus that vanished would make this pass vacuously.
    assert!(replay("message", fuzzing::message) >= 10);
}

#[test]
fn stream_corpus() {
    assert!(replay("stream", fuzzing::stream) >= 10);
}

#[test]
fn a_frame_after_garbage_arrives() {
    // The stream property's own check: a frame cut short, then a good one, then noise.
    fuzzing::stream(&[0x00, 0x05, 0x01, 0x0d, 0xd2]);
    fuzzing::stream(&[0xff; 2 * pen_protocol::MAX_FRAME]);
}
