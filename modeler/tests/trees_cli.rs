//! `penmodel trees` end to end: the counts per Q against the law, meshes of a tree and a grove,
//! the fit to silhouettes, errors naming the flag or file, and the trees in `penmodel generate`.

use serde_json::Value;

use penmodel_terrain::trees::silhouette::{self, View};
use penmodel_terrain::trees::{Preset, Species};

use crate::common::penmodel;

fn ok(out: &std::process::Output) {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

fn failed_with(out: &std::process::Output, message: &str) {
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(message), "{err}");
}

#[test]
fn stats_follow_the_law_as_json() {
    let dir = tempfile::tempdir().expect("dir");
    // The issue's form: no subcommand.
    let out = penmodel(
        dir.path(),
        &[
            "trees",
            "--preset",
            "table-3.1",
            "--q",
            "0.02,0.05,0.1,0.2",
            "--json",
            "-",
        ],
    );
    ok(&out);
    let v: Value = serde_json::from_slice(&out.stdout).expect("one JSON document on stdout");
    assert_eq!(v["m"], 5);
    let rows = v["per_q"].as_array().expect("per_q");
    assert_eq!(rows.len(), 4);
    for r in rows {
        let q = r["q"].as_f64().expect("q");
        let nodes = r["nodes"].as_u64().expect("nodes");
        // Every map of a copied node is a copied node, a shape or a leaf.
        assert_eq!(r["volume"].as_u64(), Some(1 + 5 * nodes));
        let law = 5.0 / 4.0 * q.powf(5f64.ln() / 0.46f64.ln());
        assert!((r["law"].as_f64().expect("law") - law).abs() < 1e-9 * law);
    }
    let e = v["fitted_exponent"].as_f64().expect("fitted");
    assert!((-2.3..-2.0).contains(&e), "{e}");
    // The summary went to stderr.
    assert!(String::from_utf8_lossy(&out.stderr).contains("law exponent -2.073"));
}

#[test]
fn bad_q_maps_and_presets_are_named() {
    let dir = tempfile::tempdir().expect("dir");
    failed_with(
        &penmodel(dir.path(), &["trees", "stats", "--q", "0.1,1.5"]),
        "--q: Q = 1.5 is outside (0, 1]",
    );
    failed_with(
        &penmodel(dir.path(), &["trees", "--q", "0"]),
        "--q: Q = 0 is outside (0, 1]",
    );
    failed_with(
        &penmodel(dir.path(), &["trees", "--preset", "baobab"]),
        "--preset: unknown preset \"baobab\"",
    );
    let maps =
        r#"[{"y": 0.4, "s": 0.6, "theta_z": 10, "theta_y": 0}, {"y": 0.2, "s": 1.2, "theta_z": 40, "theta_y": 60}]"#;
    std::fs::write(dir.path().join("maps.json"), maps).expect("written");
    failed_with(
        &penmodel(dir.path(), &["trees", "--maps", "maps.json"]),
        "maps.json: maps[1].s: |s| = 1.2 is not below 1: the IFS does not contract",
    );
    std::fs::write(dir.path().join("bad.json"), "{").expect("written");
    failed_with(
        &penmodel(dir.path(), &["trees", "--maps", "bad.json"]),
        "bad.json: not a list of maps",
    );
    failed_with(
        &penmodel(dir.path(), &["trees", "--maps", "none.json"]),
        "cannot read none.json",
    );
    failed_with(
        &penmodel(dir.path(), &["trees", "mesh", "--q", "2", "--obj", "t.obj"]),
        "--q: Q = 2 is outside (0, 1]",
    );
    failed_with(
        &penmodel(dir.path(), &["trees", "mesh", "--wind", "3:fast", "--obj", "t.obj"]),
        "--wind: \"3:fast\" is not AMPLITUDE:FREQUENCY",
    );
    // A usage error: no output.
    assert_eq!(penmodel(dir.path(), &["trees", "mesh"]).status.code(), Some(2));
}

