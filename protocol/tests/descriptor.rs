//! The report descriptor, parsed by an independent parser (hidreport, from the hid-tools
//! maintainers), against the report codecs: every field's offset and size, every report's length.

use crate::common;

use common::*;
use hidreport::{Field, Report as HidReport, ReportDescriptor, VariableField};
use pen_protocol::*;

fn parsed() -> ReportDescriptor {
    ReportDescriptor::try_from(&REPORT_DESCRIPTOR[..]).expect("the descriptor parses")
}

fn usage_of(f: &VariableField) -> (u16, u16) {
    (u16::from(f.usage.usage_page), u16::from(f.usage.usage_id))
}

/// The pen report's variable fields, in order, with their bit ranges.
fn pen_fields(rd: &ReportDescriptor) -> Vec<VariableField> {
    let report = rd
        .input_reports()
        .iter()
        .find(|r| r.report_id().map(u8::from) == Some(ReportId::Pen as u8))
        .expect("pen input report");
    assert_eq!(report.size_in_bytes(), PenReport::LEN, "pen report length");
    report
        .fields()
        .iter()
        .filter_map(|f| match f {
            Field::Variable(v) => Some(v.clone()),
            Field::Constant(c) => {
                // Padding: the codec must write zeros there and reject ones.
                assert_eq!(c.bits, 13..16, "padding bits");
                None
            }
            Field::Array(_) => panic!("no array fields expected"),
        })
        .collect()
}

/// Reads `bits` of `bytes` as a little-endian unsigned integer, the way a HID host does.
fn bits_value(bytes: &[u8], bits: &std::ops::Range<usize>) -> u64 {
    bits.clone()
        .rev()
        .fold(0u64, |acc, bit| (acc << 1) | ((bytes[bit / 8] >> (bit % 8)) & 1) as u64)
}

#[test]
fn every_report_has_the_codec_length() {
    let rd = parsed();
    let len = |reports: &[&dyn HidReport], id: ReportId| {
        reports
            .iter()
            .find(|r| r.report_id().map(u8::from) == Some(id as u8))
            .map(|r| r.size_in_bytes())
            .unwrap_or_else(|| panic!("{id} report missing"))
    };
    let inputs: Vec<&dyn HidReport> = rd.input_reports().iter().map(|r| r as &dyn HidReport).collect();
    let features: Vec<&dyn HidReport> = rd.feature_reports().iter().map(|r| r as &dyn HidReport).collect();
    assert_eq!(inputs.len(), 2);
    assert_eq!(features.len(), 4);
    assert!(rd.output_reports().is_empty());
    assert_eq!(len(&inputs, ReportId::Pen), PenReport::LEN);
    assert_eq!(len(&inputs, ReportId::Tof), TofReport::LEN);
    assert_eq!(len(&features, ReportId::DeviceInfo), DeviceInfo::LEN);
    assert_eq!(len(&features, ReportId::Config), Config::LEN);
    assert_eq!(len(&features, ReportId::Status), Status::LEN);
    assert_eq!(len(&features, ReportId::Command), Command::LEN);
}

#[test]
fn pen_fields_have_the_documented_usages_and_units() {
    let fields = pen_fields(&parsed());
    let usages: Vec<(u16, u16)> = fields.iter().map(usage_of).collect();
    use usage::*;
    assert_eq!(
        usages,
        [
            (PAGE_DIGITIZER, TIP_SWITCH),
            (PAGE_DIGITIZER, BARREL_SWITCH),
            (PAGE_DIGITIZER, SECONDARY_BARREL_SWITCH),
            (PAGE_DIGITIZER, IN_RANGE),
            (PAGE_VENDOR, VENDOR_DISPLAY_FRAME),
            (PAGE_GENERIC_DESKTOP, X),
            (PAGE_GENERIC_DESKTOP, Y),
            (PAGE_GENERIC_DESKTOP, Z),
            (PAGE_VENDOR, VENDOR_SEQUENCE),
            (PAGE_VENDOR, VENDOR_TIMESTAMP),
            (PAGE_VENDOR, VENDOR_RECEIVERS_USED),
            (PAGE_VENDOR, VENDOR_RESIDUAL),
            (PAGE_VENDOR, VENDOR_DOP),
        ]
    );
    // The application collection is Digitizer / Pen.
    let app = &fields[0].collections[0];
    assert_eq!(app.usages()[0].usage_page, 0x0D.into());
    assert_eq!(app.usages()[0].usage_id, 0x02.into());
    for axis in &fields[5..8] {
        assert_eq!(i32::from(axis.logical_minimum), -32767);
        assert_eq!(i32::from(axis.logical_maximum), 32767);
        assert_eq!(axis.physical_minimum.map(i32::from), Some(-32767));
        assert_eq!(axis.physical_maximum.map(i32::from), Some(32767));
        // SI linear centimetres, exponent −2 (nibble 0xE): one unit is 0.1 mm.
        assert_eq!(axis.unit.map(u32::from), Some(0x11));
        assert_eq!(axis.unit_exponent.map(|e| e.exponent()), Some(-2));
    }
}

