//! Issue 42: a user with only a mouse models in a real window. Xvfb gives the X server, xdotool
//! the synthetic input (XTest, as a person's mouse reaches X), and `penmodel open --source
//! mouse` runs unchanged: the test draws a closed region and a point in it, grabs the point,
//! lifts it with the wheel, sets its slope, shows the help (a screenshot with `xwd` finds it
//! over the picture's middle), saves and quits, then reads the document back.
//!
//! Xvfb, xdotool and xwd are installed by `scripts/setup.sh`; without them the test says so and is
//! skipped, unless `PEN_REQUIRE_X` is set (as `scripts/test.sh` sets it), when it fails.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use crate::common::example;

/// A hang guard only: a loaded machine is slow, never this slow.
const GUARD: Duration = Duration::from_secs(90);

/// The example's display and grid: `View::fit` of 600 × 340 mm on 320 m gives 1.0625 mm a
/// metre, the ground centred; the window's picture is 1280 × 720.
const MM_PER_M: f64 = 1.0625;
const PICTURE: (f64, f64) = (1280.0, 720.0);

/// The window pixel over ground point `(x, y)` metres (ground `y` grows down the picture).
fn pixel(x: f64, y: f64) -> (i64, i64) {
    let fx = 0.5 + (x - 160.0) * MM_PER_M / 600.0;
    let fy = 0.5 + (y - 160.0) * MM_PER_M / 340.0;
    ((fx * PICTURE.0).round() as i64, (fy * PICTURE.1).round() as i64)
}

pub(crate) fn found(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Kills a child when the test ends, however it ends.
/// Whether Xvfb, xdotool and xwd are installed; without them a window test is skipped, unless
/// `PEN_REQUIRE_X` is set (scripts/test.sh), where it fails.
pub(crate) fn x_tools() -> bool {
    let missing: Vec<&str> = ["Xvfb", "xdotool", "xwd"].into_iter().filter(|t| !found(t)).collect();
    if missing.is_empty() {
        return true;
    }
    assert!(
        std::env::var_os("PEN_REQUIRE_X").is_none(),
        "{missing:?} not installed (scripts/setup.sh installs them)"
    );
    eprintln!("skipped: {missing:?} not installed (scripts/setup.sh installs them)");
    false
}

pub(crate) struct Killed(pub(crate) Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

struct X {
    display: String,
    window: String,
}

impl X {
    fn xdo(&self, args: &[&str]) -> String {
        let out = Command::new("xdotool")
            .args(args)
            .env("DISPLAY", &self.display)
            .output()
            .expect("xdotool runs");
        assert!(
            out.status.success(),
            "xdotool {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    fn to(&self, (x, y): (f64, f64)) {
        let (px, py) = pixel(x, y);
        self.xdo(&["mousemove", "--window", &self.window, &px.to_string(), &py.to_string()]);
    }

    fn button(&self, what: &str, button: u8) {
        self.xdo(&[what, &button.to_string()]);
    }
}

impl X {
    /// The window's pixels, through `xwd` (x11-apps).
    fn screenshot(&self) -> Shot {
        let out = Command::new("xwd")
            .args(["-silent", "-id", &self.window])
            .env("DISPLAY", &self.display)
            .output()
            .expect("xwd runs");
        assert!(out.status.success(), "xwd: {}", String::from_utf8_lossy(&out.stderr));
        Shot::from_xwd(&out.stdout)
    }
}

/// A screenshot: 0RGB pixels, row after row.
pub(crate) struct Shot {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) pixels: Vec<u32>,
}

impl Shot {
    /// Reads an XWD file (X11's window dump: a header of 25 big-endian words, the window's
    /// name, the colour map, then the image) of a 24- or 32-bit true-colour window.
    pub(crate) fn from_xwd(b: &[u8]) -> Shot {
        let word = |i: usize| u32::from_be_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]]) as usize;
        let (header, width, height) = (word(0), word(4), word(5));
        let (byte_order, bits_per_pixel, bytes_per_line, ncolors) = (word(7), word(11), word(12), word(19));
        assert_eq!(bits_per_pixel, 32, "a 32-bit image");
        let start = header + 12 * ncolors;
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                let p = &b[start + y * bytes_per_line + 4 * x..][..4];
                let v = if byte_order == 0 {
                    u32::from_le_bytes([p[0], p[1], p[2], p[3]])
                } else {
                    u32::from_be_bytes([p[0], p[1], p[2], p[3]])
                };
                pixels.push(v & 0x00ff_ffff);
            }
        }
        Shot { width, height, pixels }
    }

    /// How many pixels differ from `other`'s.
    fn changed(&self, other: &Shot) -> usize {
        self.pixels.iter().zip(&other.pixels).filter(|(a, b)| a != b).count()
    }

    /// The columns and rows (first, last) within which pixels differ from `other`'s.
    fn changed_box(&self, other: &Shot) -> ((usize, usize), (usize, usize)) {
        let (mut x, mut y) = ((usize::MAX, 0), (usize::MAX, 0));
        for (i, _) in self
            .pixels
            .iter()
            .zip(&other.pixels)
            .enumerate()
            .filter(|(_, (a, b))| a != b)
        {
            let (c, r) = (i % self.width, i / self.width);
            x = (x.0.min(c), x.1.max(c));
            y = (y.0.min(r), y.1.max(r));
        }
        (x, y)
    }
}