#[test]
fn mesh_writes_a_tree_and_a_grove() {
    let dir = tempfile::tempdir().expect("dir");
    ok(&penmodel(
        dir.path(),
        &[
            "trees",
            "mesh",
            "--preset",
            "table-3.1",
            "--obj",
            "t.obj",
            "--ply",
            "t.ply",
            "--glb",
            "t.glb",
        ],
    ));
    let obj = std::fs::read_to_string(dir.path().join("t.obj")).expect("obj");
    // The full tree: 60 222 triangles (the polygons of the map recursion, two each), coloured.
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 60_222);
    assert!(
        obj.lines()
            .filter(|l| l.starts_with("v "))
            .all(|l| l.split_whitespace().count() == 7)
    );
    assert!(
        std::fs::read(dir.path().join("t.ply"))
            .expect("ply")
            .starts_with(b"ply\n")
    );
    assert!(
        std::fs::read(dir.path().join("t.glb"))
            .expect("glb")
            .starts_with(b"glTF")
    );
    // At Q = 0.1 the simplified shapes are crossed cards, a second object.
    ok(&penmodel(
        dir.path(),
        &["trees", "mesh", "--q", "0.1", "--obj", "q.obj"],
    ));
    let obj = std::fs::read_to_string(dir.path().join("q.obj")).expect("obj");
    assert!(obj.contains("o simplified shapes"));
    let out = penmodel(
        dir.path(),
        &[
            "trees",
            "mesh",
            "--grove",
            "20",
            "--density",
            "300",
            "--mix",
            "oak:2,fir",
            "--q",
            "0.05",
            "--glb",
            "g.glb",
        ],
    );
    ok(&out);
    let said = String::from_utf8_lossy(&out.stdout);
    let trees: u32 = said
        .split(" trees")
        .next()
        .and_then(|n| n.trim().parse().ok())
        .expect("a count");
    // 300 per hectare over π·20² m² is 37.7.
    assert!((25..=50).contains(&trees), "{said}");
}

#[test]
fn fit_returns_a_preset_and_names_bad_files() {
    let dir = tempfile::tempdir().expect("dir");
    let s = Species::preset(Preset::Cypress);
    for (name, view) in [("front.png", View::Front), ("side.png", View::Side)] {
        let img = silhouette::render(&s, view, 96, 0.02);
        let file = std::fs::File::create(dir.path().join(name)).expect("created");
        img.write_png(std::io::BufWriter::new(file)).expect("written");
    }
    let out = penmodel(
        dir.path(),
        &[
            "trees",
            "fit",
            "front.png",
            "side.png",
            "--iterations",
            "2",
            "--starts",
            "1",
            "--json",
            "-",
        ],
    );
    ok(&out);
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["preset"], "cypress");
    let (start, reached) = (&v["start"], &v["reached"]);
    for k in 0..2 {
        assert!(reached[k].as_f64() >= start[k].as_f64().map(|s| s - 0.05), "{v}");
    }
    assert_eq!(v["maps"].as_array().map(Vec::len), Some(5));
    assert_eq!(v["out_of_time"], false, "{v}");
    // Issue 47: a fit has a time budget; past it the best so far is kept, with a warning.
    let out = penmodel(
        dir.path(),
        &[
            "trees",
            "fit",
            "front.png",
            "side.png",
            "--time-limit",
            "0.001",
            "--json",
            "-",
        ],
    );
    ok(&out);
    let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    // Checked before each step: the ascent under way when time runs out finishes its step.
    assert!(v["out_of_time"] == true && v["iterations"].as_u64() <= Some(1), "{v}");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("stopped at its time limit (0.001 s)"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let usage = penmodel(
        dir.path(),
        &["trees", "fit", "front.png", "side.png", "--time-limit", "0"],
    );
    assert_eq!(usage.status.code(), Some(2), "a usage error");
    assert!(String::from_utf8_lossy(&usage.stderr).contains("give a time limit above 0"));
    failed_with(
        &penmodel(dir.path(), &["trees", "fit", "nope.png", "side.png"]),
        "cannot read nope.png",
    );
    std::fs::write(dir.path().join("text.png"), "not a png").expect("written");
    failed_with(
        &penmodel(dir.path(), &["trees", "fit", "text.png", "side.png"]),
        "text.png: not a readable PNG",
    );
    let blank = silhouette::Image::new(16, 16);
    let file = std::fs::File::create(dir.path().join("blank.png")).expect("created");
    blank.write_png(std::io::BufWriter::new(file)).expect("written");
    failed_with(
        &penmodel(dir.path(), &["trees", "fit", "front.png", "blank.png"]),
        "blank.png: the image is blank",
    );
}

