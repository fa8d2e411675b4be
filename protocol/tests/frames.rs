//! The serial framing: every intact frame survives garbage on the line; no corrupted frame is
//! ever delivered.

use crate::common;

use common::*;
use pen_protocol::*;
use proptest::prelude::*;

fn frame(m: &Message) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode_frame(&encode(m), &mut out).expect("every message fits a frame");
    out[..n].to_vec()
}

/// Feeds `stream` to a decoder; returns the decoded messages and the number of dropped frames.
fn decode_stream(stream: &[u8]) -> (Vec<Message>, usize) {
    let mut dec = FrameDecoder::new();
    let (mut messages, mut dropped) = (Vec::new(), 0);
    for &b in stream {
        match dec.push(b) {
            None => {}
            Some(Ok(payload)) => messages.push(Message::decode(payload).expect("an intact frame holds a valid report")),
            Some(Err(_)) => dropped += 1,
        }
    }
    (messages, dropped)
}

fn garbage() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        4 => proptest::collection::vec(any::<u8>(), 0..40),
        // Runs without a delimiter longer than any frame: the overflow path.
        1 => proptest::collection::vec(1u8..=255, MAX_FRAME..MAX_FRAME + 300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn garbage_between_frames_spoils_nothing(
        messages in proptest::collection::vec(message(), 1..12),
        garbage in proptest::collection::vec(garbage(), 13),
    ) {
        let mut stream = Vec::new();
        for (m, g) in messages.iter().zip(&garbage) {
            stream.extend_from_slice(g);
            stream.extend(frame(m));
        }
        stream.extend_from_slice(&garbage[12]);
        let (decoded, _) = decode_stream(&stream);
        prop_assert_eq!(decoded, messages);
    }

    #[test]
    fn a_corrupted_frame_is_dropped_and_the_rest_kept(
        messages in proptest::collection::vec(message(), 1..8),
        which in any::<prop::sample::Index>(),
        at in any::<prop::sample::Index>(),
        xor in 1u8..=255,
    ) {
        let which = which.index(messages.len());
        let mut stream = Vec::new();
        for (i, m) in messages.iter().enumerate() {
            let mut f = frame(m);
            if i == which {
                // Any byte between the delimiters; it may even become a delimiter itself.
                let body = 1..f.len() - 1;
                f[body.start + at.index(body.len())] ^= xor;
            }
            stream.extend(f);
        }
        let (decoded, dropped) = decode_stream(&stream);
        let mut expected = messages.clone();
        expected.remove(which);
        prop_assert_eq!(decoded, expected);
        prop_assert!(dropped >= 1);
    }
}

#[test]
fn errors_name_the_failure() {
    let mut dec = FrameDecoder::new();
    let mut feed = |bytes: &[u8]| {
        let mut out = Vec::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                out.push(r.map(<[u8]>::to_vec));
            }
        }
        out
    };
    // Idle delimiters produce nothing.
    assert!(feed(&[0, 0, 0]).is_empty());
    // A COBS code pointing past the end of the frame.
    assert_eq!(feed(&[0x09, 1, 2, 0]), vec![Err(FrameError::Cobs)]);
    // Valid COBS, but only 3 bytes: no room for a report and a 4-byte CRC.
    assert_eq!(feed(&[0x04, 1, 2, 3, 0]), vec![Err(FrameError::TooShort { len: 3 })]);
    // The pen frame with its CRC's last byte altered.
    let mut f = frame(&Message::Pen(sample_pen()));
    let n = f.len();
    f[n - 2] ^= 0x01;
    match feed(&f).as_slice() {
        [Err(FrameError::Crc { computed, carried })] => assert_eq!(computed ^ carried, 0x0100_0000),
        other => panic!("expected a CRC error, got {other:?}"),
    }
    // Overflow, then the next frame decodes.
    let mut stream = vec![0x55u8; MAX_FRAME + 1];
    stream.extend(frame(&Message::Pen(sample_pen())));
    let results = feed(&stream);
    assert_eq!(results[0], Err(FrameError::Overflow));
    assert_eq!(results[1], Ok(sample_pen().to_bytes().to_vec()));
}

#[test]
fn largest_report_fits_and_oversized_payload_is_refused() {
    let config = frame(&Message::Config(sample_config()));
    assert!(config.len() <= MAX_FRAME);
    let mut out = [0u8; MAX_FRAME];
    assert!(encode_frame(&[1u8; MAX_PAYLOAD + 1], &mut out).is_err());
    assert!(encode_frame(&[1u8; 20], &mut out[..10]).is_err());
    for fill in [0x00u8, 0x5a] {
        let n = encode_frame(&[fill; MAX_PAYLOAD], &mut out).expect("a payload at the limit fits");
        let mut dec = FrameDecoder::new();
        let results: Vec<_> = out[..n]
            .iter()
            .filter_map(|&b| dec.push(b).map(|r| r.map(<[u8]>::to_vec)))
            .collect();
        assert_eq!(results, vec![Ok(vec![fill; MAX_PAYLOAD])]);
    }
}
