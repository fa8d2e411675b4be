//! Truncated, oversized and corrupt input is rejected with the error that says what is wrong.

use crate::common;

use common::*;
use pen_protocol::*;

#[test]
fn empty_and_unknown() {
    assert_eq!(Message::decode(&[]), Err(DecodeError::Empty));
    assert_eq!(PenReport::decode(&[]), Err(DecodeError::Empty));
    assert_eq!(Message::decode(&[0x0a, 1, 2]), Err(DecodeError::UnknownReportId(0x0a)));
    assert_eq!(Message::decode(&[0x00]), Err(DecodeError::UnknownReportId(0x00)));
    let tof = [0x02u8; TofReport::LEN];
    assert_eq!(
        PenReport::decode(&tof),
        Err(DecodeError::WrongReportId {
            expected: ReportId::Pen,
            found: 0x02
        })
    );
}

#[test]
fn truncated_and_oversized_every_report() {
    let messages = [
        Message::Pen(sample_pen()),
        Message::Config(sample_config()),
        Message::Status(Status::ok(4)),
        Message::Command(Command::LoadDefaults),
        Message::GetFeature(GetFeature {
            report: ReportId::Status,
        }),
    ];
    for m in messages {
        let bytes = encode(&m);
        let full = bytes.len();
        for len in 1..full {
            assert_eq!(
                Message::decode(&bytes[..len]),
                Err(DecodeError::Length {
                    report: m.id(),
                    expected: full,
                    found: len
                }),
                "{m:?} truncated to {len}"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert_eq!(
            Message::decode(&longer),
            Err(DecodeError::Length {
                report: m.id(),
                expected: full,
                found: full + 1
            })
        );
    }
}

#[test]
fn error_messages_say_what_and_where() {
    let bytes = sample_pen().to_bytes();
    let err = Message::decode(&bytes[..10]).unwrap_err();
    assert_eq!(err.to_string(), "truncated pen report: 10 bytes, expected 17");
    let mut long = bytes.to_vec();
    long.push(0);
    assert_eq!(
        Message::decode(&long).unwrap_err().to_string(),
        "oversized pen report: 18 bytes, expected 17"
    );
}

#[test]
fn pen_report_fields() {
    let good = sample_pen().to_bytes();

    let mut b = good;
    b[1] |= 0x20;
    assert_eq!(
        PenReport::decode(&b),
        Err(DecodeError::ReservedBits {
            report: ReportId::Pen,
            offset: 1,
            value: 0x20
        })
    );

    let mut b = good;
    b[4..6].copy_from_slice(&i16::MIN.to_le_bytes());
    assert_eq!(
        PenReport::decode(&b),
        Err(DecodeError::OutOfRange {
            report: ReportId::Pen,
            field: "y"
        })
    );

    let mut b = good;
    b[14] = 9;
    assert_eq!(
        PenReport::decode(&b),
        Err(DecodeError::OutOfRange {
            report: ReportId::Pen,
            field: "receivers_used"
        })
    );
}

#[test]
fn tof_report_fields() {
    let mut tof_ns = [NO_ARRIVAL; MAX_RECEIVERS];
    tof_ns[0] = 1000;
    let r = TofReport {
        seq: 1,
        timestamp_us: 2,
        receiver_count: 2,
        used_mask: 1,
        tof_ns,
        speed_of_sound_m_s: 343.0,
    };
    let good = encode(&Message::Tof(r));

    // Receiver 1 heard nothing, so it cannot have been used.
    let mut b = good.clone();
    b[8] = 0b11;
    assert!(
        matches!(TofReport::decode(&b), Err(DecodeError::OutOfRange { field, .. }) if field.starts_with("used_mask"))
    );
    // Receiver 2 is not configured.
    let mut b = good.clone();
    b[8] = 0b101;
    assert_eq!(
        TofReport::decode(&b),
        Err(DecodeError::ReservedBits {
            report: ReportId::Tof,
            offset: 8,
            value: 0b100
        })
    );
    let mut b = good.clone();
    b[17..21].copy_from_slice(&5u32.to_le_bytes());
    assert!(matches!(TofReport::decode(&b), Err(DecodeError::OutOfRange { .. })));
    let mut b = good;
    b[41..45].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(
        TofReport::decode(&b),
        Err(DecodeError::NotFinite {
            report: ReportId::Tof,
            field: "speed_of_sound_m_s"
        })
    );
}

#[test]
fn config_form() {
    let good = encode(&Message::Config(sample_config()));
    let at = |offset: usize, value: &[u8]| {
        let mut b = good.clone();
        b[offset..offset + value.len()].copy_from_slice(value);
        Config::decode(&b)
    };
    assert_eq!(
        at(1, &[9]),
        Err(DecodeError::OutOfRange {
            report: ReportId::Config,
            field: "receiver_count"
        })
    );
    assert_eq!(
        at(2, &[0x1a]),
        Err(DecodeError::ReservedBits {
            report: ReportId::Config,
            offset: 2,
            value: 0x10
        })
    );
    assert_eq!(
        at(3, &[7]),
        Err(DecodeError::ReservedBits {
            report: ReportId::Config,
            offset: 3,
            value: 7
        })
    );
    assert_eq!(
        at(7, &f32::INFINITY.to_le_bytes()),
        Err(DecodeError::NotFinite {
            report: ReportId::Config,
            field: "temperature_c"
        })
    );
    // The speed of sound without its flag must be zero.
    assert_eq!(
        at(11, &343.0f32.to_le_bytes()),
        Err(DecodeError::UnusedNotZero {
            report: ReportId::Config,
            offset: 11,
            field: "speed_of_sound_m_s"
        })
    );
    // Receiver 4 is beyond the count of 4 (bytes 27 + 12·4 = 75).
    assert_eq!(
        at(75, &1.0f32.to_le_bytes()),
        Err(DecodeError::UnusedNotZero {
            report: ReportId::Config,
            offset: 75,
            field: "receivers_mm beyond receiver_count"
        })
    );
    // -0.0 is not zero bits in an unused slot.
    assert!(matches!(
        at(79, &(-0.0f32).to_le_bytes()),
        Err(DecodeError::UnusedNotZero { offset: 79, .. })
    ));
}

#[test]
fn config_values() {
    let good = sample_config();
    assert_eq!(good.validate(), Ok(()));
    let fails = |f: &dyn Fn(&mut Config), field, problem| {
        let mut c = good;
        f(&mut c);
        assert_eq!(c.validate(), Err(ConfigError { field, problem }), "{c:?}");
    };
    fails(
        &|c| c.receiver_count = 2,
        ConfigField::ReceiverCount,
        Problem::OutOfRange,
    );
    fails(
        &|c| c.receivers_mm[1] = [5001.0, 0.0, 0.0],
        ConfigField::Receiver(1),
        Problem::OutOfRange,
    );
    fails(
        &|c| c.receivers_mm[2][0] = f32::NAN,
        ConfigField::Receiver(2),
        Problem::OutOfRange,
    );
    fails(
        &|c| c.receivers_mm[3] = [5.0, 5.0, 0.0],
        ConfigField::Receiver(3),
        Problem::Degenerate,
    );
    fails(
        &|c| {
            c.receivers_mm[..4].copy_from_slice(&[[0.0; 3], [100.0, 0.0, 0.0], [200.0, 5.0, 0.0], [300.0, -5.0, 0.0]]);
        },
        ConfigField::Receivers,
        Problem::Degenerate,
    );
    fails(
        &|c| c.transducer_delay_us[0] = -1.0,
        ConfigField::TransducerDelay(0),
        Problem::OutOfRange,
    );
    fails(
        &|c| c.temperature_c = 293.0,
        ConfigField::Temperature,
        Problem::OutOfRange,
    );
    fails(
        &|c| c.speed_of_sound_m_s = Some(0.343),
        ConfigField::SpeedOfSound,
        Problem::OutOfRange,
    );
    fails(
        &|c| c.report_rate_hz = 1001,
        ConfigField::ReportRate,
        Problem::OutOfRange,
    );
    fails(
        &|c| {
            c.filter = Filter::OneEuro {
                min_cutoff_hz: 0.0,
                beta: 0.0,
                d_cutoff_hz: 1.0,
            }
        },
        ConfigField::Filter,
        Problem::OutOfRange,
    );
    fails(&|c| c.debounce_ms = 200, ConfigField::Debounce, Problem::OutOfRange);
    fails(
        &|c| {
            c.display = Some(DisplayPose {
                rotation: [0.5, 0.0, 0.0, 0.0],
                translation_mm: [0.0; 3],
                scale: 1.0,
                size_mm: [0.0; 2],
            })
        },
        ConfigField::Display,
        Problem::Degenerate,
    );
    fails(
        &|c| {
            c.display = Some(DisplayPose {
                rotation: [1.0, 0.0, 0.0, 0.0],
                translation_mm: [0.0; 3],
                scale: 3.0,
                size_mm: [0.0; 2],
            })
        },
        ConfigField::Display,
        Problem::OutOfRange,
    );
    // A display size: unknown (both 0) or both within 50 mm … 3276.7 mm.
    for size in [
        [600.0, 0.0],
        [20.0, 300.0],
        [4000.0, 300.0],
        [f32::NAN, 300.0],
        [-600.0, 340.0],
    ] {
        fails(
            &|c| {
                if let Some(d) = c.display.as_mut() {
                    d.size_mm = size;
                }
            },
            ConfigField::Display,
            Problem::OutOfRange,
        );
    }
    for size in [[0.0, 0.0], [600.0, 340.0], [50.0, 3276.7]] {
        let mut c = good;
        if let Some(d) = c.display.as_mut() {
            d.size_mm = size;
        }
        assert_eq!(c.validate(), Ok(()), "{size:?}");
    }
    fails(
        &|c| {
            c.display = None;
            c.report_display_frame = true;
        },
        ConfigField::ReportDisplayFrame,
        Problem::Missing,
    );

    // Three receivers, off the line: the fewest allowed.
    let mut c = good;
    c.receiver_count = 3;
    assert_eq!(c.validate(), Ok(()));
}

#[test]
fn status_names_the_field() {
    let err = ConfigError {
        field: ConfigField::Receiver(2),
        problem: Problem::Degenerate,
    };
    let s = Status::from_config_error(ReportId::Config as u8, err);
    assert_eq!(s.config_field(), Some(ConfigField::Receiver(2)));
    assert_eq!(
        s.to_string(),
        "configuration (0x04) rejected: degenerate (receivers_mm[2])"
    );
    for code in (0..=0xffu8).filter(|&c| ConfigField::from_code(c).is_some()) {
        assert_eq!(ConfigField::from_code(code).map(ConfigField::code), Some(code));
    }
}

#[test]
fn versions() {
    assert_eq!(check_version(PROTOCOL_VERSION), Ok(()));
    assert_eq!(check_version(Version { major: 2, minor: 9 }), Ok(()));
    // Protocol 1's configuration report was 8 bytes shorter: a version 1 device is refused.
    let err = check_version(Version { major: 1, minor: 0 }).unwrap_err();
    assert_eq!(
        err.to_string(),
        "the device speaks protocol 1.0, this host understands 2.x; update the host software or the firmware"
    );
    assert!(check_version(Version { major: 3, minor: 0 }).is_err());
}
