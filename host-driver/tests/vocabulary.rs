//! One vocabulary across the tools (issue 19.4, docs/cli.md): `--source` and `--speed` for pend
//! and penctl, the simulated pen's scenario per tool, the earlier spellings still read, and
//! what does not go together refused as a usage error (2).

use std::process::{Command, Output};

use crate::penctl::penctl_in;

fn penctl(args: &[&str]) -> Output {
    penctl_in(tempfile::tempdir().expect("home").path(), args)
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The `device` line of `penctl info`.
fn device(args: &[&str]) -> String {
    let out = penctl(&[&["info"], args].concat());
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    stdout(&out)
        .lines()
        .find_map(|l| l.strip_prefix("device").map(|d| d.trim().to_string()))
        .unwrap_or_default()
}

#[test]
fn the_simulated_pen_is_source_sim_and_the_earlier_spellings_still_work() {
    // penctl's simulated pen holds still: steady figures for info, monitor and config.
    assert_eq!(device(&["--source", "sim"]), "sim hold");
    assert_eq!(device(&["--source", "sim:modeling-session"]), "sim modeling-session");
    assert_eq!(device(&["--source", "sim", "--speed", "0"]), "sim hold");
    // Hidden, still read.
    assert_eq!(device(&["--sim"]), "sim hold");
    assert_eq!(
        device(&["--sim", "--scenario", "modeling-session"]),
        "sim modeling-session"
    );
    assert_eq!(device(&["--sim", "--sim-speed", "0"]), "sim hold");
}

#[test]
fn the_help_shows_one_spelling() {
    let out = penctl(&["info", "--help"]);
    let help = stdout(&out);
    assert!(
        help.contains("--source <SOURCE>") && help.contains("--speed <X>"),
        "{help}"
    );
    assert!(
        help.contains("sim (playing `hold`"),
        "each tool says what its sim plays: {help}"
    );
    for old in ["--serial", "--hid", "--sim ", "--sim-speed", "--scenario"] {
        assert!(!help.contains(old), "{old} in:\n{help}");
    }
    let out = Command::new(env!("CARGO_BIN_EXE_pend"))
        .arg("--help")
        .output()
        .expect("pend runs");
    let help = stdout(&out);
    assert!(
        help.contains("--source <SOURCE>") && help.contains("--speed <X>"),
        "{help}"
    );
    assert!(help.contains("plays `modeling-session` here"), "{help}");
    assert!(help.contains("sim (playing `modeling-session`"), "{help}");
    for old in ["--serial", "--hid", "--sim ", "--sim-speed"] {
        assert!(!help.contains(old), "{old} in:\n{help}");
    }
}

#[test]
fn what_does_not_go_together_is_a_usage_error() {
    let cases: [(&[&str], &str); 6] = [
        (&["info", "--source", "bogus"], "unknown source \"bogus\""),
        (&["info", "--source", "sim:nope"], "unknown scenario \"nope\""),
        (
            &["info", "--source", "hid", "--serial", "/dev/x"],
            "cannot be used with",
        ),
        (&["info", "--source", "sim", "--speed", "-1"], "is not a speed"),
        (
            &["info", "--source", "serial:/dev/x", "--speed", "2"],
            "--speed is the simulated pen's",
        ),
        (&["info", "--sim", "--scenario", "nope"], "unknown scenario \"nope\""),
    ];
    for (args, says) in cases {
        let out = penctl(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    let dir = tempfile::tempdir().expect("dir");
    let out = Command::new(env!("CARGO_BIN_EXE_pend"))
        .args(["--source", "hid", "--speed", "2", "--socket"])
        .arg(dir.path().join("pend.sock"))
        .env("HOME", dir.path())
        .output()
        .expect("pend runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--speed is the simulated pen's (--source sim); hid runs in real time"),
        "{err}"
    );
}

#[test]
fn calibrate_saves_to_calibration_file_and_reads_the_earlier_out() {
    let home = tempfile::tempdir().expect("home");
    for flag in ["--calibration", "--out"] {
        let file = home.path().join(format!("{}.toml", flag.trim_start_matches('-')));
        let out = penctl_in(
            home.path(),
            &[
                "calibrate",
                "--source",
                "sim",
                "--speed",
                "0",
                "--targets",
                "4",
                flag,
                file.to_str().expect("UTF-8"),
            ],
        );
        assert!(out.status.success(), "{flag}: {}", stderr(&out));
        assert!(file.exists(), "{flag}: {} not written", file.display());
    }
}
