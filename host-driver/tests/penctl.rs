//! `penctl` as a user runs it: the real binary, its stdout, stderr and exit status.

use std::path::Path;
use std::process::{Command, Output, Stdio};

use pen_protocol::{PenReport, Position, Quality, REPORT_DESCRIPTOR};

/// A home of its own for every run, so that no test reads or writes the real one's files
/// (`~/.config/penscape/calibration.toml` above all).
fn home() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary home")
}

/// penctl with `HOME` at `home` and no `XDG_CONFIG_HOME`: the configuration under
/// `home/.config`.
pub(crate) fn penctl_in(home: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penctl"))
        .args(args)
        .env("HOME", home)
        .env_remove("XDG_CONFIG_HOME")
        .output()
        .expect("penctl runs")
}

fn penctl(args: &[&str]) -> Output {
    penctl_in(home().path(), args)
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
        (&["decode", "0a0102"], "unknown report ID 0x0a"),
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

#[test]
fn monitor_prints_a_column_header_then_one_row_per_sample() {
    let out = penctl(&["monitor", "--sim", "--sim-speed", "0", "--count", "3"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "a header and 3 rows:\n{text}");
    let header: Vec<&str> = lines[0].split("  ").map(str::trim).filter(|c| !c.is_empty()).collect();
    assert_eq!(
        header,
        [
            "seq", "t s", "range", "x mm", "y mm", "z mm", "switches", "rx", "resid mm", "DOP", "lost"
        ]
    );
    // Each row's fields end where their header does (right-aligned numbers).
    let end = |line: &str, col: &str| line.find(col).map(|i| i + col.len());
    let row = lines[3];
    let fields: Vec<&str> = row.split_whitespace().collect();
    assert_eq!(fields.len(), 13, "{row}");
    assert_eq!(fields[0], "2");
    assert_eq!(row.find(" 2 ").map(|i| i + 2), end(lines[0], "seq"), "{row}");
    assert_eq!(fields[2], "in");
}

#[test]
fn monitor_prints_one_json_object_per_sample() {
    let out = penctl(&["monitor", "--sim", "--sim-speed", "0", "--json", "--count", "5"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON object per line"))
        .collect();
    assert_eq!(lines.len(), 5);
    for (i, v) in lines.iter().enumerate() {
        assert_eq!(v["seq"], i as u64);
        for key in ["x_mm", "y_mm", "z_mm"] {
            assert!(v[key].is_number(), "{key}");
        }
        for key in ["sw1", "sw2", "sw3", "in_range"] {
            assert!(v[key].is_boolean(), "{key}");
        }
        assert!(v["quality"]["receivers_used"].is_number());
    }
    // The pen held still 40 mm above the middle of the display: its emitter is there.
    let last = &lines[4];
    assert_eq!(last["in_range"], true);
    assert!((last["x_mm"].as_f64().unwrap_or(0.0) - 300.0).abs() < 3.0);
}

#[test]
fn config_is_validated_before_it_is_sent() {
    let out = penctl(&[
        "config",
        "set",
        "--sim",
        "receivers_mm=[[0,0,0],[0,0,5],[600,0,0],[0,300,0]]",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("receivers_mm[1] is degenerate"), "{err}");
    let out = penctl(&["config", "set", "--sim", "temperature_c=\"warm\""]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("`temperature_c`: invalid type: string \"warm\", expected f32")
    );
    let ok = penctl(&["config", "set", "--sim", "temperature_c=24.5", "stream_tof=true"]);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let get = penctl(&["config", "get", "--sim", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&get.stdout).expect("JSON");
    assert_eq!(v["receiver_count"], 4);
}

#[test]
fn json_prints_the_devices_f32_numbers_as_their_shortest_decimals() {
    // The simulated base station's delays include 36.2 and 40.1 µs and its filter's beta 0.1,
    // none of which an f32 holds exactly.
    for args in [
        &["config", "get", "--sim", "--json"][..],
        &["info", "--sim", "--json"][..],
    ] {
        let out = penctl(args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains(r#""transducer_delay_us":[38.0,41.5,36.2,40.1]"#) && text.contains(r#""beta":0.1,"#),
            "{args:?}: {text}"
        );
        assert!(!text.contains("0000000"), "{args:?}: f32 noise in {text}");
        // Read back, each is the device's f32 exactly.
        let v: serde_json::Value = serde_json::from_str(&text).expect("JSON");
        let config = if args[0] == "info" { &v["config"] } else { &v };
        let delay = config["transducer_delay_us"][2].as_f64().expect("a number");
        assert_eq!(delay as f32, 36.2f32);
    }
}

#[test]
fn calibrate_with_the_simulated_pen_writes_the_file_and_plot() {
    let tmp = home();
    let dir = tmp.path().join("out");
    let file = dir.join("calibration.toml");
    let png = dir.join("residuals.png");
    let out = penctl(&[
        "calibrate",
        "--sim",
        "--sim-speed",
        "0",
        "--targets",
        "9",
        "--out",
        file.to_str().expect("utf-8"),
        "--plot",
        png.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cal = pen_host::calibration::Calibration::load(&file).expect("a valid calibration file");
    assert_eq!(cal.residuals.len(), 9);
    assert!(cal.rms_mm() <= 0.5, "RMS {:.3} mm", cal.rms_mm());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("RMS") && text.contains("saved"), "{text}");
    assert!(std::fs::metadata(&png).expect("plot written").len() > 1000);
    let too_few = penctl(&["calibrate", "--sim", "--targets", "3"]);
    assert_eq!(too_few.status.code(), Some(2), "fewer than 4 targets is a usage error");
}

#[test]
fn target_counts_other_than_4_5_and_9_are_refused_naming_them() {
    for n in ["3", "6", "7", "8", "10", "seven"] {
        let out = penctl(&["calibrate", "--sim", "--sim-speed", "0", "--targets", n]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--targets {n}: {err}");
        assert!(
            err.contains("4 targets (the corners), 5 (and the centre) or 9 (a 3 × 3 grid)"),
            "{err}"
        );
        assert!(!err.contains("target 1"), "refused before any touch: {err}");
    }
}

#[test]
fn no_device_is_a_clear_error() {
    let out = penctl(&["info", "--serial", "/dev/does-not-exist"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot attach") && err.contains("/dev/does-not-exist"),
        "{err}"
    );
}

/// Nothing attached (as on the test machine, which has no base station): exit status 3, the
/// reason and the hint on stderr, nothing on stdout. With a base station plugged in the test
/// only checks that each line names one.
#[test]
fn list_with_nothing_attached_exits_3() {
    let out = penctl(&["list"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    if stdout.is_empty() {
        assert_eq!(out.status.code(), Some(3), "{out:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("no base station attached"), "{err}");
    } else {
        assert!(out.status.success(), "{out:?}");
        assert!(
            stdout
                .lines()
                .all(|l| l.starts_with("hid ") || l.starts_with("serial ")),
            "{stdout}"
        );
    }
}

/// The real device's calibration as a user has it: the simulated pen must never replace it.
const REAL_CALIBRATION: &str = r#"# a real base station's calibration
version = 2

[device]
unique_id = "0123456789abcdef01234567"

[display]
width_mm = 600.0
height_mm = 340.0
width_px = 2560
height_px = 1440

[transform]
kind = "rigid"
rotation_wxyz = [1.0, 0.0, 0.0, 0.0]
translation_mm = [1.0, 2.0, 3.0]
scale = 1.0
"#;

#[test]
fn calibrating_the_simulated_pen_never_writes_the_real_devices_file() {
    let home = home();
    let config = home.path().join(".config/penscape");
    std::fs::create_dir_all(&config).expect("config folder");
    let real = config.join("calibration.toml");
    std::fs::write(&real, REAL_CALIBRATION).expect("the real calibration");
    let out = penctl_in(
        home.path(),
        &["calibrate", "--sim", "--sim-speed", "0", "--targets", "4"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        std::fs::read_to_string(&real).expect("still there"),
        REAL_CALIBRATION,
        "the real device's calibration is untouched"
    );
    let sim = config.join("calibration-sim.toml");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains(&format!("saved {}", sim.display())), "{stdout}");
    let cal = pen_host::calibration::Calibration::load(&sim).expect("the simulated pen's own file");
    assert_eq!(
        cal.device,
        Some(pen_host::calibration::SIMULATED_ID),
        "it records the device"
    );
    let text = std::fs::read_to_string(&sim).expect("read");
    assert!(
        text.contains("version = 3")
            && text.contains("unique_id = \"70656e73636170652d73696d\"")
            && text.contains("[pen]\ntip_offset_mm"),
        "{text}"
    );

    // XDG_CONFIG_HOME is honoured the same way; with no real calibration, none appears.
    let xdg = self::home();
    let out = Command::new(env!("CARGO_BIN_EXE_penctl"))
        .args(["calibrate", "--sim", "--sim-speed", "0", "--targets", "4"])
        .env("HOME", home.path())
        .env("XDG_CONFIG_HOME", xdg.path())
        .output()
        .expect("penctl runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(xdg.path().join("penscape/calibration-sim.toml").exists());
    assert!(!xdg.path().join("penscape/calibration.toml").exists());

    // penctl info says whether the device has a calibration of its own.
    let info = penctl_in(home.path(), &["info", "--sim"]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        text.contains(&format!("calibration  {}: this base station's", sim.display())),
        "{text}"
    );
}

#[test]
fn another_devices_calibration_is_refused_by_pend_saying_what_to_do() {
    let home = home();
    let config = home.path().join(".config/penscape");
    std::fs::create_dir_all(&config).expect("config folder");
    // The simulated pen's default calibration belongs to another base station.
    let sim = config.join("calibration-sim.toml");
    std::fs::write(&sim, REAL_CALIBRATION).expect("write");
    let info = penctl_in(home.path(), &["info", "--sim", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).expect("JSON");
    assert_eq!(v["calibration"]["applies"], false, "{v}");
    assert_eq!(v["calibration"]["device"], "0123456789abcdef01234567");

    let socket = home.path().join("pend.sock");
    let mut pend = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--sim", "--sim-speed", "0", "--socket"])
        .arg(&socket)
        .env("HOME", home.path())
        .env_remove("XDG_CONFIG_HOME")
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("pend starts");
    let stderr = pend.stderr.take().expect("piped");
    // Read pend's log on a thread so that a pend that never says it cannot hang the test.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut log = Vec::new();
    let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while std::time::Instant::now() < end && !log.iter().any(|l: &String| l.contains("refused")) {
        if let Ok(line) = rx.recv_timeout(std::time::Duration::from_millis(200)) {
            log.push(line);
        }
    }
    let _ = pend.kill();
    let _ = pend.wait();
    let log = log.join("\n");
    assert!(log.contains(&format!("pend: calibration {}", sim.display())), "{log}");
    assert!(
        log.contains("refused: the calibration is for base station 0123456789abcdef01234567, not for the one attached, 70656e73636170652d73696d (the simulated pen)")
            && log.contains("penctl calibrate"),
        "{log}"
    );
    assert!(
        !log.contains("attached sim"),
        "the device is not served with another's calibration: {log}"
    );
}

#[test]
fn a_display_size_out_of_range_is_refused_naming_it() {
    // Not a size at all: a usage error, as clap says it.
    for bad in ["600", "600x", "wide", "600x340x2"] {
        let out = penctl(&["calibrate", "--sim", "--display-mm", bad]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--display-mm {bad}: {err}");
        assert!(err.contains("expected WIDTHxHEIGHT, such as 600x340"), "{err}");
    }
    let out = penctl(&["calibrate", "--sim", "--display-px", "2560"]);
    assert_eq!(out.status.code(), Some(2));

    // A size out of range: a usage error too, naming the flag and the range.
    let out = penctl(&["calibrate", "--sim", "--display-mm", "1e-300x340"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--display-mm: `display.width_mm` must be between 20 and 10000 mm, is 1e-300"),
        "{err}"
    );
    assert!(!err.contains("target 1"), "refused before any touch: {err}");
    let out = penctl(&["calibrate", "--sim", "--display-px", "2560x0"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--display-px: `display.height_px` must be between 16 and 65536 pixels, is 0"),
        "{err}"
    );

    // A file with such a width is refused on load, by pend too, before it serves anything.
    let home = home();
    let file = home.path().join("tiny.toml");
    std::fs::write(&file, REAL_CALIBRATION.replace("width_mm = 600.0", "width_mm = 1e-300")).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--sim", "--socket"])
        .arg(home.path().join("pend.sock"))
        .arg("--calibration")
        .arg(&file)
        .env("HOME", home.path())
        .output()
        .expect("pend runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`display.width_mm` must be between 20 and 10000 mm, is 1e-300"),
        "{err}"
    );
}

#[test]
fn info_shows_the_reset_record() {
    // The simulated base station has run without a panic: its record says so, in words and in
    // JSON (feature report 0x09, protocol 2.2).
    let out = penctl(&["info", "--sim"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("last reset   no panic or fault recorded"), "{text}");
    let out = penctl(&["info", "--sim", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["last_reset"]["report_id"], 9, "{v}");
    assert_eq!(v["last_reset"]["kind"], "None", "{v}");
}

/// Issue 47 item 11: `penctl monitor` on a serial line of pure garbage (a pseudo-terminal
/// written with bytes that never make a frame) warns on stderr with the count dropped; it
/// printed nothing at all.
#[test]
fn monitor_warns_with_a_count_when_the_line_is_garbage() {
    use std::io::{BufRead, BufReader, Write};
    let pty = nix::pty::openpty(None, None).expect("a pseudo-terminal");
    let slave = std::fs::read_link(format!("/proc/self/fd/{}", std::os::fd::AsRawFd::as_raw_fd(&pty.slave)))
        .expect("the terminal's name");
    let mut master = std::fs::File::from(pty.master);
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let writer = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            // Zero bytes end frames, none of which checks out.
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                if master.write_all(b"not a frame at all\0garbage\0").is_err() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
        })
    };
    let mut penctl = Command::new(env!("CARGO_BIN_EXE_penctl"))
        .args(["monitor", "--source"])
        .arg(format!("serial:{}", slave.display()))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("penctl starts");
    let stderr = penctl.stderr.take().expect("stderr");
    let (tx, lines) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let end = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let warning = loop {
        assert!(std::time::Instant::now() < end, "no warning within 60 s");
        match lines.recv_timeout(std::time::Duration::from_millis(200)) {
            Ok(line) if line.contains("dropped") => break line,
            _ => {}
        }
    };
    let _ = penctl.kill();
    let _ = penctl.wait();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    drop(pty.slave);
    let _ = writer.join();
    assert!(warning.starts_with("penctl: warning: "), "{warning}");
    let count: u64 = warning
        .trim_start_matches("penctl: warning: ")
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("a count: {warning}"));
    assert!(count > 0, "{warning}");
}
