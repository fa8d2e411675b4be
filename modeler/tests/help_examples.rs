//! The examples `penmodel generate --help` and `penmodel render --help` give run as printed
//! (issue 19.7: one named a file that was not there), and generate's outputs are each optional.

use std::path::{Path, PathBuf};

use crate::common::penmodel;

/// The repository's folder, where the examples are run from.
fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the modeler is in the repository")
        .to_owned()
}

/// The `penmodel …` lines of a help text's examples, as arguments (no quoting in them).
fn examples(help: &str) -> Vec<Vec<String>> {
    help.lines()
        .map(str::trim)
        .filter_map(|l| l.strip_prefix("penmodel "))
        .map(|l| {
            let command = l.split('#').next().unwrap_or_default();
            command.split_whitespace().map(str::to_string).collect()
        })
        .collect()
}

/// Each example of `penmodel SUBCOMMAND --help` runs and succeeds: the documents it names are
/// the repository's (the paths taken from there), the files it writes go to a temporary folder.
fn examples_run(subcommand: &str) {
    let dir = tempfile::tempdir().expect("dir");
    let help = penmodel(dir.path(), &[subcommand, "--help"]);
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout).into_owned();
    let examples = examples(&help);
    assert!(!examples.is_empty(), "no examples in:\n{help}");
    for example in examples {
        assert_eq!(example[0], subcommand, "{example:?}");
        let args: Vec<String> = example
            .iter()
            .map(|a| {
                let in_repository = repository().join(a);
                if a.starts_with("modeler/") {
                    assert!(
                        in_repository.exists(),
                        "{a}, named in `{subcommand} --help`, is not there"
                    );
                    in_repository.display().to_string()
                } else {
                    a.clone()
                }
            })
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = penmodel(dir.path(), &args);
        assert!(
            out.status.success(),
            "penmodel {}: {}",
            example.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn generate_help_examples_run() {
    examples_run("generate");
}

#[test]
fn generate_writes_only_the_outputs_asked_for_and_needs_one() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = repository().join("modeler/examples/02-twin-hills.json");
    let doc = doc.to_str().expect("UTF-8 path");
    let out = penmodel(dir.path(), &["generate", doc, "--png", "only.png"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut written: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    written.sort();
    // The PNG and its sidecar (issue 46), nothing else.
    assert_eq!(written, ["only.png", "only.png.json"]);

    let out = penmodel(dir.path(), &["generate", doc]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(
            "--raw <OUT.f32>|--png <OUT.png>|--raw16 <OUT.r16>|--geotiff <OUT.tif>|--obj <OUT.obj>|--glb <OUT.glb>"
        ),
        "{err}"
    );
}

#[test]
fn an_os_error_is_said_once() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = repository().join("modeler/examples/02-twin-hills.json");
    let doc = doc.to_str().expect("UTF-8 path");
    for args in [
        ["render", doc, "--png", "missing/x.png"],
        ["generate", doc, "--png", "missing/x.png"],
    ] {
        let out = penmodel(dir.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(
            err, "penmodel: cannot write missing/x.png: No such file or directory (os error 2)\n",
            "{args:?}"
        );
    }
}

#[test]
fn render_help_examples_run() {
    examples_run("render");
}

/// The PNG `penmodel render` writes for `args` (after the document and `--png`).
fn render(dir: &Path, name: &str, args: &[&str]) -> Vec<u8> {
    let doc = repository().join("modeler/examples/04-volcano.json");
    let png = dir.join(name);
    let out = penmodel(
        dir,
        &[
            &[
                "render",
                doc.to_str().expect("UTF-8"),
                "--png",
                png.to_str().expect("UTF-8"),
                "--size",
                "160x90",
            ],
            args,
        ]
        .concat(),
    );
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read(&png).expect("the PNG")
}

#[test]
fn sizes_on_the_display_are_millimetres_and_the_earlier_metres_still_read() {
    let dir = tempfile::tempdir().expect("dir");
    let mm = render(
        dir.path(),
        "mm.png",
        &["--display-mm", "600x340", "--head-mm", "0,-150,500"],
    );
    let m = render(dir.path(), "m.png", &["--display", "0.6x0.34", "--head", "0,-0.15,0.5"]);
    assert_eq!(mm, m, "the same view in either unit");
    let orbit = render(dir.path(), "orbit.png", &[]);
    assert_ne!(mm, orbit, "the tracked view is not the orbit camera's");

    let scaled = render(dir.path(), "v.png", &["--vertical-scale", "3"]);
    let aliased = render(dir.path(), "e.png", &["--exaggeration", "3"]);
    assert_eq!(scaled, aliased);
    assert_ne!(scaled, orbit, "the vertical scale changes the picture");
}

#[test]
fn the_shared_flags_refuse_bad_values_as_usage_errors() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = repository().join("modeler/examples/04-volcano.json");
    let doc = doc.to_str().expect("UTF-8");
    let cases: [(&[&str], &str); 9] = [
        (
            &["--show", "headless", "--source", "serial:/dev/x", "--speed", "2"],
            "--speed is the simulated pen's",
        ),
        (
            &["--show", "headless", "--source", "daemon", "--speed", "0"],
            "daemon runs in real time",
        ),
        (&["--vertical-scale", "0"], "is not a vertical scale"),
        (&["--exaggeration", "-2"], "is not a vertical scale"),
        (&["--speed", "-1"], "is not a speed"),
        (&["--head-mm", "1,2"], "expected X,Y,Z in mm"),
        (
            &["render", doc, "--png", "x.png", "--display-mm", "600x340"],
            "--head-mm",
        ),
        (
            &[
                "render",
                doc,
                "--png",
                "x.png",
                "--display-mm",
                "0.6",
                "--head-mm",
                "0,0,500",
            ],
            "in mm",
        ),
        (
            &["render", doc, "--png", "x.png", "--vertical-scale", "nan"],
            "is not a vertical scale",
        ),
    ];
    for (args, says) in cases {
        let out = penmodel(dir.path(), args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert_eq!(
            std::fs::read_dir(dir.path()).expect("dir").count(),
            0,
            "{args:?} wrote something"
        );
    }
    // The earlier spelling is read: the session starts and fails only for want of pend.
    let out = penmodel(
        dir.path(),
        &[
            "--show",
            "headless",
            "--exaggeration",
            "2",
            "--source",
            "daemon:nothing.sock",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("pend is not running"), "{err}");
}
