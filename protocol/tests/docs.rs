//! docs/protocol.md's generated sections match the code. Run with `PEN_UPDATE_DOCS=1` to rewrite
//! them after a deliberate protocol change.

use crate::common;

use crate::common::splice::splice;
use common::*;
use hidreport::{Field, Report as HidReport, ReportDescriptor, VariableField};
use pen_protocol::*;
use std::fmt::Write;

const DOC: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/protocol.md");

fn usage_name(page: u16, id: u16) -> String {
    use usage::*;
    let name = match (page, id) {
        (PAGE_DIGITIZER, TIP_SWITCH) => "Tip Switch (SW1)",
        (PAGE_DIGITIZER, BARREL_SWITCH) => "Barrel Switch (SW2)",
        (PAGE_DIGITIZER, SECONDARY_BARREL_SWITCH) => "Secondary Barrel Switch (SW3)",
        (PAGE_DIGITIZER, IN_RANGE) => "In Range",
        (PAGE_GENERIC_DESKTOP, X) => "X",
        (PAGE_GENERIC_DESKTOP, Y) => "Y",
        (PAGE_GENERIC_DESKTOP, Z) => "Z",
        (PAGE_VENDOR, VENDOR_SW1) => "vendor: SW1 (tip)",
        (PAGE_VENDOR, VENDOR_SW2) => "vendor: SW2 (barrel)",
        (PAGE_VENDOR, VENDOR_SW3) => "vendor: SW3 (second barrel)",
        (PAGE_VENDOR, VENDOR_IN_RANGE) => "vendor: in range",
        (PAGE_VENDOR, VENDOR_X) => "vendor: X",
        (PAGE_VENDOR, VENDOR_Y) => "vendor: Y",
        (PAGE_VENDOR, VENDOR_Z) => "vendor: Z",
        (PAGE_VENDOR, VENDOR_DISPLAY_FRAME) => "vendor: display frame",
        (PAGE_VENDOR, VENDOR_SEQUENCE) => "vendor: sequence number",
        (PAGE_VENDOR, VENDOR_TIMESTAMP) => "vendor: timestamp",
        (PAGE_VENDOR, VENDOR_RECEIVERS_USED) => "vendor: receivers used",
        (PAGE_VENDOR, VENDOR_RESIDUAL) => "vendor: residual",
        (PAGE_VENDOR, VENDOR_DOP) => "vendor: DOP",
        (PAGE_VENDOR, id) if id > VENDOR_REPORT_BASE => "vendor: report bytes",
        _ => "?",
    };
    format!("{name} `{page:#06x}:{id:#04x}`")
}

fn unit_text(f: &VariableField) -> String {
    match (
        f.unit.map(u32::from).unwrap_or(0),
        f.unit_exponent.map(|e| e.exponent()).unwrap_or(0),
    ) {
        (0, _) => "–".into(),
        (0x11, e) => format!("cm (10^{e})"),
        (0x1001, e) => format!("s (10^{e})"),
        (u, e) => format!("{u:#x} (10^{e})"),
    }
}

fn physical_text(f: &VariableField) -> String {
    match (f.physical_minimum.map(i32::from), f.physical_maximum.map(i32::from)) {
        (None, None) | (Some(0), Some(0)) => "= logical".into(),
        (lo, hi) => format!("{}…{}", lo.unwrap_or(0), hi.unwrap_or(0)),
    }
}

/// The descriptor as a table, one row per field; runs of identical byte fields collapse to one.
fn descriptor_table() -> String {
    let rd = ReportDescriptor::try_from(&REPORT_DESCRIPTOR[..]).expect("parses");
    let mut out = String::new();
    let mut rows = |kind: &str, reports: Vec<&dyn HidReport>| {
        for r in reports {
            let id = r.report_id().map(u8::from).expect("every report has an ID");
            let name = ReportId::from_u8(id).map(ReportId::name).unwrap_or("?");
            let fields = r.fields();
            let mut i = 0;
            while i < fields.len() {
                match &fields[i] {
                    Field::Constant(c) => {
                        let _ = writeln!(
                            out,
                            "| `{id:#04x}` {name} | {kind} | {}–{} | 1 × {} | padding (constant 0) | | | |",
                            c.bits.start,
                            c.bits.end - 1,
                            c.bits.len()
                        );
                        i += 1;
                    }
                    Field::Variable(v) => {
                        let same = |f: &Field| match f {
                            Field::Variable(w) => {
                                w.usage == v.usage
                                    && w.bits.len() == v.bits.len()
                                    && w.usage.usage_page == 0xFF00.into()
                            }
                            _ => false,
                        };
                        let mut n = 1;
                        while i + n < fields.len() && same(&fields[i + n]) && v.bits.len() == 8 {
                            n += 1;
                        }
                        let end = v.bits.start + n * v.bits.len() - 1;
                        let _ = writeln!(
                            out,
                            "| `{id:#04x}` {name} | {kind} | {}–{end} | {} × {n} | {} | {}…{} | {} | {} |",
                            v.bits.start,
                            v.bits.len(),
                            usage_name(v.usage.usage_page.into(), v.usage.usage_id.into()),
                            i32::from(v.logical_minimum),
                            i32::from(v.logical_maximum),
                            physical_text(v),
                            unit_text(v),
                        );
                        i += n;
                    }
                    Field::Array(_) => panic!("no array fields"),
                }
            }
        }
    };
    rows(
        "Input",
        rd.input_reports().iter().map(|r| r as &dyn HidReport).collect(),
    );
    rows(
        "Feature",
        rd.feature_reports().iter().map(|r| r as &dyn HidReport).collect(),
    );
    out
}

fn hex_lines(bytes: &[u8]) -> String {
    bytes
        .chunks(32)
        .map(|c| c.iter().map(|b| format!("{b:02x}")).collect::<String>() + "\n")
        .collect()
}

#[test]
fn generated_sections_are_current() {
    let doc = std::fs::read_to_string(DOC).expect("docs/protocol.md");
    let table_head = "\n| Report | Kind | Bits | Size × count | Usage | Logical | Physical | Unit (exp) |\n|---|---|---|---|---|---|---|---|\n";
    let mut frame = [0u8; MAX_FRAME];
    let pen = sample_pen().to_bytes();
    let n = encode_frame(&pen, &mut frame).expect("fits");
    let example = format!(
        "\n```text\nreport {}frame  {}```\n",
        hex_lines(&pen),
        hex_lines(&frame[..n])
    );
    let mut fresh = splice(&doc, "descriptor-table", &format!("{table_head}{}", descriptor_table()));
    fresh = splice(&fresh, "descriptor-len", &REPORT_DESCRIPTOR_LEN.to_string());
    fresh = splice(
        &fresh,
        "descriptor-hex",
        &format!("\n```text\n{}```\n", hex_lines(&REPORT_DESCRIPTOR)),
    );
    fresh = splice(&fresh, "frame-example", &example);
    if fresh != doc {
        if std::env::var_os("PEN_UPDATE_DOCS").is_some() {
            std::fs::write(DOC, &fresh).expect("write docs/protocol.md");
        } else {
            panic!("docs/protocol.md is stale: run `PEN_UPDATE_DOCS=1 cargo test -p pen-protocol --test docs`");
        }
    }
}
