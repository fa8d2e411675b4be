//! The fuzz targets' corpora (host-driver/fuzz/corpus/: pend's lines from the simulated pen, the
//! calibrations `penctl calibrate --source sim` saves and docs/calibration.md's example, grown by
//! `cargo +nightly fuzz`) replayed on stable through the same properties the targets check
//! (docs/reliability.md).

use pen_host::fuzzing;

#[path = "../../protocol/tests/corpus_replay.rs"]
mod corpus_replay;

/// Runs every file of the target's corpus through `property`; returns how many there were.
fn replay(target: &str, property: fn(&[u8])) -> usize {
    corpus_replay::replay(env!("CARGO_MANIFEST_DIR"), target, property)
}

#[test]
fn socket_line_corpus() {
    // A corpus that vanished would make this pass vacuously.
    assert!(replay("socket_line", fuzzing::socket_line) >= 10);
}

#[test]
fn calibration_corpus() {
    assert!(replay("calibration", fuzzing::calibration) >= 5);
}

#[test]
fn a_time_past_2106_is_refused_not_drifted() {
    // Found by fuzzing: t = 9795453872.7769848 s read as 9795453872776984 µs, which pend writes
    // as 9795453872.776983 (an f64 that large is 2 µs coarse), and a client reads a different
    // time. Such times are now refused by name; just before the limit, every microsecond
    // survives the round trip.
    let line = |t: &str| format!(r#"{{"type":"missed","t":{t},"count":1}}"#);
    let err = pen_host::client::parse_line(&line("9795453872.7769848")).expect_err("refused");
    assert!(err.to_string().contains("is not a time"), "{err}");
    assert!(pen_host::client::parse_line(&line("4294967296")).is_err());
    for t in ["4294967295.999999", "4294967295.123457", "1732200000.123456"] {
        fuzzing::socket_line(line(t).as_bytes());
        assert!(pen_host::client::parse_line(&line(t)).is_ok(), "{t}");
    }
}

#[test]
fn a_huge_coordinate_is_written_as_read() {
    // Found by fuzzing: u_px 9.999999999991e24, written as pend writes it, was read back an ulp
    // off (serde_json's default float parser), so a line did not survive the wire; now read
    // exactly (feature float_roundtrip).
    let line = r#"{"type":"tip_up","t":1.5,"u_mm":1,"v_mm":2,"h_mm":3,"u_px":9.999999999991e24,"v_px":5}"#;
    fuzzing::socket_line(line.as_bytes());
    let Ok(pen_host::client::Line::Event(e)) = pen_host::client::parse_line(line) else {
        panic!("an event")
    };
    assert!(pen_host::wire::line(&e).contains(r#""u_px":9.999999999991e+24"#));
}
