//! The properties the fuzz targets (`protocol/fuzz/`) check, in one place so that the stable test
//! that replays their corpora (`tests/fuzz_corpus.rs`) checks exactly the same thing. Not part of
//! the protocol's API: hidden, and free to change with the targets.
//!
//! Each function takes arbitrary bytes and panics if a property fails; "no panic" alone is the
//! weakest of them.

use crate::{FrameDecoder, MAX_FRAME, MAX_PAYLOAD, Message, encode_frame};

/// A report from the device or a feature report (HID input, GET/SET_REPORT, or a serial frame's
/// payload): decoding never panics, and whatever decodes is in canonical form — encoding it
/// again gives back exactly the bytes read. That is the promise that a report the host accepts is
/// the report the device meant: no two byte strings decode to the same message, so no garbage is
/// silently "corrected" into a plausible sample.
pub fn message(bytes: &[u8]) {
    let Ok(message) = Message::decode(bytes) else {
        return;
    };
    let mut out = [0u8; MAX_PAYLOAD];
    let n = match message.encode(&mut out) {
        Ok(n) => n,
        Err(e) => panic!("{message:?} decoded from {bytes:02x?} does not encode: {e}"),
    };
    assert_eq!(
        &out[..n],
        bytes,
        "{message:?} decoded from bytes that are not its encoding"
    );
    assert_eq!(Message::decode(&out[..n]), Ok(message), "decode(encode(m)) != m");
}

/// A serial byte stream, garbage included, through the frame decoder:
///
/// - every frame it yields is a payload of 1..=[`MAX_PAYLOAD`] bytes whose own framing decodes
///   back to it (so its CRC was right: the decoder never yields bytes that fail the check), and
///   each payload passes [`message`];
/// - whatever the garbage left behind, an intact frame sent after it is received intact: garbage
///   spoils only itself, the decoder resynchronises within one frame.
pub fn stream(bytes: &[u8]) {
    let mut decoder = FrameDecoder::new();
    for &b in bytes {
        if let Some(Ok(payload)) = decoder.push(b) {
            check_payload(payload);
        }
    }
    // A known frame after the garbage: a pen report (the commonest traffic).
    let sentinel = [
        0x01, 0x0d, 0xd2, 0x04, 0xc9, 0xfd, 0x7a, 0x03, 0x34, 0x12, 0x04, 0x03, 0x02, 0x01, 0x05, 0x07, 0x12,
    ];
    let mut frame = [0u8; MAX_FRAME];
    let n = match encode_frame(&sentinel, &mut frame) {
        Ok(n) => n,
        Err(e) => panic!("the sentinel frame does not encode: {e}"),
    };
    let (last, body) = frame[..n].split_last().expect("a frame has delimiters");
    for &b in body {
        // The leading delimiter ends whatever the garbage left unfinished, which may itself be a
        // good frame; within the frame nothing else can be yielded.
        if let Some(Ok(payload)) = decoder.push(b) {
            check_payload(payload);
        }
    }
    match decoder.push(*last) {
        Some(Ok(payload)) => assert_eq!(payload, sentinel, "the frame after the garbage arrived altered"),
        other => panic!("the intact frame after the garbage was lost: {other:?}"),
    }
}

fn check_payload(payload: &[u8]) {
    assert!(
        (1..=MAX_PAYLOAD).contains(&payload.len()),
        "a payload of {} bytes",
        payload.len()
    );
    // Frame the payload again and decode it with a fresh decoder: the same bytes come back, so
    // the payload's CRC (which the re-encoding computes independently) is the one it carried.
    let mut frame = [0u8; MAX_FRAME];
    let n = match encode_frame(payload, &mut frame) {
        Ok(n) => n,
        Err(e) => panic!("a received payload does not frame again: {e}"),
    };
    let mut fresh = FrameDecoder::new();
    let mut again = None;
    for &b in &frame[..n] {
        if let Some(r) = fresh.push(b) {
            again = Some(r.map(|p| {
                let mut copy = [0u8; MAX_PAYLOAD];
                copy[..p.len()].copy_from_slice(p);
                (copy, p.len())
            }));
        }
    }
    match again {
        Some(Ok((copy, len))) => assert_eq!(&copy[..len], payload, "re-framed payload differs"),
        other => panic!("a received payload does not survive its own framing: {other:?}"),
    }
    message(payload);
}
