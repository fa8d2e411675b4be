//! `penmodel rocks` end to end: its outputs, the JSON of docs/rocks.md, the same rocks for the
//! same seed, flags named in errors, and the examples of its --help.

use std::path::Path;

use serde_json::Value;

use crate::common::penmodel;

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn rocks_writes_json_meshes_and_a_top_view() {
    let dir = tempfile::tempdir().expect("dir");
    let args = [
        "rocks",
        "--size",
        "96x64",
        "--radii",
        "6,2",
        "--fractions",
        "0.3,0.4",
        "--seed",
        "5",
        "--json",
        "f.json",
        "--obj",
        "f.obj",
        "--glb",
        "f.glb",
        "--png",
        "f.png",
    ];
    let out = penmodel(dir.path(), &args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.starts_with("96 × 64 cells: "), "{stdout}");
    let json: Value = serde_json::from_slice(&std::fs::read(dir.path().join("f.json")).expect("json")).expect("JSON");
    assert_eq!(json["size"], serde_json::json!([96, 64]));
    let diagrams = json["diagrams"].as_array().expect("diagrams");
    assert_eq!(diagrams.len(), 2);
    assert_eq!(diagrams[0]["radius"], 6.0);
    let rocks = json["rocks"].as_array().expect("rocks");
    let kept: u64 = diagrams.iter().map(|d| d["cells_kept"].as_u64().expect("count")).sum();
    assert_eq!(rocks.len() as u64, kept);
    let mut vertex_total = 0;
    for r in rocks {
        let k = r["polygon"].as_array().expect("polygon").len();
        assert_eq!(r["added"].as_array().expect("added").len(), k);
        assert_eq!(r["moved"].as_array().expect("moved").len(), k);
        let n = r["vertices"].as_array().expect("vertices").len();
        assert_eq!(n, 2 * k);
        vertex_total += n;
        for t in r["triangles"].as_array().expect("triangles") {
            assert!(
                t.as_array()
                    .expect("triangle")
                    .iter()
                    .all(|i| (i.as_u64().expect("index") as usize) < n)
            );
        }
    }
    for stage in ["seeds_and_diagrams", "selection", "polygons", "meshes", "total"] {
        assert!(json["timing_ms"][stage].as_f64().is_some(), "timing_ms.{stage}");
    }
    // The OBJ has every rock vertex; the glTF and PNG have their signatures.
    let obj = std::fs::read_to_string(dir.path().join("f.obj")).expect("obj");
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), vertex_total);
    assert_eq!(&std::fs::read(dir.path().join("f.glb")).expect("glb")[..4], b"glTF");
    assert_eq!(&std::fs::read(dir.path().join("f.png")).expect("png")[1..4], b"PNG");
}

