//! `penctl` as a user runs it: the real binary, its stdout, stderr and exit status.

use std::process::{Command, Output};

use pen_protocol::{PenReport, Position, Quality, REPORT_DESCRIPTOR};

fn penctl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penctl"))
        .args(args)
        .output()
        .expect("penctl runs")
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn descriptor_is_one_line_of_hex() {
    let out = penctl(&["descriptor"]);
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8(out.stdout).expect("utf-8"),
        hex(&REPORT_DESCRIPTOR) + "\n"
    );
}

#[test]
fn decode_prints_the_report_as_json() {
    let report = PenReport {
        sw1: false,
        sw2: true,
        sw3: false,
        in_range: true,
        display_frame: false,
        position: Position { x: -15, y: 2500, z: 7 },
        seq: 65535,
        timestamp_us: 4_000_000_000,
        quality: Quality {
            receivers_used: 4,
            residual: 3,
            dop: 21,
        },
    };
    let out = penctl(&["decode", &hex(&report.to_bytes())]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["report_id"], 1);
    assert_eq!(
        (v["sw1"].as_bool(), v["sw2"].as_bool(), v["sw3"].as_bool()),
        (Some(false), Some(true), Some(false))
    );
    assert_eq!(v["in_range"], true);
    assert_eq!(
        (v["x_mm"].as_f64(), v["y_mm"].as_f64(), v["z_mm"].as_f64()),
        (Some(-1.5), Some(250.0), Some(0.7))
    );
    assert_eq!(v["seq"], 65535);
    assert_eq!(v["timestamp_us"], 4_000_000_000u64);
    assert_eq!(v["quality"]["receivers_used"], 4);
    assert_eq!(v["quality"]["residual_mm"].as_f64(), Some(0.3));
    assert_eq!(v["quality"]["dop"].as_f64(), Some(2.1));
    assert_eq!(
        out.stdout.iter().filter(|&&b| b == b'\n').count(),
        1,
        "exactly one line"
    );
}

#[test]
fn decode_accepts_spaced_hex_and_frames() {
    let spaced = penctl(&["decode", "01 0d d2 04 c9 fd 7a 03", "34 12 04 03 02 01 05 07 12"]);
    assert!(spaced.status.success());
    let framed = penctl(&["decode", "--frame", "0016010dd204c9fd7a033412040302010507122a520ac600"]);
    assert!(framed.status.success());
    assert_eq!(spaced.stdout, framed.stdout);
}

#[test]
fn invalid_input_fails_with_a_reason_on_stderr() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["decode", "010dd204c9fd7a0334120403020105"],
            "truncated pen report: 15 bytes, expected 17",
        ),
        (
            &["decode", "010dd204c9fd7a033412040302010507120000"],
            "oversized pen report: 19 bytes, expected 17",
        ),
        (&["decode", "090102"], "unknown report ID 0x09"),
        (&["decode", "01zz"], "'z' at position 2 is not a hex digit"),
        (
            &["decode", "01fdd204c9fd7a03341204030201050712"],
            "reserved bits 0xe0 set in byte 1",
        ),
        (
            &["decode", "--frame", "0016010dd204c9fd7a033412040302010507122a520ac700"],
            "frame CRC mismatch",
        ),
    ];
    for (args, reason) in cases {
        let out = penctl(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("penctl: ") && err.contains(reason), "{args:?}: {err}");
    }
}

#[test]
fn help_and_usage_errors() {
    let help = penctl(&["--help"]);
    assert!(help.status.success());
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("descriptor") && text.contains("decode"));
    assert_eq!(penctl(&["decode"]).status.code(), Some(2));
    assert_eq!(penctl(&["no-such-command"]).status.code(), Some(2));
}
