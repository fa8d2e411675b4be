//! `penmodel generate`, `render` and `bench` end to end: outputs, exit codes and messages.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn penmodel(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .args(args)
        .output()
        .unwrap()
}

fn example(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn generate_writes_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let [raw, png, obj, glb] = ["t.f32", "t.png", "t.obj", "t.glb"].map(|n| dir.path().join(n));
    let out = penmodel(&[
        "generate",
        &example("04-volcano.json"),
        "--raw",
        s(&raw),
        "--png",
        s(&png),
        "--obj",
        s(&obj),
        "--glb",
        s(&glb),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "160 × 160 cells, heights 0 to 70 m\n"
    );
    assert_eq!(std::fs::metadata(&raw).unwrap().len(), 160 * 160 * 4);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    assert!(std::fs::read_to_string(&obj).unwrap().contains("\nf "));
    assert!(std::fs::read(&glb).unwrap().starts_with(b"glTF"));
}

#[test]
fn bad_input_exits_1_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("bad.json");
    let text = std::fs::read_to_string(example("02-twin-hills.json"))
        .unwrap()
        .replacen("\"height\": 40.0", "\"height\": 40.0, \"kind\": \"closed\"", 1);
    std::fs::write(&doc, text).unwrap();
    let raw = dir.path().join("o.f32");
    let out = penmodel(&["generate", s(&doc), "--raw", s(&raw)]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("penmodel: regions[0].figures[0]"), "{err}");
    assert!(!raw.exists());

    let out = penmodel(&["generate", s(&dir.path().join("missing.json")), "--raw", s(&raw)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read"));

    let out = penmodel(&[
        "generate",
        &example("04-volcano.json"),
        "--raw",
        s(&dir.path().join("no/such/dir/o.f32")),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot write"));
}

#[test]
fn usage_errors_exit_2() {
    assert_eq!(
        penmodel(&["generate", &example("04-volcano.json")]).status.code(),
        Some(2)
    );
    assert_eq!(penmodel(&["frobnicate"]).status.code(), Some(2));
    // Without a subcommand penmodel models with the pen (tests/demo_cli.rs); its options are
    // checked like any others.
    assert_eq!(penmodel(&["--fps", "61"]).status.code(), Some(2));
    // Holding 1 frame in 0 of the moving ones means nothing: 1 holds them all.
    assert_eq!(penmodel(&["--moving-every", "0"]).status.code(), Some(2));
    assert_eq!(penmodel(&["--show", "sideways"]).status.code(), Some(2));
    let help = penmodel(&["generate", "--help"]);
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).contains("--raw <OUT.f32>"));
}

fn png_size(path: &Path) -> (u32, u32) {
    let reader = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()))
        .read_info()
        .unwrap();
    (reader.info().width, reader.info().height)
}

