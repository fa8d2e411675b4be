//! The reset record (0x09): round trip, refusals, and its words.

use pen_protocol::{Report, ResetKind, ResetRecord};

#[test]
fn a_record_round_trips_and_its_text_is_cut_at_a_character() {
    let mut r = ResetRecord {
        kind: ResetKind::Panic,
        line: 42,
        column: 7,
        uptime_ms: 12_345,
        ..ResetRecord::NONE
    };
    // 48 ASCII bytes and a two-byte character: the character does not fit in 49.
    let long = format!("{}é and more", "x".repeat(48));
    r.set_text(&long);
    assert_eq!(r.text(), "x".repeat(48));
    let mut buf = [0u8; 64];
    let n = r.encode(&mut buf).expect("encodes");
    assert_eq!(n, ResetRecord::LEN);
    assert_eq!(buf[0], 0x09);
    assert_eq!(ResetRecord::decode(&buf[..n]).expect("decodes"), r);
    assert_eq!(r.to_string(), format!("panic after 12.3 s: {}", "x".repeat(48)));
}

#[test]
fn a_bad_kind_or_reserved_byte_is_refused() {
    let mut buf = [0u8; 64];
    let n = ResetRecord::NONE.encode(&mut buf).expect("encodes");
    buf[1] = 4;
    assert!(ResetRecord::decode(&buf[..n]).is_err());
    buf[1] = 0;
    buf[2] = 1;
    assert!(ResetRecord::decode(&buf[..n]).is_err());
}

#[test]
fn a_stacking_fault_reads_as_a_stack_overflow() {
    let r = ResetRecord {
        kind: ResetKind::Fault,
        column: 1 << 12,
        ..ResetRecord::NONE
    };
    assert!(r.to_string().ends_with("stack overflow"), "{r}");
    let r = ResetRecord { column: 1 << 8, ..r };
    assert!(!r.to_string().contains("overflow"), "{r}");
}