#[test]
fn generate_exports_the_documents_trees() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = r#"{"version": 4, "grid": {"cols": 64, "rows": 64, "cell_size": 1.0},
      "regions": [{"boundary": [[2.0, 2.0], [62.0, 2.0], [62.0, 62.0], [2.0, 62.0], [2.0, 2.0]],
        "figures": [{"kind": "point", "points": [[32.0, 32.0]], "height": 10.0}]}],
      "trees": [{"at": [32.5, 32.5], "height": 8.0, "preset": "fir"}],
      "groves": [{"region": [[5.0, 5.0], [25.0, 5.0], [25.0, 25.0], [5.0, 25.0], [5.0, 5.0]], "density": 100.0}]}"#;
    std::fs::write(dir.path().join("d.json"), doc).expect("written");
    ok(&penmodel(dir.path(), &["generate", "d.json", "--obj", "d.obj"]));
    let obj = std::fs::read_to_string(dir.path().join("d.obj")).expect("obj");
    assert!(obj.contains("o trees"));
    // The fir stands on the peak: its lowest vertices are near the terrain's 10 m there.
    let trees = obj.split("o trees").nth(1).expect("the trees");
    let lowest = trees
        .lines()
        .filter(|l| l.starts_with("v "))
        .filter_map(|l| {
            let f: Vec<f64> = l.split_whitespace().skip(1).filter_map(|v| v.parse().ok()).collect();
            ((f[0] - 32.5).abs() < 1.0 && (f[2] - 32.5).abs() < 1.0).then_some(f[1])
        })
        .fold(f64::INFINITY, f64::min);
    assert!((lowest - 10.0).abs() < 0.5, "{lowest}");
}

#[test]
fn scene_bench_reports_both_levels_of_detail() {
    let dir = tempfile::tempdir().expect("dir");
    let n = 4u64;
    let out = penmodel(
        dir.path(),
        &[
            "trees", "scene", "--trees", "4", "--bench", "--frames", "1", "--width", "160", "--height", "90", "--json",
        ],
    );
    ok(&out);
    let v: Value = serde_json::from_slice(&out.stdout).expect("one JSON document on stdout");
    for key in [
        "frame_ms_full",
        "frame_ms_lod",
        "frame_ms_lod_stereo",
        "polygons_full",
        "polygons_lod",
        "image_difference",
        "image_metric",
    ] {
        assert!(v.get(key).is_some(), "{key} missing: {v}");
    }
    for key in ["frame_ms_full", "frame_ms_lod", "frame_ms_lod_stereo"] {
        assert!(v[key].as_f64().expect(key) > 0.0, "{key}: {v}");
    }
    // Every tree in full is its species' whole node tree: Samples 3.1 and 3.2 in turn.
    let whole = |p| penmodel_terrain::trees::NodeTree::build(&Species::preset(p)).polygons();
    let full = v["polygons_full"].as_u64().expect("polygons_full");
    assert_eq!(full, n / 2 * (whole(Preset::Table31) + whole(Preset::Sample32)));
    let lod = v["polygons_lod"].as_u64().expect("polygons_lod");
    assert!(lod > 0 && lod < full, "{lod} of {full}");
    let mad = v["image_difference"]["mean_abs"].as_f64().expect("mean_abs");
    assert!((0.0..=255.0).contains(&mad), "{mad}");
    assert!(v["image_difference"]["psnr_db"].as_f64().expect("psnr") > 0.0);
    assert!(v["image_metric"].as_str().expect("metric").contains("PSNR"));
    // Without --bench: untimed, and the summary is readable text.
    let out = penmodel(
        dir.path(),
        &["trees", "scene", "--trees", "2", "--width", "64", "--height", "36"],
    );
    ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("2 Table 3.1 trees") && text.contains("untimed"), "{text}");
    // Bad input names the flag.
    let out = penmodel(dir.path(), &["trees", "scene", "--trees", "0"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--trees"));
}

#[test]
fn scene_bench_turning_times_a_moving_view_and_keeps_the_still_pictures() {
    let dir = tempfile::tempdir().expect("dir");
    let run = |turn: &str, png: &str| {
        let out = penmodel(
            dir.path(),
            &[
                "trees", "scene", "--trees", "4", "--bench", "--frames", "2", "--width", "160", "--height", "90",
                "--turn", turn, "--png", png, "--json",
            ],
        );
        ok(&out);
        serde_json::from_slice::<Value>(&out.stdout).expect("one JSON document on stdout")
    };
    let still = run("0", "still");
    let turning = run("-2.5", "turning");
    assert_eq!(still["turn_deg_per_frame"].as_f64(), Some(0.0), "{still}");
    assert_eq!(turning["turn_deg_per_frame"].as_f64(), Some(-2.5), "{turning}");
    assert!(turning["frame_ms_lod"].as_f64().expect("frame_ms_lod") > 0.0);
    // The timed frames turn, but the pictures and their difference are the still view's.
    assert_eq!(still["image_difference"], turning["image_difference"]);
    for name in ["full.png", "lod.png", "stereo.png"] {
        let a = std::fs::read(dir.path().join("still").join(name)).expect("still picture");
        let b = std::fs::read(dir.path().join("turning").join(name)).expect("turning picture");
        assert!(a == b, "{name} differs after turning");
    }
    // A turn that is not a number of degrees from -10 to 10 is refused, naming the flag.
    for bad in ["11", "nan", "inf", "x"] {
        let out = penmodel(dir.path(), &["trees", "scene", "--bench", "--turn", bad]);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{bad}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("--turn"), "{bad}");
    }
}

