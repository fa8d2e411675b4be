//! `penmodel` with no arguments and no display: the built-in demo, headless, writes its frames,
//! animation, terrain and document — the README's main job, run in CI.

use std::path::Path;
use std::process::Command;

use serde_json::Value;

fn run(dir: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir)
        .args(extra)
        // No display: the session goes to files. No pend: the demo.
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", dir)
        .output()
        .expect("penmodel runs")
}

/// An APNG's frames as its chunks say: (frames in acTL, each frame's delay in seconds from fcTL).
fn apng_frames(path: &Path) -> (u32, Vec<f64>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (mut count, mut delays, mut at) = (0, Vec::new(), 8);
    while at + 8 <= bytes.len() {
        let (len, kind, body) = (be(at) as usize, &bytes[at + 4..at + 8], at + 8);
        match kind {
            b"acTL" => count = be(body),
            b"fcTL" => {
                // After sequence number, width, height, x, y: delay numerator and denominator.
                let num = u16::from_be_bytes([bytes[body + 20], bytes[body + 21]]);
                let den = u16::from_be_bytes([bytes[body + 22], bytes[body + 23]]);
                delays.push(f64::from(num) / f64::from(if den == 0 { 100 } else { den }));
            }
            _ => {}
        }
        at = body + len + 4;
    }
    (count, delays)
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{} is a PNG", path.display());
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    (be(16), be(20))
}

#[test]
fn the_demo_runs_headless_and_writes_its_results() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Small frames, few of them: the debug build renders slowly.
    let out = run(dir.path(), &["--size", "320x180", "--fps", "1", "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "exit {:?}\n{stderr}", out.status);
    // Without pend the default source is the demo.
    assert!(stderr.contains("pen from sim"), "{stderr}");
    let summary: Value = serde_json::from_slice(&out.stdout).expect("one JSON object on stdout");
    assert_eq!(summary["source"], "sim");
    assert!(
        summary["state"]
            .as_str()
            .is_some_and(|s| s.contains("over (0 reports lost)")),
        "{summary}"
    );
    let stats = &summary["stats"];
    assert_eq!(
        (
            &stats["regions"],
            &stats["figures"],
            &stats["pulls"],
            &stats["undos"],
            &stats["refused"]
        ),
        (
            &Value::from(1),
            &Value::from(6),
            // The six figures' pulls and the demo's first tree's (issue 14).
            &Value::from(7),
            &Value::from(2),
            &Value::from(0)
        ),
        "{summary}"
    );
    // The tree tool's step (pen_sim::session::tree_step): two taps, one outline.
    assert_eq!(
        (&stats["trees"], &stats["groves"]),
        (&Value::from(2), &Value::from(1)),
        "{summary}"
    );

    let out_dir = dir.path().join("out");
    // Frames of the display's view with the overview column beside it, and their animation.
    let frames = summary["frames"].as_u64().expect("frame count");
    assert!(
        frames >= 20,
        "{frames} frames at 1 per second of a session over 20 s long"
    );
    // By default the animation only; single frames and meshes on request (a compact default).
    assert!(!out_dir.join("frames/frame_00000.png").exists());
    assert_eq!(png_size(&out_dir.join("frames/animation.png")), (480, 180));
    // Where the view moves (the ground tilts while a figure is pulled; the tracked head's last
    // 12 s) the animation holds 1 frame in 3 (--moving-every), shown the longer: fewer frames,
    // and still the session's time, a second per frame at --fps 1.
    let held = summary["animation_frames"].as_u64().expect("frames held");
    let (count, delays) = apng_frames(&out_dir.join("frames/animation.png"));
    assert_eq!((u64::from(count), delays.len() as u64), (held, held), "{summary}");
    assert!(held < frames * 9 / 10, "{held} of {frames} frames held");
    let played: f64 = delays.iter().sum();
    assert!(
        (played - frames as f64).abs() < 1e-6,
        "{played} s for {frames} frames at 1 a second"
    );
    assert!(delays.iter().all(|&d| (0.999..=3.001).contains(&d)), "{delays:?}");
    // The terrain: 16-bit heightmap, float32, meshes, renders; the document.
    assert_eq!(png_size(&out_dir.join("terrain.png")), (480, 272));
    let raw = std::fs::metadata(out_dir.join("terrain.f32"))
        .expect("terrain.f32")
        .len();
    assert_eq!(raw, 480 * 272 * 4);
    for name in ["render.png", "display.png"] {
        assert!(out_dir.join(name).exists(), "{name}");
    }
    for name in ["terrain.obj", "terrain.glb"] {
        assert!(!out_dir.join(name).exists(), "{name} only with --meshes");
    }
    let doc = penmodel_terrain::Document::load(&out_dir.join("document.json")).expect("a valid document");
    assert_eq!(doc.regions.len(), 1);
    assert_eq!(
        doc.regions[0].figures.len(),
        4,
        "two peaks, a ridge, a plateau (the mistake undone)"
    );
    assert_eq!(doc.regions[0].figures[3].figures.len(), 1, "the plateau's peak");
    let hi = summary["heights_m"][1].as_f64().expect("highest");
    assert!(
        (1000.0..1200.0).contains(&hi),
        "the plateau's peak, pulled 110 mm at 1:10 000: {hi} m"
    );

    // Run again: the demo's own outputs are replaced, nothing refuses; frames and meshes asked.
    let again = run(
        dir.path(),
        &[
            "--size",
            "160x90",
            "--fps",
            "1",
            "--no-overview",
            "--frames",
            "--meshes",
            "--moving-every",
            "1",
        ],
    );
    assert!(again.status.success(), "{}", String::from_utf8_lossy(&again.stderr));
    let stdout = String::from_utf8_lossy(&again.stdout);
    assert!(
        stdout.contains("1 region,") && stdout.contains("its meshes"),
        "{stdout}"
    );
    assert_eq!(png_size(&out_dir.join("frames/frame_00000.png")), (160, 90));
    // --moving-every 1: the animation holds every frame written, in far fewer bytes (deltas).
    let files: Vec<_> = std::fs::read_dir(out_dir.join("frames"))
        .expect("frames")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with("frame_"))
        .collect();
    let (count, _) = apng_frames(&out_dir.join("frames/animation.png"));
    assert_eq!(count as usize, files.len());
    let whole: u64 = files.iter().filter_map(|e| e.metadata().ok()).map(|m| m.len()).sum();
    let stored = std::fs::metadata(out_dir.join("frames/animation.png"))
        .expect("animation")
        .len();
    assert!(stored * 2 < whole, "{stored} bytes for frames of {whole} bytes");
    for name in ["terrain.obj", "terrain.glb"] {
        assert!(out_dir.join(name).exists(), "{name}");
    }

    // Open the document with no pen: it is the user's now, so the demo does not play into it.
    // Headless there is nothing to do: refused, saying how to attach a pen; nothing touched.
    let bytes_before = std::fs::read(out_dir.join("document.json")).expect("the document");
    let refused = run(
        dir.path(),
        &["open", "out/document.json", "--out", "more", "--fps", "1"],
    );
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("no pen") && stderr.contains("pend") && stderr.contains("--source sim"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(out_dir.join("document.json")).expect("the document"),
        bytes_before,
        "untouched"
    );
    assert!(!dir.path().join("more/document.json").exists());

    // Asked for explicitly, the demo's pen draws on it. Its region overlaps the one there and
    // is refused (counted, told); its figures land in the existing region; nothing is lost.
    let before = penmodel_terrain::Document::load(&out_dir.join("document.json")).expect("valid");
    let open = run(
        dir.path(),
        &[
            "open",
            "out/document.json",
            "--source",
            "sim",
            "--out",
            "more",
            "--size",
            "160x90",
            "--fps",
            "0",
            "--json",
        ],
    );
    let stderr = String::from_utf8_lossy(&open.stderr);
    assert!(open.status.success(), "{stderr}");
    assert!(stderr.contains("refused"), "{stderr}");
    let summary: Value = serde_json::from_slice(&open.stdout).expect("JSON");
    // --fps 0: no animation, the results alone.
    assert_eq!(summary["frames"], 0, "{summary}");
    assert!(!dir.path().join("more/frames").exists());
    assert!(dir.path().join("more/terrain.png").exists());
    assert!(
        summary["stats"]["refused"].as_u64().is_some_and(|n| n >= 1),
        "{summary}"
    );
    let after = penmodel_terrain::Document::load(&out_dir.join("document.json")).expect("saved in place");
    assert_eq!(after.regions.len(), 1);
    assert_eq!(after.regions[0].boundary, before.regions[0].boundary);
    assert!(
        after.regions[0].figures.len() > before.regions[0].figures.len(),
        "{summary}"
    );
}

