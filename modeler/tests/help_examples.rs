//! The examples `penmodel generate --help` and `penmodel render --help` give run as printed
//! (issue 19.7: one named a file that was not there), and generate's outputs are each optional.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn penmodel(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir)
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("penmodel runs")
}

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
    let written: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(written, ["only.png"]);

    let out = penmodel(dir.path(), &["generate", doc]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--raw <OUT.f32>|--png <OUT.png>|--obj <OUT.obj>|--glb <OUT.glb>"),
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
