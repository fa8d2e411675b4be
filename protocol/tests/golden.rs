//! Golden bytes: every report and a few frames, written out by hand from the layout in
//! docs/protocol.md (the frames' CRCs were checked with Python's zlib.crc32). A change that moves
//! any of these bytes is a protocol change and bumps the protocol version.

use crate::common;

use common::*;
use pen_protocol::*;

fn hex(s: &str) -> Vec<u8> {
    let s: String = s.split_whitespace().collect();
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

fn check(m: Message, golden: &str) {
    let golden = hex(golden);
    assert_eq!(encode(&m), golden, "encoding of {m:?}");
    assert_eq!(Message::decode(&golden), Ok(m), "decoding of the golden bytes");
}

#[test]
fn pen_report() {
    // id, switches SW1+SW3+in range, x 1234, y -567, z 890, seq 0x1234, timestamp, 5 receivers, 0.7 mm, DOP 1.8
    check(
        Message::Pen(sample_pen()),
        "01 0d d204 c9fd 7a03 3412 04030201 05 07 12",
    );
    assert_eq!(
        sample_pen().to_bytes().to_vec(),
        hex("01 0d d204 c9fd 7a03 3412 04030201 05 07 12")
    );
}

#[test]
fn tof_report() {
    let mut tof_ns = [NO_ARRIVAL; MAX_RECEIVERS];
    tof_ns[..4].copy_from_slice(&[1_000_000, 1_500_000, NO_ARRIVAL, 2_000_000]);
    let r = TofReport {
        seq: 0x1234,
        timestamp_us: 0x0102_0304,
        receiver_count: 4,
        used_mask: 0b1011,
        tof_ns,
        speed_of_sound_m_s: 343.0,
    };
    check(
        Message::Tof(r),
        "02 3412 04030201 04 0b
         40420f00 60e31600 ffffffff 80841e00 ffffffff ffffffff ffffffff ffffffff
         0080ab43",
    );
}

#[test]
fn device_info() {
    let r = DeviceInfo {
        protocol: Version { major: 1, minor: 0 },
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        receiver_count: 4,
        max_receivers: 8,
        fix_rate_hz: 150,
        unique_id: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11],
    };
    check(
        Message::DeviceInfo(r),
        "03 01 00 00 01 00 04 08 9600 000102030405060708090a0b",
    );
}

#[test]
fn config() {
    check(
        Message::Config(sample_config()),
        "04 04 0a 01 05 9600
         0000ac41 00000000
         0000803f 0ad7a33c 0000803f
         00000000 00000000 00000000
         00001644 00000000 00000000
         00000000 0000c843 00001643
         00001644 0000c843 00001643
         000000000000000000000000 000000000000000000000000
         000000000000000000000000 000000000000000000000000
         00004841 00004841 00005041 00004041 00000000 00000000 00000000 00000000
         0000803f 00000000 00000000 00000000
         000020c1 0000a041 00000000
         0000803f
         00001644 0000aa43",
    );
}

#[test]
fn os_pen_report() {
    // id, tip + in range, x 3000 (300.0 mm), y 1700 (170.0 mm)
    check(
        Message::OsPen(OsPenReport {
            tip: true,
            barrel: false,
            secondary_barrel: false,
            in_range: true,
            x: 3000,
            y: 1700,
        }),
        "07 09 b80b a406",
    );
}

#[test]
fn status_command_get_feature() {
    check(
        Message::Status(Status {
            request: 0x04,
            code: StatusCode::OutOfRange,
            field: 0x12,
        }),
        "05 04 03 12",
    );
    check(Message::Command(Command::SaveConfig), "06 01");
    check(Message::Command(Command::EnterBootloader), "06 03");
    check(
        Message::GetFeature(GetFeature {
            report: ReportId::Config,
        }),
        "80 04",
    );
}

fn frame(m: &Message) -> Vec<u8> {
    let mut out = [0u8; MAX_FRAME];
    let n = encode_frame(&encode(m), &mut out).expect("fits");
    out[..n].to_vec()
}

#[test]
fn frames() {
    // No zero in the payload: one COBS block of 21 bytes (code 0x16), then the CRC.
    assert_eq!(
        frame(&Message::Pen(sample_pen())),
        hex("00 16 010dd204c9fd7a03341204030201050712 2a520ac6 00")
    );
    // Zeros in the payload become COBS codes.
    assert_eq!(
        frame(&Message::Status(Status::ok(0x04))),
        hex("00 03 0504 01 05 f2879311 00")
    );
    assert_eq!(
        frame(&Message::GetFeature(GetFeature {
            report: ReportId::Config
        })),
        hex("00 07 8004ad4e377d 00")
    );
}

#[test]
fn descriptor_starts_with_the_pen_collection() {
    // Usage Page (Digitizer), Usage (Pen), Collection (Application), Report ID (7, the OS's
    // pen), Usage (Stylus), Collection (Physical), Usage (Tip Switch).
    assert_eq!(
        REPORT_DESCRIPTOR[..13],
        hex("05 0d 09 02 a1 01 85 07 09 20 a1 00 09")[..]
    );
    assert_eq!(REPORT_DESCRIPTOR[13], 0x42);
    assert_eq!(REPORT_DESCRIPTOR.last(), Some(&0xc0));
}
