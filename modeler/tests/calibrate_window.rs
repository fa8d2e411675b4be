//! Issue 42: `penmodel calibrate` in a real window (Xvfb), the simulated pen touching the
//! targets: a screenshot shows a target and the progress bar while it goes, then the residual
//! plot; a key saves the calibration, which the file then holds. Skipped without Xvfb, xdotool
//! and xwd unless `PEN_REQUIRE_X` is set, as `mouse_window` is.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::mouse_window::{Killed, Shot, x_tools, xvfb};

/// A hang guard only.
const GUARD: Duration = Duration::from_secs(90);

/// The window's colours for a target, a taken target and a residual (`calibrate.rs`).
const TARGET: u32 = 0xffd640;
const DONE: u32 = 0x5ac86e;
const RESIDUAL: u32 = 0xf05a50;

fn screenshot(display: &str, window: &str) -> Option<Shot> {
    let out = Command::new("xwd")
        .args(["-silent", "-id", window])
        .env("DISPLAY", display)
        .output()
        .ok()?;
    out.status.success().then(|| Shot::from_xwd(&out.stdout))
}

fn count(shot: &Shot, colour: u32) -> usize {
    shot.pixels.iter().filter(|p| **p == colour).count()
}

/// Starts `penmodel calibrate` with the simulated pen at `speed` in a window on `display`,
/// saving to `file`, and waits for its window: the process and the window's id.
fn start(dir: &std::path::Path, display: &str, file: &std::path::Path, args: &[&str]) -> (Killed, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir)
        .args(["calibrate", "--source", "sim"])
        .args(args)
        .args(["--show", "window", "--windowed", "--calibration"])
        .arg(file)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .env("HOME", dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("penmodel starts");
    let mut penmodel = Killed(child);
    let until = Instant::now() + GUARD;
    let window = loop {
        let out = Command::new("xdotool")
            .args(["search", "--onlyvisible", "--name", "^penmodel calibrate$"])
            .env("DISPLAY", display)
            .output()
            .expect("xdotool runs");
        if let Some(w) = String::from_utf8_lossy(&out.stdout).lines().next() {
            break w.to_string();
        }
        if let Some(status) = penmodel.0.try_wait().expect("wait") {
            let mut err = String::new();
            if let Some(mut e) = penmodel.0.stderr.take() {
                std::io::Read::read_to_string(&mut e, &mut err).expect("stderr");
            }
            panic!("penmodel calibrate ended before its window showed: {status:?}: {err}");
        }
        assert!(Instant::now() < until, "no calibration window");
        std::thread::sleep(Duration::from_millis(100));
    };
    (penmodel, window)
}

/// Presses `key` in `window` and waits at most `within` for penmodel to end (`late` if not).
fn press(
    display: &str,
    window: &str,
    key: &str,
    penmodel: &mut Killed,
    within: Duration,
    late: &str,
) -> std::process::ExitStatus {
    let pressed = Command::new("xdotool")
        .args(["windowfocus", "--sync", window, "key", key])
        .env("DISPLAY", display)
        .status()
        .expect("xdotool runs");
    assert!(pressed.success());
    let end = Instant::now() + within;
    loop {
        if let Some(s) = penmodel.0.try_wait().expect("wait") {
            return s;
        }
        assert!(Instant::now() < end, "{late}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn penmodel_calibrate_draws_the_targets_then_the_residual_plot() {
    if !x_tools() {
        return;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("calibration.toml");
    let (_server, display) = xvfb();
    let (mut penmodel, window) = start(dir.path(), &display, &file, &["--speed", "3", "--targets", "4"]);
    let until = Instant::now() + GUARD;
    // While it goes: a target (yellow) and, once one is taken, the progress (green); at the end
    // the plot, whose residuals are red. Nothing is saved before the plot is closed.
    let (mut saw_target, mut saw_progress) = (false, false);
    let plot = loop {
        assert!(
            Instant::now() < until,
            "no residual plot (target {saw_target}, progress {saw_progress})"
        );
        if let Some(shot) = screenshot(&display, &window) {
            saw_target |= count(&shot, TARGET) > 50;
            saw_progress |= count(&shot, DONE) > 50;
            if count(&shot, RESIDUAL) > 50 {
                break shot;
            }
        }
        std::thread::sleep(Duration::from_millis(150));
    };
    assert!(
        saw_target && saw_progress,
        "target {saw_target}, progress {saw_progress}"
    );
    assert!(!file.exists(), "saved only when the plot is closed");
    // The plot's four targets are rings, its axes and legend are drawn (light text on panels).
    assert!(count(&plot, TARGET) > 4 * 20, "the targets' rings");
    assert!(
        plot.pixels.iter().filter(|p| **p == 0xffffff).count() > 500,
        "the axes' labels and the legend"
    );
    let status = press(
        &display,
        &window,
        "q",
        &mut penmodel,
        GUARD,
        "penmodel calibrate did not end at the key",
    );
    let mut out = String::new();
    if let Some(mut o) = penmodel.0.stdout.take() {
        std::io::Read::read_to_string(&mut o, &mut out).expect("stdout");
    }
    assert!(status.success(), "{status:?}: {out}");
    assert!(out.contains("calibrated over 4 targets"), "{out}");
    let saved = std::fs::read_to_string(&file).expect("the calibration saved");
    assert!(saved.contains("[transform]") && saved.contains("unique_id"), "{saved}");
}

/// Without a display the terminal prompts, in `penctl calibrate`'s words, and the calibration
/// is saved where asked (the simulated pen's never over the real device's default file).
#[test]
fn penmodel_calibrate_headless_prompts_at_the_terminal() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("cal.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .args([
            "calibrate",
            "--source",
            "sim",
            "--speed",
            "0",
            "--targets",
            "5",
            "--show",
            "headless",
        ])
        .arg("--calibration")
        .arg(&file)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("HOME", dir.path())
        .output()
        .expect("penmodel runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    for n in 1..=5 {
        assert!(err.contains(&format!("target {n}/5: touch (")), "{err}");
    }
    assert!(err.contains("pivot: hold the tip on (300, 170) mm"), "{err}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("calibrated over 5 targets"));
    assert!(file.exists());
    assert!(!dir.path().join(".config/penscape/calibration.toml").exists());
}

/// Esc before the plot ends at once without saving (exit 1), though the procedure still waits
/// for a touch.
#[test]
fn escape_before_the_plot_saves_nothing() {
    if !x_tools() {
        return;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("calibration.toml");
    let (_server, display) = xvfb();
    let (mut penmodel, window) = start(dir.path(), &display, &file, &["--speed", "0.2"]);
    let status = press(
        &display,
        &window,
        "Escape",
        &mut penmodel,
        Duration::from_secs(20),
        "Esc did not end penmodel calibrate at once",
    );
    let mut err = String::new();
    if let Some(mut e) = penmodel.0.stderr.take() {
        std::io::Read::read_to_string(&mut e, &mut err).expect("stderr");
    }
    assert_eq!(status.code(), Some(1), "{err}");
    assert!(err.contains("nothing saved"), "{err}");
    assert!(!file.exists());
}

/// As in pend and penctl, a source that does not read and `--speed` with a real device are
/// usage errors (2), before anything is opened.
#[test]
fn penmodel_calibrate_refuses_a_bad_source_or_speed_as_usage_errors() {
    for args in [
        &["calibrate", "--source", "bogus"][..],
        &["calibrate", "--source", "serial:/dev/null", "--speed", "2"][..],
        &["calibrate", "--targets", "7"][..],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("penmodel runs");
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