/// Starts Xvfb on a display number nobody uses; its socket is there when it returns.
/// The X server a test started: stopped with SIGTERM, so that it removes its socket and lock
/// file (SIGKILL left them behind, using up display numbers run after run).
pub(crate) struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = Command::new("kill").args(["-TERM", &self.0.id().to_string()]).status();
        let end = Instant::now() + Duration::from_secs(3);
        while Instant::now() < end {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

pub(crate) fn xvfb() -> (Server, String) {
    // Xvfb picks a display number nobody uses and writes it on `-displayfd` once it accepts
    // clients: no race with another test (or another user's) choosing the same free number.
    let mut child = Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1400x900x24", "-nolisten", "tcp"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("Xvfb starts");
    let stdout = child.stdout.take().expect("stdout");
    let server = Server(child);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx.recv_timeout(GUARD).expect("Xvfb said its display number");
    let n: u32 = line.trim().parse().expect("a display number");
    (server, format!(":{n}"))
}

#[test]
fn a_mouse_draws_a_region_and_pulls_a_point_in_a_real_window() {
    if !x_tools() {
        return;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let doc = dir.path().join("doc.json");
    std::fs::copy(example("01-ridges-and-peaks.json"), &doc).expect("copy the example");
    let regions_before = read(&doc)["regions"].as_array().map_or(0, Vec::len);

    let (_server, display) = xvfb();
    let mut child = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir.path())
        .args([
            "open", "doc.json", "--source", "mouse", "--show", "window", "--size", "1280x720",
        ])
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .env("HOME", dir.path())
        .env("XDG_RUNTIME_DIR", dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("penmodel starts");
    // Its stderr, line by line, to wait on what it says.
    let (tx, said) = mpsc::channel();
    let stderr = child.stderr.take().expect("stderr");
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let penmodel = Killed(child);
    let mut log = Vec::new();
    let mut wait_for = |what: &str| {
        let until = Instant::now() + GUARD;
        while !log.iter().any(|l: &String| l.contains(what)) {
            let left = until.saturating_duration_since(Instant::now());
            assert!(!left.is_zero(), "penmodel never said {what:?}: {log:#?}");
            if let Ok(line) = said.recv_timeout(left) {
                log.push(line);
            }
        }
        log.clone()
    };
    wait_for("the mouse is the pen");
    let mut x = X {
        display,
        window: String::new(),
    };
    let until = Instant::now() + GUARD;
    x.window = loop {
        let out = Command::new("xdotool")
            .args(["search", "--onlyvisible", "--name", "^penmodel$"])
            .env("DISPLAY", &x.display)
            .output()
            .expect("xdotool runs");
        if let Some(w) = String::from_utf8_lossy(&out.stdout).lines().next() {
            break w.to_string();
        }
        assert!(Instant::now() < until, "no penmodel window");
        std::thread::sleep(Duration::from_millis(100));
    };

    // A closed region in the example's free lower-right corner: left held around a 30 m square,
    // back to the start, then the middle button (SW3) ends it.
    let square = [
        (285.0, 285.0),
        (300.0, 285.0),
        (315.0, 285.0),
        (315.0, 300.0),
        (315.0, 315.0),
        (300.0, 315.0),
        (285.0, 315.0),
        (285.0, 300.0),
        (285.0, 286.0),
    ];
    x.to(square[0]);
    x.button("mousedown", 1);
    for p in &square[1..] {
        x.to(*p);
    }
    x.button("mouseup", 1);
    x.button("click", 2);
    wait_for("added region");
    // A point in it: a click, then SW3.
    x.to((300.0, 300.0));
    x.button("click", 1);
    x.button("click", 2);
    wait_for("added point");
    // Grab it (right held, the tip touched and lifted), lift it ten notches, slope it with the
    // middle button held and the pointer moved right, release: one pull and one slope.
    x.to((300.5, 300.0));
    x.button("mousedown", 3);
    x.button("click", 1);
    const NOTCHES: usize = 10;
    for _ in 0..NOTCHES {
        x.button("click", 4);
    }
    x.button("mousedown", 2);
    for p in [(305.0, 300.0), (310.0, 300.0), (318.0, 300.0)] {
        x.to(p);
    }
    x.button("mouseup", 2);
    x.button("mouseup", 3);
    // The keys need the focus (Xvfb has no window manager to give it).
    x.xdo(&["windowfocus", "--sync", &x.window]);
    // `h` draws the help over the middle of the picture: a screenshot shows it there.
    // First the picture settles (the pull's tilt eases back, the erosion catches up).
    let until = Instant::now() + GUARD;
    let mut before = x.screenshot();
    loop {
        std::thread::sleep(Duration::from_millis(300));
        let now = x.screenshot();
        if now.changed(&before) == 0 {
            break;
        }
        assert!(Instant::now() < until, "the picture never settled");
        before = now;
    }
    x.xdo(&["key", "h"]);
    let until = Instant::now() + GUARD;
    let after = loop {
        let now = x.screenshot();
        if now.changed(&before) > 0 {
            break now;
        }
        assert!(Instant::now() < until, "h drew nothing");
        std::thread::sleep(Duration::from_millis(100));
    };
    let (w, h) = (after.width, after.height);
    let (box_x, box_y) = after.changed_box(&before);
    assert!(
        box_x.0 < w / 2 && box_x.1 > w / 2 && box_y.0 < h / 2 && box_y.1 > h / 2,
        "the help is drawn over the middle: changed x {box_x:?}, y {box_y:?} of {w} × {h}"
    );
    assert!(after.changed(&before) > w * h / 20, "a panel, not a few pixels");
    x.xdo(&["key", "h"]);
    // Save and quit from the keyboard.
    x.xdo(&["key", "s"]);
    wait_for("saved");
    x.xdo(&["key", "q"]);
    let mut penmodel = penmodel;
    let until = Instant::now() + GUARD;
    let status = loop {
        if let Some(s) = penmodel.0.try_wait().expect("wait") {
            break s;
        }
        assert!(Instant::now() < until, "penmodel did not quit on q");
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success(), "penmodel quit with {status}");

    let saved = read(&doc);
    let regions = saved["regions"].as_array().expect("regions");
    assert_eq!(regions.len(), regions_before + 1, "one region more");
    let region = &regions[regions.len() - 1];
    let boundary = region["boundary"].as_array().expect("a boundary");
    assert!(boundary.len() >= 4, "{region}");
    for p in boundary {
        let (px, py) = (p[0].as_f64().unwrap_or(f64::NAN), p[1].as_f64().unwrap_or(f64::NAN));
        assert!(
            (283.0..=317.0).contains(&px) && (283.0..=317.0).contains(&py),
            "{region}"
        );
    }
    let figures = region["figures"].as_array().expect("figures");
    assert_eq!(figures.len(), 1, "{region}");
    let point = &figures[0];
    assert_eq!(point["kind"], "point", "{region}");
    let at = &point["points"][0];
    assert!((at[0].as_f64().unwrap_or(0.0) - 300.0).abs() < 1.0, "{point}");
    assert!((at[1].as_f64().unwrap_or(0.0) - 300.0).abs() < 1.0, "{point}");
    // winit 0.30 reports each notch xdotool emulates twice (the button's press and its release;
    // rust-windowing/winit#4386), a real wheel's once: the height counts what the window got.
    let lifted_mm = (2 * NOTCHES) as f64 * penmodel::mouse::WHEEL_MM;
    let height = point["height"].as_f64().unwrap_or(0.0);
    assert!(
        (height - lifted_mm / MM_PER_M).abs() < 1e-6,
        "pulled to {height} m: {point}"
    );
    // 0.04 per mm of sideways motion, from the grab at 300.5 m to 318 m (18.6 mm).
    let slope = point["slope"].as_f64().unwrap_or(0.0);
    assert!((0.6..=0.9).contains(&slope), "slope {slope}: {point}");
}

fn read(doc: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(doc).expect("the document")).expect("JSON")
}
