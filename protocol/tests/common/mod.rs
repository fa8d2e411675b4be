//! Sample reports and proptest strategies shared by the protocol's tests.
#![allow(dead_code)]

use pen_protocol::*;
use proptest::prelude::*;

pub mod splice;

/// The pen report the golden tests and the documentation's examples use.
pub fn sample_pen() -> PenReport {
    PenReport {
        sw1: true,
        sw2: false,
        sw3: true,
        in_range: true,
        display_frame: false,
        position: Position {
            x: 1234,
            y: -567,
            z: 890,
        },
        seq: 0x1234,
        timestamp_us: 0x0102_0304,
        quality: Quality {
            receivers_used: 5,
            residual: 7,
            dop: 18,
        },
    }
}

/// A valid configuration: four receivers around a 600 × 400 mm display, two of them raised.
pub fn sample_config() -> Config {
    let mut receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
    receivers_mm[..4].copy_from_slice(&[
        [0.0, 0.0, 0.0],
        [600.0, 0.0, 0.0],
        [0.0, 400.0, 150.0],
        [600.0, 400.0, 150.0],
    ]);
    let mut transducer_delay_us = [0.0; MAX_RECEIVERS];
    transducer_delay_us[..4].copy_from_slice(&[12.5, 12.5, 13.0, 12.0]);
    Config {
        receiver_count: 4,
        receivers_mm,
        transducer_delay_us,
        temperature_c: 21.5,
        speed_of_sound_m_s: None,
        report_rate_hz: 150,
        filter: Filter::OneEuro {
            min_cutoff_hz: 1.0,
            beta: 0.02,
            d_cutoff_hz: 1.0,
        },
        debounce_ms: 5,
        display: Some(DisplayPose {
            rotation: [1.0, 0.0, 0.0, 0.0],
            translation_mm: [-10.0, 20.0, 0.0],
            scale: 1.0,
            size_mm: [600.0, 340.0],
        }),
        report_display_frame: false,
        stream_tof: true,
    }
}

/// Any finite f32, zero and subnormals included.
pub fn finite() -> impl Strategy<Value = f32> {
    prop_oneof![
        proptest::num::f32::NORMAL | proptest::num::f32::ZERO | proptest::num::f32::SUBNORMAL,
        -2000.0f32..2000.0,
    ]
}

pub fn pen() -> impl Strategy<Value = PenReport> {
    let axis = -POSITION_LOGICAL_MAX..=POSITION_LOGICAL_MAX;
    (
        any::<[bool; 5]>(),
        (axis.clone(), axis.clone(), axis),
        any::<u16>(),
        any::<u32>(),
        (0..=MAX_RECEIVERS as u8, any::<u8>(), any::<u8>()),
    )
        .prop_map(
            |(b, (x, y, z), seq, timestamp_us, (receivers_used, residual, dop))| PenReport {
                sw1: b[0],
                sw2: b[1],
                sw3: b[2],
                in_range: b[3],
                display_frame: b[4],
                position: Position { x, y, z },
                seq,
                timestamp_us,
                quality: Quality {
                    receivers_used,
                    residual,
                    dop,
                },
            },
        )
}

pub fn tof() -> impl Strategy<Value = TofReport> {
    (
        0..=MAX_RECEIVERS as u8,
        any::<u16>(),
        any::<u32>(),
        any::<[u32; MAX_RECEIVERS]>(),
        any::<u8>(),
        finite(),
    )
        .prop_map(|(count, seq, timestamp_us, raw, mask, speed)| {
            let mut tof_ns = [NO_ARRIVAL; MAX_RECEIVERS];
            let mut used_mask = 0;
            for i in 0..count as usize {
                // Every fourth receiver heard nothing, to cover the marker.
                tof_ns[i] = if raw[i] % 4 == 0 { NO_ARRIVAL } else { raw[i] };
                if tof_ns[i] != NO_ARRIVAL && mask & (1 << i) != 0 {
                    used_mask |= 1 << i;
                }
            }
            TofReport {
                seq,
                timestamp_us,
                receiver_count: count,
                used_mask,
                tof_ns,
                speed_of_sound_m_s: speed,
            }
        })
}

pub fn info() -> impl Strategy<Value = DeviceInfo> {
    (
        any::<[u8; 7]>(),
        0..=MAX_RECEIVERS as u8,
        any::<u16>(),
        any::<[u8; 12]>(),
    )
        .prop_flat_map(|(v, max_receivers, fix_rate_hz, unique_id)| {
            (0..=max_receivers).prop_map(move |receiver_count| DeviceInfo {
                protocol: Version {
                    major: v[0],
                    minor: v[1],
                },
                firmware: FirmwareVersion {
                    major: v[2],
                    minor: v[3],
                    patch: v[4],
                },
                receiver_count,
                max_receivers,
                fix_rate_hz,
                unique_id,
            })
        })
}

