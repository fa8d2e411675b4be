//! Round trips of every report and message, and decoding of arbitrary bytes.

use crate::common;

use common::*;
use pen_protocol::*;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Every message decodes to itself, with the length its report declares.
    #[test]
    fn message_round_trip(m in message()) {
        let bytes = encode(&m);
        prop_assert_eq!(bytes[0], m.id() as u8);
        prop_assert_eq!(Message::decode(&bytes), Ok(m));
    }

    /// Decoding arbitrary bytes never panics, and whatever decodes re-encodes to the same bytes:
    /// each value has exactly one encoding.
    #[test]
    fn arbitrary_bytes_decode_canonically(
        id in proptest::sample::select(vec![0x00u8, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x80, 0xff]),
        rest in proptest::collection::vec(any::<u8>(), 0..200),
    ) {
        let mut bytes = vec![id];
        bytes.extend_from_slice(&rest);
        if let Ok(m) = Message::decode(&bytes) {
            prop_assert_eq!(encode(&m), bytes);
        }
    }

    /// A valid report with one bit flipped either fails to decode or decodes to a value whose
    /// encoding is exactly the altered bytes: no bit is silently ignored.
    #[test]
    fn flipped_bit_is_never_ignored(m in message(), bit in any::<usize>()) {
        let mut bytes = encode(&m);
        let bit = bit % (bytes.len() * 8);
        bytes[bit / 8] ^= 1 << (bit % 8);
        if let Ok(decoded) = Message::decode(&bytes) {
            prop_assert_eq!(encode(&decoded), bytes);
        }
    }

    /// Millimetres to logical units and back loses at most half a unit (0.05 mm).
    #[test]
    fn position_mm_round_trip(x in -3276.7f32..3276.7, y in -3276.7f32..3276.7, z in -3276.7f32..3276.7) {
        let p = Position::from_mm([x, y, z]).expect("within range");
        for (back, orig) in p.to_mm().into_iter().zip([x, y, z]) {
            prop_assert!((back - orig).abs() <= 0.05 + 1e-3, "{} vs {}", back, orig);
        }
    }
}

#[test]
fn position_from_mm_rejects_what_it_cannot_carry() {
    assert_eq!(Position::from_mm([f32::NAN, 0.0, 0.0]), None);
    assert_eq!(Position::from_mm([0.0, f32::INFINITY, 0.0]), None);
    assert_eq!(Position::from_mm([0.0, 0.0, 3276.8]), None);
    assert_eq!(
        Position::from_mm([-3276.7, 3276.7, 0.04]),
        Some(Position {
            x: -32767,
            y: 32767,
            z: 0
        })
    );
    assert_eq!(
        Position::from_mm([0.05, -0.05, 0.149]),
        Some(Position { x: 1, y: -1, z: 1 })
    );
}

#[test]
fn quality_saturates() {
    let q = Quality::new(12, 30.0, f32::NAN);
    assert_eq!(
        q,
        Quality {
            receivers_used: 8,
            residual: 255,
            dop: 255
        }
    );
    let q = Quality::new(4, 0.34, 1.26);
    assert_eq!(
        q,
        Quality {
            receivers_used: 4,
            residual: 3,
            dop: 13
        }
    );
    assert!((q.residual_mm() - 0.3).abs() < 1e-6 && (q.dop() - 1.3).abs() < 1e-6);
}