/// For every field, a report whose value in that field is distinctive, read back at the bits the
/// descriptor declares, must give the value the codec wrote.
#[test]
fn every_pen_field_sits_where_the_codec_writes_it() {
    let fields = pen_fields(&parsed());
    let base = PenReport {
        sw1: false,
        sw2: false,
        sw3: false,
        in_range: false,
        display_frame: false,
        position: Position::default(),
        seq: 0,
        timestamp_us: 0,
        quality: Quality {
            receivers_used: 0,
            residual: 0,
            dop: 0,
        },
    };
    type Set = fn(&mut PenReport);
    // (field index, how to set a distinctive value, the raw value expected in the field's bits)
    let cases: [(usize, Set, u64); 13] = [
        (0, |r| r.sw1 = true, 1),
        (1, |r| r.sw2 = true, 1),
        (2, |r| r.sw3 = true, 1),
        (3, |r| r.in_range = true, 1),
        (4, |r| r.display_frame = true, 1),
        (5, |r| r.position.x = -12345, (-12345i16) as u16 as u64),
        (6, |r| r.position.y = 23456, 23456),
        (7, |r| r.position.z = -2, 0xFFFE),
        (8, |r| r.seq = 0xBEEF, 0xBEEF),
        (9, |r| r.timestamp_us = 0xDEAD_BEEF, 0xDEAD_BEEF),
        (10, |r| r.quality.receivers_used = 7, 7),
        (11, |r| r.quality.residual = 0xA5, 0xA5),
        (12, |r| r.quality.dop = 0x5A, 0x5A),
    ];
    let mut covered = 0;
    for (index, set, raw) in cases {
        let mut r = base;
        set(&mut r);
        let bytes = r.to_bytes();
        let field = &fields[index];
        assert_eq!(
            bits_value(&bytes, &field.bits),
            raw,
            "field {index} {:?}",
            usage_of(field)
        );
        // Every other field reads zero: the value landed in exactly this field's bits.
        for (j, other) in fields.iter().enumerate().filter(|(j, _)| *j != index) {
            assert_eq!(
                bits_value(&bytes, &other.bits),
                0,
                "field {j} disturbed by field {index}"
            );
        }
        // hidreport's own extraction agrees, with the sign from the logical minimum.
        let v = field.extract(&bytes).expect("extract");
        if field.is_signed() {
            assert_eq!(i32::from(&v) as i64, raw as u16 as i16 as i64);
        } else {
            assert_eq!(u32::from(&v) as u64, raw);
        }
        covered += field.bits.len();
    }
    // The fields plus 3 padding bits fill the report after the ID byte.
    assert_eq!(covered + 3, (PenReport::LEN - 1) * 8);
}

#[test]
fn vendor_reports_are_byte_arrays_covering_the_codec_bytes() {
    let rd = parsed();
    let check = |report: &dyn HidReport, len: usize| {
        let fields = report.fields();
        assert_eq!(fields.len(), len - 1, "one byte field per body byte");
        for (i, f) in fields.iter().enumerate() {
            assert_eq!(f.bits(), &((i + 1) * 8..(i + 2) * 8));
        }
    };
    for r in rd.feature_reports() {
        let id = ReportId::from_u8(r.report_id().map(u8::from).expect("report ID")).expect("known ID");
        let len = match id {
            ReportId::DeviceInfo => DeviceInfo::LEN,
            ReportId::Config => Config::LEN,
            ReportId::Status => Status::LEN,
            ReportId::Command => Command::LEN,
            other => panic!("{other} is not a feature report"),
        };
        check(r, len);
    }
    let tof = rd
        .input_reports()
        .iter()
        .find(|r| r.report_id().map(u8::from) == Some(2))
        .expect("tof");
    check(tof, TofReport::LEN);
}

#[test]
fn sample_reports_are_recognised_by_their_ids() {
    let rd = parsed();
    let pen = sample_pen().to_bytes();
    let found = rd.find_input_report(&pen).expect("pen report recognised");
    assert_eq!(found.size_in_bytes(), pen.len());
    let config = encode(&Message::Config(sample_config()));
    assert_eq!(
        rd.find_feature_report(&config)
            .expect("config recognised")
            .size_in_bytes(),
        config.len()
    );
}