#[test]
fn fit_refuses_a_dot_a_line_and_a_filled_square() {
    // Issue 47: a solid square ran 400 s, a line fitted maps `trees stats` refuses, a single
    // pixel "fitted" at 0.85 into a 568,000-polygon tree.
    let dir = tempfile::tempdir().expect("dir");
    let s = Species::preset(Preset::Cypress);
    let side = silhouette::render(&s, View::Side, 64, 0.02);
    let file = std::fs::File::create(dir.path().join("side.png")).expect("created");
    side.write_png(std::io::BufWriter::new(file)).expect("written");
    let mut cases = Vec::new();
    let mut dot = silhouette::Image::new(32, 32);
    dot.data[16 * 32 + 16] = 1.0;
    cases.push(("dot.png", dot, "the front silhouette is a single pixel"));
    let mut line = silhouette::Image::new(32, 32);
    for r in 2..30 {
        line.data[r * 32 + 16] = 1.0;
    }
    cases.push((
        "line.png",
        line,
        "the front silhouette is a line (1 × 28 pixels covered)",
    ));
    let mut square = silhouette::Image::new(32, 32);
    for r in 4..28 {
        for c in 4..28 {
            square.data[r * 32 + c] = 1.0;
        }
    }
    cases.push((
        "square.png",
        square,
        "the front silhouette is a filled rectangle (24 × 24 pixels",
    ));
    for (name, img, message) in cases {
        let file = std::fs::File::create(dir.path().join(name)).expect("created");
        img.write_png(std::io::BufWriter::new(file)).expect("written");
        let out = penmodel(dir.path(), &["trees", "fit", name, "side.png", "--json", "fit.json"]);
        failed_with(&out, message);
        assert!(!dir.path().join("fit.json").exists(), "{name}: nothing written");
    }
}

#[test]
fn mesh_refuses_a_time_or_wind_that_is_not_a_number() {
    // Issue 47: `--t nan` exited 0 with every vertex NaN (and an invalid glTF).
    let dir = tempfile::tempdir().expect("dir");
    for (args, message) in [
        (&["--wind", "1:1", "--t", "nan"][..], "--t: NaN is not a finite number"),
        (&["--wind", "1:1", "--t", "inf"][..], "--t: inf is not a finite number"),
        (
            &["--wind", "nan:1"][..],
            "--wind: \"nan:1\" is not AMPLITUDE:FREQUENCY[:REST] of finite numbers",
        ),
    ] {
        let mut all = vec!["trees", "mesh", "--obj", "t.obj"];
        all.extend_from_slice(args);
        failed_with(&penmodel(dir.path(), &all), message);
        assert!(!dir.path().join("t.obj").exists(), "{args:?}: nothing written");
    }
}
