//! The report descriptor, parsed by an independent parser (hidreport, from the hid-tools
//! maintainers), against the report codecs: every field's offset and size, every report's length;
//! and the OS's pen collection read as an OS pen stack reads it.

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
    assert_eq!(inputs.len(), 4);
    assert_eq!(features.len(), 5);
    assert!(rd.output_reports().is_empty());
    assert_eq!(len(&inputs, ReportId::Pen), PenReport::LEN);
    assert_eq!(len(&inputs, ReportId::Tof), TofReport::LEN);
    assert_eq!(len(&inputs, ReportId::OsPen), OsPenReport::LEN);
    assert_eq!(len(&inputs, ReportId::Head), HeadReport::LEN);
    assert_eq!(len(&features, ReportId::DeviceInfo), DeviceInfo::LEN);
    assert_eq!(len(&features, ReportId::Config), Config::LEN);
    assert_eq!(len(&features, ReportId::Status), Status::LEN);
    assert_eq!(len(&features, ReportId::ResetRecord), ResetRecord::LEN);
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
            (PAGE_VENDOR, VENDOR_SW1),
            (PAGE_VENDOR, VENDOR_SW2),
            (PAGE_VENDOR, VENDOR_SW3),
            (PAGE_VENDOR, VENDOR_IN_RANGE),
            (PAGE_VENDOR, VENDOR_DISPLAY_FRAME),
            (PAGE_VENDOR, VENDOR_X),
            (PAGE_VENDOR, VENDOR_Y),
            (PAGE_VENDOR, VENDOR_Z),
            (PAGE_VENDOR, VENDOR_SEQUENCE),
            (PAGE_VENDOR, VENDOR_TIMESTAMP),
            (PAGE_VENDOR, VENDOR_RECEIVERS_USED),
            (PAGE_VENDOR, VENDOR_RESIDUAL),
            (PAGE_VENDOR, VENDOR_DOP),
        ]
    );
    // The project's own report sits in the vendor application collection, with vendor usages
    // only (see below why both).
    let app = &fields[0].collections[0];
    assert_eq!(app.usages()[0].usage_page, 0xFF00.into());
    assert_eq!(app.usages()[0].usage_id, 0x01.into());
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

