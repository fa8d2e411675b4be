//! `penmodel generate` end to end: outputs, exit codes and messages.

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
    assert_eq!(penmodel(&[]).status.code(), Some(2));
    let help = penmodel(&["generate", "--help"]);
    assert!(help.status.success());
    assert!(String::from_utf8_lossy(&help.stdout).contains("--raw <OUT.f32>"));
}