#[test]
fn render_writes_a_png_of_the_requested_size() {
    let dir = tempfile::tempdir().unwrap();
    for (stereo, size, expected) in [
        ("none", "320x200", (320, 200)),
        ("anaglyph", "161x97", (161, 97)),
        ("side-by-side", "400X150", (400, 150)),
    ] {
        let png = dir.path().join(format!("{stereo}.png"));
        let out = penmodel(&[
            "render",
            &example("02-twin-hills.json"),
            "--png",
            s(&png),
            "--size",
            size,
            "--stereo",
            stereo,
            "--tilt",
            "10",
            "--azimuth",
            "-40",
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(png_size(&png), expected);
    }
    // The tracked view and a turntable.
    let png = dir.path().join("tracked.png");
    let frames = dir.path().join("turn");
    let out = penmodel(&[
        "render",
        &example("04-volcano.json"),
        "--png",
        s(&png),
        "--size",
        "160x90",
        "--display",
        "1.6x0.9",
        "--head",
        "0.1,-0.3,0.7",
        "--turntable",
        "3",
        "--frames",
        s(&frames),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(png_size(&png), (160, 90));
    for name in ["frame_00000.png", "frame_00002.png", "animation.png"] {
        assert_eq!(png_size(&frames.join(name)), (160, 90), "{name}");
    }
}

#[test]
fn render_usage_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("o.png");
    let doc = example("02-twin-hills.json");
    for args in [
        vec!["render", &doc, "--png", s(&png), "--size", "0x10"],
        vec!["render", &doc, "--png", s(&png), "--size", "10"],
        vec!["render", &doc, "--png", s(&png), "--stereo", "3d"],
        vec!["render", &doc],
        vec!["render", &doc, "--png", s(&png), "--head", "0,0,1"],
        vec!["render", &doc, "--png", s(&png), "--turntable", "3"],
    ] {
        let out = penmodel(&args);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(!png.exists());
    }
}

#[test]
fn render_of_a_bad_document_exits_1_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("bad.json");
    std::fs::write(
        &doc,
        r#"{"version": 1, "grid": {"cols": 8, "rows": 8, "cell_size": -1.0}, "regions": []}"#,
    )
    .unwrap();
    let png = dir.path().join("o.png");
    let out = penmodel(&["render", s(&doc), "--png", s(&png)]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("grid.cell_size"), "{err}");
    assert!(!png.exists());
    // A camera that cannot work is a bad input too.
    let out = penmodel(&[
        "render",
        &example("02-twin-hills.json"),
        "--png",
        s(&png),
        "--distance",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("distance"));
}

#[test]
fn bench_json_has_the_documented_shape() {
    let out = penmodel(&[
        "bench",
        "--json",
        "--grid",
        "16",
        "--grid",
        "24",
        "--memory-grid",
        "64",
        "--memory-figures",
        "10",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let obj = v.as_object().unwrap();
    assert_eq!(
        obj.keys().collect::<Vec<_>>(),
        ["render", "pull_update", "memory", "terrain", "still"]
    );
    // Still frames (issue 18): each grid with LOD off and on, mono and stereo.
    let still = v["still"].as_array().unwrap();
    assert_eq!(still.len(), 8);
    for (k, s) in still.iter().enumerate() {
        assert_eq!(
            s.as_object().unwrap().keys().collect::<Vec<_>>(),
            ["grid", "lod_error", "stereo", "frame_ms", "nodes_per_level"]
        );
        assert_eq!(s["grid"], if k < 4 { 16 } else { 24 });
        assert_eq!(s["stereo"], k % 4 >= 2);
        assert_eq!(s["lod_error"].as_f64(), Some(if k % 2 == 0 { 0.0 } else { 1.0 }));
        assert!(s["frame_ms"].as_f64().unwrap() > 0.0);
        // LOD off draws no nodes; on, at least one.
        assert_eq!(s["nodes_per_level"].as_array().unwrap().is_empty(), k % 2 == 0);
    }
    // The terrain engine's figures (issue 18): each grid in both metrics.
    let terrain = v["terrain"].as_array().unwrap();
    assert_eq!(terrain.len(), 4);
    for (t, (n, metric)) in terrain
        .iter()
        .zip([(16, "taxicab"), (16, "euclidean"), (24, "taxicab"), (24, "euclidean")])
    {
        assert_eq!(
            t.as_object().unwrap().keys().collect::<Vec<_>>(),
            ["grid", "metric", "full_ms", "move_point_ms", "slope_ms"]
        );
        assert_eq!((t["grid"].as_u64(), t["metric"].as_str()), (Some(n), Some(metric)));
        for key in ["full_ms", "move_point_ms", "slope_ms"] {
            assert!(t[key].as_f64().unwrap() >= 0.0, "{key}");
        }
    }
    let render = v["render"].as_array().unwrap();
    let pull = v["pull_update"].as_array().unwrap();
    for (i, n) in [16, 24].into_iter().enumerate() {
        let r = render[i].as_object().unwrap();
        assert_eq!(
            r.keys().collect::<Vec<_>>(),
            ["grid", "width", "height", "look", "frame_ms", "frame_mean_ms"]
        );
        // The land look unless --look classic (issue 20).
        assert_eq!(r["look"].as_str(), Some("land"));
        assert!(r["frame_mean_ms"].as_f64().unwrap() > 0.0);
        assert_eq!(
            (r["grid"].as_u64(), r["width"].as_u64(), r["height"].as_u64()),
            (Some(n), Some(1280), Some(720))
        );
        assert!(r["frame_ms"].as_f64().unwrap() > 0.0);
        assert_eq!(pull[i]["grid"].as_u64(), Some(n));
        assert!(pull[i]["ms"].as_f64().unwrap() >= 0.0);
    }
    let memory = &v["memory"];
    assert_eq!(
        (memory["grid"].as_u64(), memory["figures"].as_u64()),
        (Some(64), Some(10))
    );
    assert!(memory["estimate_mb"].as_f64().unwrap() > 0.0);
    // Linux reports the peak resident set; elsewhere it is null.
    assert!(memory["peak_rss_mb"].is_null() || memory["peak_rss_mb"].as_f64().unwrap() > 0.0);
}

/// Runs `generate` on `text` as a document (and `journal` beside it), returning exit code and stderr.
fn generate_text(text: &[u8], journal: Option<&[u8]>) -> (Option<i32>, String) {
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("d.json");
    std::fs::write(&doc, text).unwrap();
    if let Some(j) = journal {
        std::fs::write(dir.path().join("d.json.journal"), j).unwrap();
    }
    let out = penmodel(&["generate", s(&doc), "--raw", s(&dir.path().join("o.f32"))]);
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn volcano_with(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(example("04-volcano.json")).unwrap();
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn generate_refuses_what_would_not_make_finite_terrain() {
    let volcano = std::fs::read_to_string(example("04-volcano.json")).unwrap();
    let (code, err) = generate_text(volcano_with("\"height\": 70.0", "\"height\": 1.7e308").as_bytes(), None);
    assert_eq!(code, Some(1));
    assert!(err.contains("a height must be within ±1000000 m, got 1.7e308"), "{err}");
    let (code, err) = generate_text(
        volcano_with("\"cell_size\": 2.0", "\"cell_size\": 1e308").as_bytes(),
        None,
    );
    assert_eq!(code, Some(1));
    assert_eq!(
        err,
        "penmodel: grid.cell_size: the cell size must be between 0.001 and 100000 m, got 1e308\n"
    );
    // A journal that sets such a height does not replay.
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("v.json");
    std::fs::write(&doc, &volcano).unwrap();
    let base = penmodel_terrain::journal::fingerprint(volcano.as_bytes());
    let journal = format!(
        "{{\"op\":\"open\",\"journal\":1,\"base\":\"{base}\"}}\n{{\"op\":\"do\",\"edit\":{{\"op\":\"set_height\",\"at\":\"regions[0].figures[0]\",\"height\":1e308}}}}\n"
    );
    let (code, err) = generate_text(volcano.as_bytes(), Some(journal.as_bytes()));
    assert_eq!(code, Some(1));
    assert!(
        err.contains("line 2: cannot replay") && err.contains("got 1e308"),
        "{err}"
    );
}

#[test]
fn generate_refuses_text_after_the_document() {
    let volcano = std::fs::read_to_string(example("04-volcano.json")).unwrap();
    for tail in ["xyz garbage {", volcano.as_str()] {
        let (code, err) = generate_text(format!("{volcano}{tail}").as_bytes(), None);
        assert_eq!(code, Some(1));
        assert!(
            err.starts_with("penmodel: document: unexpected text after the end of the document"),
            "{err}"
        );
    }
}

#[test]
fn generate_messages_name_the_problem_once() {
    let (code, err) = generate_text(b"{", None);
    assert_eq!(code, Some(1));
    assert!(err.starts_with("penmodel: document: ") && !err.contains('?'), "{err}");
    let (_, err) = generate_text(b"[]", None);
    assert!(
        err.contains("expected a document") && !err.contains("VersionOnly"),
        "{err}"
    );
    let (_, err) = generate_text(
        br#"{"version": 1, "grid": {"cols": 4, "rows": 4, "cell_size": 1}, "regions": [{"boundary": [[0, 0, 1]]}]}"#,
        None,
    );
    assert!(
        err.starts_with("penmodel: regions[0].boundary[0]: a point is [x, y]: two numbers, found more"),
        "{err}"
    );
    // A directory as the document: refused before reading, said once.
    let dir = tempfile::tempdir().unwrap();
    let out = penmodel(&["generate", s(dir.path()), "--raw", s(&dir.path().join("o.f32"))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(err.matches("a directory, not a regular file").count(), 1, "{err}");
    // A missing one: the OS's reason once.
    let out = penmodel(&[
        "generate",
        s(&dir.path().join("no.json")),
        "--raw",
        s(&dir.path().join("o.f32")),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    // A journal line that is not UTF-8 is named by its line.
    let volcano = std::fs::read_to_string(example("04-volcano.json")).unwrap();
    let base = penmodel_terrain::journal::fingerprint(volcano.as_bytes());
    let mut journal =
        format!("{{\"op\":\"open\",\"journal\":1,\"base\":\"{base}\"}}\n{{\"op\":\"undo\"}}\n").into_bytes();
    journal.extend_from_slice(b"{\"op\":\"re\xffdo\"}\n");
    let (code, err) = generate_text(volcano.as_bytes(), Some(&journal));
    assert_eq!(code, Some(1));
    assert!(err.contains("line 3: not UTF-8 text"), "{err}");
}

#[test]
fn generate_says_when_it_skips_a_stale_journal() {
    let volcano = std::fs::read_to_string(example("04-volcano.json")).unwrap();
    let journal = b"{\"op\":\"open\",\"journal\":1,\"base\":\"fnv1a64:0000000000000000\"}\n";
    let (code, err) = generate_text(volcano.as_bytes(), Some(journal));
    assert_eq!(code, Some(0));
    assert!(err.contains("d.json.journal was not replayed"), "{err}");
}

#[test]
fn a_reader_that_goes_away_ends_penmodel_quietly() {
    // `penmodel generate DOC | head -0`: the pipe's reader is gone before penmodel writes, so
    // its first line meets a broken pipe — every time, not by a race.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("t.png");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .args(["generate", &example("04-volcano.json"), "--png", s(&png)])
        .stdout(writer)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(png.exists(), "the work is done before the summary line");
}

/// `penmodel open` of a document whose journal has a flipped bit: refused naming the line and
/// suggesting --recover; with --recover, opened up to the last good line, saying what it left
/// out, the journal as it was kept beside it.
#[test]
fn open_refuses_a_corrupt_journal_and_recover_opens_up_to_the_bad_line() {
    use penmodel_terrain::{Edit, FigurePath, editor::Editor, journal};
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("d.json");
    let volcano = penmodel_terrain::Document::load(Path::new(&example("04-volcano.json"))).unwrap();
    let mut editor = Editor::create(&doc, volcano).unwrap();
    for height in [50.0, 109.0, 130.0] {
        let at = FigurePath::new(0, 0);
        editor.apply(Edit::SetHeight { at, height }).unwrap();
    }
    drop(editor);
    let jpath = journal::path_for(&doc);
    let flipped = std::fs::read_to_string(&jpath).unwrap().replace("109.0", "108.0");
    std::fs::write(&jpath, &flipped).unwrap();
    let out = dir.path().join("out");
    // A pen that never comes (a serial port that is no port): the session waits until stopped.
    let open = |recover: bool| {
        let mut args = vec!["open", s(&doc)];
        if recover {
            args.push("--recover");
        }
        args.extend(["--source", "serial:/dev/null", "--fps", "0", "--size", "64x36"]);
        args.extend(["--show", "headless", "--out", s(&out)]);
        Command::new(env!("CARGO_BIN_EXE_penmodel"))
            .args(&args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env("XDG_RUNTIME_DIR", dir.path())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };

    let refused = open(false).wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("d.json.journal line 3: checksum mismatch"), "{stderr}");
    assert!(stderr.contains("penmodel open --recover"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(&jpath).unwrap(),
        flipped,
        "refused: nothing touched"
    );

    let child = open(true);
    let copy = format!("{}.corrupt", s(&jpath));
    let start = std::time::Instant::now();
    while !Path::new(&copy).exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    // Stopped (as a user stops it): the session saves what it has.
    std::thread::sleep(std::time::Duration::from_millis(500));
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let recovered = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&recovered.stderr);
    assert!(recovered.status.success(), "{stderr}");
    assert!(
        stderr.contains("recovered: journal lines 3 to 4 left out (2 lines; line 3: checksum mismatch"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), flipped);
    // The edit before the bad line is in the saved document.
    let saved = penmodel_terrain::Document::load(&doc).unwrap();
    assert_eq!(saved.regions[0].figures[0].height, 50.0);
    // The session went on from the good lines and saved: the document opens cleanly.
    let (_, report) = Editor::open_read_only(&doc).expect("opens without --recover now");
    assert!(report.recovered.is_none());
}

/// Issue 42: `open DOC` writes its results beside DOC (`DOC`'s name with `.out`), never into
/// the `./out` another run left.
#[test]
fn open_writes_its_results_beside_the_document() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("maps")).expect("maps");
    let doc = dir.path().join("maps/alps.json");
    std::fs::copy(crate::common::example("02-twin-hills.json"), &doc).expect("copy");
    // A pen that never comes: the session waits, its results' folder made, until stopped.
    let mut child = Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir.path())
        .args(["open", "maps/alps.json", "--source", "serial:/dev/null", "--fps", "0"])
        .args(["--show", "headless"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("penmodel starts");
    let until = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while !dir.path().join("maps/alps.out").is_dir() {
        assert!(std::time::Instant::now() < until, "no maps/alps.out");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(!dir.path().join("out").exists(), "nothing in ./out");
}

/// Issue 42: a pen-sim scenario plays once and the session ends with it (`--loop` repeats it).
#[test]
fn a_simulated_scenario_plays_once() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = crate::common::penmodel(
        dir.path(),
        &[
            "--source",
            "sim:draw-figures",
            "--speed",
            "0",
            "--fps",
            "0",
            "--size",
            "64x36",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("the scenario draw-figures is over"), "{stderr}");
    assert!(dir.path().join("out/document.json").exists(), "{stderr}");
}

#[test]
fn a_failed_open_removes_the_out_folder_it_created() {
    // Issue 47: `penmodel open` on a document it cannot read left the `--out` folder behind.
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "not json").unwrap();
    let out_dir = dir.path().join("results");
    let open = || {
        penmodel(&[
            "open",
            s(&bad),
            "--out",
            s(&out_dir),
            "--source",
            "sim:modeling-session",
            "--show",
            "headless",
            "--fps",
            "0",
        ])
    };
    let out = open();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!out_dir.exists(), "the --out folder it made is gone");
    // A folder that was there before stays.
    std::fs::create_dir(&out_dir).unwrap();
    let out = open();
    assert_eq!(out.status.code(), Some(1));
    assert!(out_dir.is_dir(), "a folder it did not make is kept");
}

#[test]
fn a_document_starting_with_a_byte_order_mark_renders() {
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("bom.json");
    let mut text = b"\xef\xbb\xbf".to_vec();
    text.extend(std::fs::read(example("02-twin-hills.json")).unwrap());
    std::fs::write(&doc, text).unwrap();
    let png = dir.path().join("t.png");
    let out = penmodel(&["generate", s(&doc), "--png", s(&png)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(png.exists());
}

#[test]
fn long_and_thin_grids_render_and_analyse() {
    // Issue 47, item 3: the land look's and `analyze --sky`'s sweeps held the square of the
    // long side (262144 × 1 aborted asking for 275 GB).
    let dir = tempfile::tempdir().unwrap();
    for (cols, rows) in [(4096, 2), (1, 1000), (2, 3), (262_144, 1)] {
        let doc = dir.path().join(format!("g{cols}x{rows}.json"));
        std::fs::write(
            &doc,
            format!("{{\"version\": 1, \"grid\": {{\"cols\": {cols}, \"rows\": {rows}, \"cell_size\": 2.0}}, \"regions\": []}}"),
        )
        .unwrap();
        let png = dir.path().join("r.png");
        let out = penmodel(&["render", s(&doc), "--png", s(&png), "--size", "160x90"]);
        assert!(
            out.status.success(),
            "{cols}×{rows} render: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let sky = dir.path().join("s.png");
        let out = penmodel(&["analyze", s(&doc), "--sky", s(&sky), "--sky-directions", "8"]);
        assert!(
            out.status.success(),
            "{cols}×{rows} sky: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