/// Linux's hid-input maps an input field by its usage whatever collection holds it: a Digitizer
/// or Generic Desktop usage in the vendor collection made a second pen device of the 3D report
/// on a real kernel (hil-tests/kernel). Every report but the OS pen's must carry vendor usages
/// only — fields and collections alike — so that the OS makes exactly one pen.
#[test]
fn only_the_os_pen_report_carries_usages_an_os_binds() {
    let rd = parsed();
    let mut checked = 0;
    let reports = rd
        .input_reports()
        .iter()
        .map(|r| r as &dyn HidReport)
        .chain(rd.feature_reports().iter().map(|r| r as &dyn HidReport));
    for r in reports {
        let id = r.report_id().map(u8::from).expect("every report has an ID");
        for f in r.fields() {
            let (usages, collections): (Vec<_>, _) = match f {
                Field::Variable(v) => (vec![v.usage], &v.collections),
                Field::Array(a) => (a.usages().to_vec(), &a.collections),
                Field::Constant(_) => continue,
            };
            let pages: Vec<u16> = usages
                .iter()
                .map(|u| u16::from(u.usage_page))
                .chain(
                    collections
                        .iter()
                        .flat_map(|c| c.usages().iter().map(|u| u16::from(u.usage_page))),
                )
                .collect();
            if id == ReportId::OsPen as u8 {
                assert!(pages.iter().all(|&p| p != usage::PAGE_VENDOR), "{pages:x?}");
            } else {
                assert!(
                    pages.iter().all(|&p| p >= usage::PAGE_VENDOR),
                    "report {id:#04x} has a usage on a page an OS binds: {pages:x?}"
                );
            }
            checked += 1;
        }
    }
    // 6 OS pen fields, 13 pen fields, a field per body byte of the other reports.
    let bytes = [
        TofReport::LEN,
        HeadReport::LEN,
        DeviceInfo::LEN,
        Config::LEN,
        Status::LEN,
        Command::LEN,
        ResetRecord::LEN,
    ];
    assert_eq!(checked, 6 + 13 + bytes.iter().map(|l| l - 1).sum::<usize>());
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
            ReportId::ResetRecord => ResetRecord::LEN,
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

/// The OS pen report's fields as a parsed descriptor declares them.
fn os_fields(rd: &ReportDescriptor) -> Vec<VariableField> {
    let report = rd
        .input_reports()
        .iter()
        .find(|r| r.report_id().map(u8::from) == Some(ReportId::OsPen as u8))
        .expect("OS pen input report");
    report
        .fields()
        .iter()
        .filter_map(|f| match f {
            Field::Variable(v) => Some(v.clone()),
            _ => None,
        })
        .collect()
}

#[test]
fn the_os_pen_collection_spans_the_calibrated_display() {
    use usage::*;
    // A 600 × 340 mm display, as a calibration writes it.
    let extent = os_extent([600.0, 340.0]).expect("a valid size");
    assert_eq!(extent, [6000, 3400]);
    let descriptor = report_descriptor(Some(extent));
    assert_eq!(descriptor.bytes().len(), REPORT_DESCRIPTOR_LEN);
    let rd = ReportDescriptor::try_from(descriptor.bytes()).expect("parses");
    let fields = os_fields(&rd);
    let usages: Vec<(u16, u16)> = fields.iter().map(usage_of).collect();
    assert_eq!(
        usages,
        [
            (PAGE_DIGITIZER, TIP_SWITCH),
            (PAGE_DIGITIZER, BARREL_SWITCH),
            (PAGE_DIGITIZER, SECONDARY_BARREL_SWITCH),
            (PAGE_DIGITIZER, IN_RANGE),
            (PAGE_GENERIC_DESKTOP, X),
            (PAGE_GENERIC_DESKTOP, Y),
        ]
    );
    // The Digitizer / Pen application collection holds it, and only it.
    let app = &fields[0].collections[0];
    assert_eq!(
        (app.usages()[0].usage_page, app.usages()[0].usage_id),
        (0x0D.into(), 0x02.into())
    );
    let in_pen_collection = rd
        .input_reports()
        .iter()
        .flat_map(|r| r.fields())
        .filter_map(|f| match f {
            Field::Variable(v) => Some(v),
            _ => None,
        })
        .filter(|v| {
            v.collections
                .first()
                .is_some_and(|c| c.usages()[0].usage_page == 0x0D.into())
        })
        .count();
    assert_eq!(in_pen_collection, 6);
    // X and Y: 0…W and 0…H in 0.1 mm, physical the same, unsigned.
    for (axis, max) in [(&fields[4], 6000), (&fields[5], 3400)] {
        assert_eq!(i32::from(axis.logical_minimum), 0);
        assert_eq!(i32::from(axis.logical_maximum), max);
        assert_eq!(axis.physical_minimum.map(i32::from), Some(0));
        assert_eq!(axis.physical_maximum.map(i32::from), Some(max));
        assert_eq!(axis.unit.map(u32::from), Some(0x11));
        assert_eq!(axis.unit_exponent.map(|e| e.exponent()), Some(-2));
        assert!(!axis.is_signed());
    }
    // Every valid display size gives the same length; an unknown one the placeholder.
    for size in [[50.0, 50.0], [3276.7, 3276.7], [1200.0, 675.0]] {
        let d = report_descriptor(os_extent(size));
        assert_eq!(d.bytes().len(), REPORT_DESCRIPTOR_LEN, "{size:?}");
    }
    assert_eq!(os_extent([0.0, 0.0]), None);
    assert_eq!(os_extent([f32::NAN, 340.0]), None);
    assert_eq!(report_descriptor(None).bytes(), &REPORT_DESCRIPTOR[..]);
}

/// What an OS pen stack makes of a report, read as libinput does from the evdev device the
/// kernel builds from the descriptor: the axis's absinfo (minimum, maximum, resolution in units
/// per mm from the physical range and unit) and the value; the pointer's place on a screen is
/// (value − min) / (max − min) of the screen's width or height.
struct Axis {
    min: i32,
    max: i32,
    units_per_mm: f64,
}

impl Axis {
    fn from_field(f: &VariableField) -> Axis {
        let (min, max) = (i32::from(f.logical_minimum), i32::from(f.logical_maximum));
        let physical = (
            f.physical_minimum.map(i32::from).unwrap_or(min),
            f.physical_maximum.map(i32::from).unwrap_or(max),
        );
        // The kernel's hidinput_calc_abs_res: centimetres with the exponent, to units per mm.
        assert_eq!(f.unit.map(u32::from), Some(0x11), "centimetres");
        let exponent = f.unit_exponent.map(|e| e.exponent()).unwrap_or(0);
        let physical_mm = (physical.1 - physical.0) as f64 * 10f64.powi(exponent as i32) * 10.0;
        Axis {
            min,
            max,
            units_per_mm: (max - min) as f64 / physical_mm,
        }
    }

    /// Where `raw` puts the pointer across a screen `pixels` wide.
    fn screen(&self, raw: u64, pixels: f64) -> f64 {
        (raw as f64 - self.min as f64) / (self.max - self.min) as f64 * pixels
    }
}

#[test]
fn the_os_reads_the_pen_where_it_is_on_the_display() {
    let extent = os_extent([600.0, 340.0]).expect("valid");
    let rd = ReportDescriptor::try_from(report_descriptor(Some(extent)).bytes()).expect("parses");
    let fields = os_fields(&rd);
    let (x, y) = (Axis::from_field(&fields[4]), Axis::from_field(&fields[5]));
    // libinput's tablet size is (max − min) / resolution: the display's own millimetres.
    assert!(((x.max - x.min) as f64 / x.units_per_mm - 600.0).abs() < 1e-9);
    assert!(((y.max - y.min) as f64 / y.units_per_mm - 340.0).abs() < 1e-9);
    // A pen at (150 mm, 85 mm) from the display's top-left corner, tip down: a quarter of the
    // way across and down a 1920 × 1080 screen, tip and proximity both set.
    let report = OsPenReport {
        tip: true,
        barrel: false,
        secondary_barrel: false,
        in_range: true,
        x: 1500,
        y: 850,
    };
    let mut bytes = [0u8; OsPenReport::LEN];
    report.encode(&mut bytes).expect("fits");
    let found = rd.find_input_report(&bytes).expect("recognised by its ID");
    assert_eq!(found.size_in_bytes(), OsPenReport::LEN);
    let value = |f: &VariableField| u32::from(&f.extract(&bytes).expect("extract")) as u64;
    assert_eq!(value(&fields[0]), 1, "BTN_TOUCH");
    assert_eq!(value(&fields[3]), 1, "BTN_TOOL_PEN (in range)");
    assert!((x.screen(value(&fields[4]), 1920.0) - 480.0).abs() < 1e-9);
    assert!((y.screen(value(&fields[5]), 1080.0) - 270.0).abs() < 1e-9);
}

/// hid-tools (the Linux HID maintainers' Python tools: `pip install hid-tools`) parses the
/// descriptor a calibrated device presents and decodes an OS pen report with it, as
/// `hid-decode` and `hid-recorder` do. Skipped, with a message, where Python or hid-tools is
/// missing.
#[test]
fn hid_tools_parses_the_descriptor_and_decodes_the_os_pen() {
    const SCRIPT: &str = r#"
import sys
from hidtools.hid import ReportDescriptor
rdesc_hex, report_hex = sys.stdin.read().split()
rd = ReportDescriptor.from_bytes(bytes.fromhex(rdesc_hex))
report = bytes.fromhex(report_hex)
r = rd.get(report[0], len(report))
for f in r.fields:
    print("field", f.usage_name, f.logical_min, f.logical_max, f.physical_min, f.physical_max, f.unit, f.unit_exp)
print("decoded", rd.format_report(report))
"#;
    let extent = os_extent([600.0, 340.0]).expect("valid");
    let descriptor = report_descriptor(Some(extent));
    let report = OsPenReport {
        tip: true,
        barrel: false,
        secondary_barrel: true,
        in_range: true,
        x: 1500,
        y: 850,
    };
    let mut bytes = [0u8; OsPenReport::LEN];
    report.encode(&mut bytes).expect("fits");
    let hex = |b: &[u8]| b.iter().map(|b| format!("{b:02x}")).collect::<String>();
    let child = std::process::Command::new("python3")
        .args(["-c", SCRIPT])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn();
    let Ok(mut child) = child else {
        eprintln!("skipped: no python3 (hid-tools runs on it)");
        return;
    };
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().expect("piped");
        write!(stdin, "{} {}", hex(descriptor.bytes()), hex(&bytes)).expect("write");
    }
    let out = child.wait_with_output().expect("python3 ran");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if stderr.contains("No module named 'hidtools'") {
        eprintln!("skipped: hid-tools is not installed (pip install hid-tools)");
        return;
    }
    assert!(out.status.success(), "hid-tools failed: {stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let fields: Vec<&str> = stdout.lines().filter_map(|l| l.strip_prefix("field ")).collect();
    // Usage, logical min and max, physical min and max, unit (0x11: cm), unit exponent.
    assert_eq!(
        fields,
        [
            "Tip Switch 0 1 0 0 0 0",
            "Barrel Switch 0 1 0 0 0 0",
            "Secondary Barrel Switch 0 1 0 0 0 0",
            "In Range 0 1 0 0 0 0",
            "Undefined 0 1 0 0 0 0",
            "X 0 6000 0 6000 17 -2",
            "Y 0 3400 0 3400 17 -2",
        ],
        "{stdout}"
    );
    let decoded = stdout
        .lines()
        .find_map(|l| l.strip_prefix("decoded "))
        .expect("a decoded line");
    let words: String = decoded.split_whitespace().collect::<Vec<_>>().join(" ");
    assert_eq!(
        words,
        "ReportID: 7 / Tip Switch: 1 | Barrel Switch: 0 | Secondary Barrel Switch: 1 | In Range: 1 | # | X: 1500 | Y: 850"
    );
}
