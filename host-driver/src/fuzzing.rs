//! The properties the fuzz targets (`host-driver/fuzz/`) check, in one place so that the stable
//! test that replays their corpora (`tests/fuzz_corpus.rs`) checks exactly the same thing. Not
//! part of the crate's API: hidden, and free to change with the targets.

use crate::calibration::Calibration;
use crate::client::{Line, parse_line};
use crate::events::{DisplayPoint, EventKind, HeadPose, PenEvent};
use crate::wire::{self, Hello, SocketLine};

/// Any bytes as a line from pend's socket, read as a client reads it: never a panic, and a
/// line that reads is one pend could have written — written again as pend writes it, it reads
/// to the same line, and that text is a fixed point (writing what it reads gives it back).
pub fn socket_line(bytes: &[u8]) {
    // A client reads text; bytes that are not UTF-8 fail there, before any parsing.
    let Ok(text) = std::str::from_utf8(bytes) else {
        return;
    };
    let Ok(line) = parse_line(text) else {
        return;
    };
    // What pend would send for it (coordinates to the micrometre, times to the microsecond).
    let written = write(&line);
    let again = match parse_line(written.trim_end()) {
        Ok(again) => again,
        Err(e) => panic!("{line:?} read from {text:?}, written as {written:?}, does not read back: {e}"),
    };
    assert_eq!(write(&again), written, "writing {again:?} is not a fixed point");
    match (&line, &again) {
        (Line::Event(a), Line::Event(b)) => {
            // Rounding may move a coordinate by at most half a micrometre and a time by half a
            // microsecond; what the event is, and which report it came from, never change.
            assert_eq!((kind(a), a.sw, a.seq), (kind(b), b.sw, b.seq), "an event changed");
            assert_eq!(a.point.is_some(), b.point.is_some(), "a point appeared or vanished");
        }
        (Line::Hello { device: a }, Line::Hello { device: b }) => assert_eq!(a, b),
        _ => panic!("{line:?} read back as {again:?}"),
    }
}

/// The event's kind with a head's pose reduced to whether it has one: its coordinates are
/// rounded like every point when written.
fn kind(e: &PenEvent) -> EventKind {
    match &e.kind {
        EventKind::Head(h) => EventKind::Head(HeadPose {
            at: h.at.map(|_| DisplayPoint {
                u_mm: 0.0,
                v_mm: 0.0,
                h_mm: 0.0,
                u_px: 0.0,
                v_px: 0.0,
            }),
            ..h.clone()
        }),
        k => k.clone(),
    }
}

fn write(line: &Line) -> String {
    match line {
        Line::Event(e) => wire::line(e),
        Line::Hello { device } => SocketLine::Hello(Hello::new(0, device.clone())).to_text(),
    }
}

/// Any bytes as a calibration file: never a panic, and a file that loads saves as a file that
/// loads to the same calibration (its text a fixed point of load and save).
pub fn calibration(bytes: &[u8]) {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return;
    };
    let Ok(loaded) = Calibration::from_toml(text, "fuzz.toml") else {
        return;
    };
    let saved = loaded.to_toml();
    let again = match Calibration::from_toml(&saved, "saved.toml") {
        Ok(again) => again,
        Err(e) => panic!("a calibration read from {text:?} saves as {saved:?}, which does not load: {e}"),
    };
    assert_eq!(again.to_toml(), saved, "load → save is not a fixed point");
}