#[test]
fn the_same_seed_gives_the_same_rocks() {
    let dir = tempfile::tempdir().expect("dir");
    let run = |seed: &str| {
        let out = penmodel(dir.path(), &["rocks", "--size", "80x80", "--seed", seed, "--json", "-"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        let mut v: Value = serde_json::from_slice(&out.stdout).expect("one JSON document on stdout");
        v["timing_ms"] = Value::Null;
        v
    };
    assert_eq!(run("3"), run("3"));
    assert_ne!(run("3")["rocks"], run("4")["rocks"]);
}

#[test]
fn bad_flags_are_named() {
    let dir = tempfile::tempdir().expect("dir");
    for (args, status, words) in [
        (
            &["--radii", "0,3", "--fractions", "0.2,0.2"][..],
            1,
            "--radii: the 1st radius, 0, must be above 0",
        ),
        (
            &["--radii", "9,3", "--fractions", "0.6,0.5"],
            1,
            "--fractions: they add up to 1.1",
        ),
        (&["--radii", "9,3"], 1, "--fractions or --counts"),
        (
            &["--size", "64x64", "--radii", "65", "--counts", "3"],
            1,
            "--radii: the 1st radius, 65, is larger",
        ),
        (
            &["--radii", "9", "--counts", "3,4"],
            1,
            "--counts: give one count per radius",
        ),
        (&["--heights", "-1,0,0"], 1, "--heights: c_h1 = -1 must be from 0 to 10"),
        (&["--size", "12"], 2, "WIDTHxHEIGHT"),
        (&["--radii", "x"], 2, "--radii"),
    ] {
        let mut all = vec!["rocks"];
        all.extend_from_slice(args);
        let out = penmodel(dir.path(), &all);
        assert_eq!(out.status.code(), Some(status), "{all:?}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains(words), "{all:?}: {}", text(&out.stderr));
        assert!(
            std::fs::read_dir(dir.path()).expect("dir").next().is_none(),
            "{all:?} wrote a file"
        );
    }
}

#[test]
fn the_help_examples_run() {
    let dir = tempfile::tempdir().expect("dir");
    let help = text(&penmodel(dir.path(), &["rocks", "--help"]).stdout);
    let examples: Vec<Vec<&str>> = help
        .lines()
        .filter_map(|l| l.trim().strip_prefix("penmodel "))
        .map(|l| l.split('#').next().unwrap_or_default().split_whitespace().collect())
        .collect();
    assert!(examples.len() >= 3, "{help}");
    for e in examples {
        let out = penmodel(dir.path(), &e);
        assert!(out.status.success(), "{e:?}: {}", text(&out.stderr));
    }
}

#[test]
fn generate_puts_a_documents_rocks_into_the_meshes() {
    let dir = tempfile::tempdir().expect("dir");
    let volcano = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/04-volcano.json"))
        .expect("example");
    let field = r#""rocks": [{"at": [120.0, 110.0], "outline": [[0.0, 0.0], [80.0, 0.0], [80.0, 60.0], [0.0, 60.0], [0.0, 0.0]],
        "cell_size": 0.5, "layers": [{"radius": 8.0, "fraction": 0.3}, {"radius": 3.0, "fraction": 0.3}], "seed": 2}]"#;
    let end = volcano.rfind('}').expect("an object");
    let doc = format!("{},\n{field}\n}}\n", volcano[..end].trim_end()).replace("\"version\": 1", "\"version\": 2");
    std::fs::write(dir.path().join("d.json"), doc).expect("write");
    let out = penmodel(dir.path(), &["generate", "d.json", "--obj", "d.obj", "--glb", "d.glb"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let obj = std::fs::read_to_string(dir.path().join("d.obj")).expect("obj");
    let objects: Vec<&str> = obj.lines().filter(|l| l.starts_with("o ")).collect();
    assert_eq!(objects, ["o terrain", "o rocks 0"]);
    let vertices = obj.lines().filter(|l| l.starts_with("v ")).count();
    assert!(vertices > 160 * 160 + 1000, "{vertices} vertices");
    // The rocks stand on the cone: their heights are above 0.
    let rock_heights: Vec<f64> = obj
        .lines()
        .skip_while(|l| *l != "o rocks 0")
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split(' ').nth(1).expect("y").parse().expect("number"))
        .collect();
    assert!(rock_heights.iter().all(|&h| h > 0.0), "a rock below the ground");
    let glb = std::fs::read(dir.path().join("d.glb")).expect("glb");
    assert!(String::from_utf8_lossy(&glb).contains("\"name\":\"rocks 0\""));
}

#[test]
fn generate_names_a_bad_rock_field() {
    let dir = tempfile::tempdir().expect("dir");
    let volcano = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/04-volcano.json"))
        .expect("example");
    let end = volcano.rfind('}').expect("an object");
    for (layers, words) in [
        (
            r#"[{"radius": 0.0, "fraction": 0.3}]"#,
            "rocks[0].layers[0].radius: 0 must be above 0",
        ),
        (
            r#"[{"radius": 8.0, "fraction": 0.7}, {"radius": 3.0, "fraction": 0.4}]"#,
            "rocks[0].layers: the fractions add up to 1.1",
        ),
        (
            r#"[{"radius": 500.0, "count": 3}]"#,
            "rocks[0].layers[0].radius: 500 cells leaves no room",
        ),
    ] {
        let field = format!(
            r#""rocks": [{{"at": [120.0, 110.0], "outline": [[0.0, 0.0], [80.0, 0.0], [80.0, 60.0], [0.0, 0.0]], "cell_size": 0.5, "layers": {layers}}}]"#
        );
        let doc = format!("{},\n{field}\n}}\n", volcano[..end].trim_end()).replace("\"version\": 1", "\"version\": 2");
        std::fs::write(dir.path().join("d.json"), doc).expect("write");
        let out = penmodel(dir.path(), &["generate", "d.json", "--obj", "d.obj"]);
        assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
        assert!(text(&out.stderr).contains(words), "{}", text(&out.stderr));
        assert!(!dir.path().join("d.obj").exists());
    }
}

/// Issue 41: the `fig1` preset gave table 1's rows by list position, so `--radii 1,3,9` gave
/// r = 1 the r = 9 coefficients. Each radius takes its own row, in any order.
#[test]
fn the_fig1_preset_goes_by_radius_not_by_position() {
    let dir = tempfile::tempdir().expect("dir");
    let shapes = |radii: &str, fractions: &str| {
        let out = penmodel(
            dir.path(),
            &[
                "rocks",
                "--size",
                "64x64",
                "--radii",
                radii,
                "--fractions",
                fractions,
                "--json",
                "-",
            ],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        let v: Value = serde_json::from_slice(&out.stdout).expect("JSON");
        let mut by_radius: Vec<(f64, Value)> = v["diagrams"]
            .as_array()
            .expect("diagrams")
            .iter()
            .map(|d| (d["radius"].as_f64().expect("radius"), d["shape"].clone()))
            .collect();
        by_radius.sort_by(|a, b| a.0.total_cmp(&b.0));
        by_radius
    };
    let listed_large_first = shapes("9,3,1", "0.2,0.24,0.3");
    assert_eq!(shapes("1,3,9", "0.3,0.24,0.2"), listed_large_first);
    // Table 1's row for r = 1: c_w 0.1, 0.1, 0.1.
    assert_eq!(listed_large_first[0].1["widths"], serde_json::json!([0.1, 0.1, 0.1]));
}

/// Issue 41: a fraction the cells cannot reach ended with exit 0 and only `reached: false`;
/// it is a warning, and an error (exit 1, the outputs written) under `--strict`.
#[test]
fn an_unreachable_fraction_warns_and_fails_under_strict() {
    let dir = tempfile::tempdir().expect("dir");
    let args = [
        "rocks",
        "--size",
        "64x64",
        "--radii",
        "9,1",
        "--fractions",
        "0.2,0.8",
        "--json",
        "r.json",
    ];
    let out = penmodel(dir.path(), &args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let err = text(&out.stderr);
    assert!(err.contains("warning: r 1: ") && err.contains("80.0 % asked"), "{err}");
    let strict = penmodel(dir.path(), &[&args[..], &["--strict"]].concat());
    assert_eq!(strict.status.code(), Some(1), "{}", text(&strict.stderr));
    assert!(
        text(&strict.stderr).contains("--strict: r 1: "),
        "{}",
        text(&strict.stderr)
    );
    assert!(dir.path().join("r.json").exists(), "the outputs are written first");
    // A reachable one says nothing.
    let fine = penmodel(
        dir.path(),
        &[
            "rocks",
            "--size",
            "64x64",
            "--radii",
            "9,1",
            "--fractions",
            "0.2,0.3",
            "--strict",
        ],
    );
    assert!(
        fine.status.success() && !text(&fine.stderr).contains("warning"),
        "{}",
        text(&fine.stderr)
    );
}
