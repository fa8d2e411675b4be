//! The head report (0x08, protocol 2.1): its bytes, its checks, and what an older host does
//! with it.

use pen_protocol::*;

fn sample_head() -> HeadReport {
    HeadReport {
        no_fix: false,
        display_frame: true,
        position: Position {
            x: 3000,
            y: 1700,
            z: 7000,
        },
        prediction_ms: 30,
        seq: 0x0102,
        timestamp_us: 0x0a0b_0c0d,
        quality: Quality {
            receivers_used: 4,
            residual: 9,
            dop: 21,
        },
    }
}

#[test]
fn golden_bytes() {
    // Written out by hand from docs/protocol.md's table, little-endian.
    let golden = [
        0x08, // report ID
        0x02, // flags: display frame
        0xb8, 0x0b, // x 3000
        0xa4, 0x06, // y 1700
        0x58, 0x1b, // z 7000
        30,   // prediction, ms
        0x02, 0x01, // seq
        0x0d, 0x0c, 0x0b, 0x0a, // timestamp
        4, 9, 21, // receivers, residual, DOP
    ];
    assert_eq!(sample_head().to_bytes(), golden);
    assert_eq!(Message::decode(&golden), Ok(Message::Head(sample_head())));
}

#[test]
fn no_fix_and_receivers_used_must_agree() {
    let mut bytes = sample_head().to_bytes();
    bytes[1] |= 0x01; // no fix, yet 4 receivers used
    assert_eq!(
        Message::decode(&bytes),
        Err(DecodeError::OutOfRange {
            report: ReportId::Head,
            field: "receivers_used"
        })
    );
    bytes[15] = 0;
    assert!(matches!(Message::decode(&bytes), Ok(Message::Head(h)) if h.no_fix));
}

#[test]
fn out_of_range_fields_are_named() {
    let mut bytes = sample_head().to_bytes();
    bytes[8] = MAX_PREDICTION_MS + 1;
    assert_eq!(
        Message::decode(&bytes),
        Err(DecodeError::OutOfRange {
            report: ReportId::Head,
            field: "prediction_ms"
        })
    );
    let mut bytes = sample_head().to_bytes();
    bytes[1] = 0x04;
    assert!(matches!(
        Message::decode(&bytes),
        Err(DecodeError::ReservedBits { offset: 1, .. })
    ));
    let mut bytes = sample_head().to_bytes();
    bytes[6..8].copy_from_slice(&i16::MIN.to_le_bytes());
    assert_eq!(
        Message::decode(&bytes),
        Err(DecodeError::OutOfRange {
            report: ReportId::Head,
            field: "z"
        })
    );
    assert!(matches!(
        Message::decode(&sample_head().to_bytes()[..17]),
        Err(DecodeError::Length {
            expected: 18,
            found: 17,
            ..
        })
    ));
}

#[test]
fn framed_on_the_serial_link() {
    let mut frame = [0u8; MAX_FRAME];
    let n = encode_report_frame(&sample_head(), &mut frame).expect("frames");
    let mut decoder = FrameDecoder::new();
    let mut got = None;
    for &b in &frame[..n] {
        if let Some(r) = decoder.push(b) {
            got = Some(r.map(|p| p.to_vec()));
        }
    }
    assert_eq!(got, Some(Ok(sample_head().to_bytes().to_vec())));
}

#[test]
fn a_version_2_0_host_reads_it_as_an_unknown_report() {
    // What a 2.0 host does with the bytes: its decoder has no 0x08, so the report is an unknown
    // ID (dropped and counted), never mistaken for a pen report; and 2.1 is a minor version of
    // the major it supports, so it keeps the device.
    let bytes = sample_head().to_bytes();
    assert!(PenReport::decode(&bytes).is_err());
    assert_eq!(PROTOCOL_VERSION, Version { major: 2, minor: 2 });
    assert!(check_version(Version { major: 2, minor: 1 }).is_ok());
}

#[test]
fn described_in_the_vendor_collection() {
    // A vendor byte array: report ID 0x08, usage 0xff00:0x28, 17 bytes of 8 bits, Input.
    let d = &REPORT_DESCRIPTOR;
    let item = [0x85, 0x08, 0x09, 0x28, 0x75, 0x08, 0x95, 0x11, 0x81, 0x02];
    assert!(d.windows(item.len()).any(|w| w == item), "{d:02x?}");
}

#[test]
fn head_tracking_commands() {
    // Command report bytes 4 and 5 (protocol 2.1); 6 is still unknown.
    assert_eq!(Message::decode(&[0x06, 4]), Ok(Message::Command(Command::HeadOn)));
    assert_eq!(Message::decode(&[0x06, 5]), Ok(Message::Command(Command::HeadOff)));
    assert!(matches!(
        Message::decode(&[0x06, 6]),
        Err(DecodeError::OutOfRange { field: "command", .. })
    ));
}