#[test]
fn a_real_session_never_overwrites_a_document() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("out")).expect("out");
    std::fs::write(dir.path().join("out/document.json"), "{}").expect("a file");
    let out = run(dir.path(), &["--source", "serial:/dev/null/nothing"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("exists") && stderr.contains("penmodel open"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("out/document.json")).expect("kept"),
        "{}"
    );
    // Nor does the demo replace a document it did not write.
    let demo = run(dir.path(), &["--fps", "1"]);
    assert_eq!(demo.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&demo.stderr);
    assert!(stderr.contains("exists") && stderr.contains("--out"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("out/document.json")).expect("kept"),
        "{}"
    );
    // A source that is not one is a usage error with the choices, each named once.
    let bad = run(dir.path(), &["--source", "carrier-pigeon"]);
    assert_eq!(bad.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        stderr.contains("sim (the built-in demo), sim:SCENARIO, mouse, none, daemon"),
        "{stderr}"
    );
    assert_eq!(
        stderr.matches("sim,").count() + stderr.matches("sim ").count(),
        1,
        "{stderr}"
    );
}

/// Issue 42: the mouse's mapping is read from the settings file; a bad one ends penmodel
/// before anything is created (no window needed to find out), naming the file, key and line.
#[test]
fn a_bad_mouse_mapping_is_refused_before_anything_is_created() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = dir.path().join("config/penscape");
    std::fs::create_dir_all(&config).expect("config folder");
    let settings = config.join("modeler.toml");
    std::fs::write(&settings, "[mouse]\nleft = \"sw1\"\nright = \"sw4\"\n").expect("write");
    let doc = dir.path().join("doc.json");
    std::fs::copy(crate::common::example("01-ridges-and-peaks.json"), &doc).expect("copy");
    let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir.path())
        .args([
            "open",
            &doc.display().to_string(),
            "--source",
            "mouse",
            "--show",
            "window",
        ])
        .env("XDG_CONFIG_HOME", dir.path().join("config"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("penmodel runs");
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&settings.display().to_string()) && err.contains("sw4") && err.contains("line 3"),
        "{err}"
    );
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .expect("read_dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["config", "doc.json"], "nothing created");
}