fn filter() -> impl Strategy<Value = Filter> {
    prop_oneof![
        Just(Filter::Off),
        (finite(), finite(), finite()).prop_map(|(min_cutoff_hz, beta, d_cutoff_hz)| Filter::OneEuro {
            min_cutoff_hz,
            beta,
            d_cutoff_hz
        }),
    ]
}

fn pose() -> impl Strategy<Value = Option<DisplayPose>> {
    proptest::option::of(
        (
            [finite(), finite(), finite(), finite()],
            [finite(), finite(), finite()],
            finite(),
            [finite(), finite()],
        )
            .prop_map(|(rotation, translation_mm, scale, size_mm)| DisplayPose {
                rotation,
                translation_mm,
                scale,
                size_mm,
            }),
    )
}

/// Any configuration in canonical form (unused slots zero): what decoding can yield.
pub fn config() -> impl Strategy<Value = Config> {
    (
        0..=MAX_RECEIVERS as u8,
        proptest::collection::vec([finite(), finite(), finite()], MAX_RECEIVERS),
        proptest::collection::vec(finite(), MAX_RECEIVERS),
        (finite(), proptest::option::of(finite()), any::<u16>(), any::<u8>()),
        filter(),
        pose(),
        any::<[bool; 2]>(),
    )
        .prop_map(
            |(
                count,
                receivers,
                delays,
                (temperature_c, speed, report_rate_hz, debounce_ms),
                filter,
                display,
                flags,
            )| {
                let mut receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
                let mut transducer_delay_us = [0.0; MAX_RECEIVERS];
                let n = count as usize;
                receivers_mm[..n].copy_from_slice(&receivers[..n]);
                transducer_delay_us[..n].copy_from_slice(&delays[..n]);
                Config {
                    receiver_count: count,
                    receivers_mm,
                    transducer_delay_us,
                    temperature_c,
                    speed_of_sound_m_s: speed,
                    report_rate_hz,
                    filter,
                    debounce_ms,
                    display,
                    report_display_frame: flags[0],
                    stream_tof: flags[1],
                }
            },
        )
}

pub fn status() -> impl Strategy<Value = Status> {
    let codes = [
        StatusCode::Ok,
        StatusCode::UnknownReport,
        StatusCode::Malformed,
        StatusCode::OutOfRange,
        StatusCode::Degenerate,
        StatusCode::Missing,
        StatusCode::ReadOnly,
        StatusCode::StorageFailed,
        StatusCode::Unsupported,
    ];
    let fields = prop_oneof![Just(0u8), 0x01u8..=0x09, 0x10u8..=0x1f];
    (any::<u8>(), proptest::sample::select(codes.to_vec()), fields).prop_map(|(request, code, field)| Status {
        request,
        code,
        field,
    })
}

/// Any head report in canonical form: receivers used 0 exactly when there is no fix.
pub fn head() -> impl Strategy<Value = HeadReport> {
    (
        any::<[bool; 2]>(),
        [-i16::MAX..=i16::MAX, -i16::MAX..=i16::MAX, -i16::MAX..=i16::MAX],
        0..=MAX_PREDICTION_MS,
        any::<u16>(),
        any::<u32>(),
        (1..=MAX_RECEIVERS as u8, any::<u8>(), any::<u8>()),
    )
        .prop_map(
            |([no_fix, display_frame], [x, y, z], prediction_ms, seq, timestamp_us, q)| HeadReport {
                no_fix,
                display_frame,
                position: Position { x, y, z },
                prediction_ms,
                seq,
                timestamp_us,
                quality: if no_fix {
                    Quality::NONE
                } else {
                    Quality {
                        receivers_used: q.0,
                        residual: q.1,
                        dop: q.2,
                    }
                },
            },
        )
}

pub fn message() -> impl Strategy<Value = Message> {
    prop_oneof![
        pen().prop_map(Message::Pen),
        head().prop_map(Message::Head),
        tof().prop_map(Message::Tof),
        info().prop_map(Message::DeviceInfo),
        config().prop_map(Message::Config),
        status().prop_map(Message::Status),
        proptest::sample::select(vec![
            Command::SaveConfig,
            Command::LoadDefaults,
            Command::EnterBootloader,
            Command::HeadOn,
            Command::HeadOff
        ])
        .prop_map(Message::Command),
        proptest::sample::select(vec![ReportId::DeviceInfo, ReportId::Config, ReportId::Status])
            .prop_map(|report| Message::GetFeature(GetFeature { report })),
    ]
}

/// Encodes a message into a fresh vector.
pub fn encode(m: &Message) -> Vec<u8> {
    let mut buf = [0u8; MAX_PAYLOAD];
    let n = m.encode(&mut buf).expect("every message fits MAX_PAYLOAD");
    buf[..n].to_vec()
}
