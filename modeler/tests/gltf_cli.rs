//! `penmodel generate --glb` read by outside tools (issue 46): the Khronos glTF validator (npm
//! `gltf-validator`, installed into target/gltf-npm) finds no errors, and pygltflib (PyPI,
//! target/gltf-venv) reads the materials and the trees' instances back (`scripts/gltf_peer.py`).

use std::path::Path;
use std::process::Command;

use penmodel_terrain::editor::Editor;

use crate::common::outside_check;

/// A river (the omega example) with a rock field, a fir and a grove.
fn document(dir: &Path) -> std::path::PathBuf {
    let omega = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/rivers/omega.json");
    let text = std::fs::read_to_string(omega).expect("the example");
    let mut doc: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    doc["version"] = 4.into();
    doc["rocks"] = serde_json::json!([{"at": [20.0, 20.0],
        "outline": [[0.0, 0.0], [40.0, 0.0], [40.0, 30.0], [0.0, 30.0], [0.0, 0.0]],
        "cell_size": 0.5, "layers": [{"radius": 4.0, "fraction": 0.3}], "seed": 2}]);
    doc["trees"] = serde_json::json!([{"at": [150.5, 60.5], "height": 8.0, "preset": "fir"}]);
    doc["groves"] = serde_json::json!([{"region": [[120.0, 120.0], [160.0, 120.0], [160.0, 160.0],
        [120.0, 160.0], [120.0, 120.0]], "density": 100.0}]);
    let path = dir.join("d.json");
    std::fs::write(&path, doc.to_string()).expect("written");
    path
}

/// Skipped, saying so, only when node/npm or the packages cannot be had.
#[test]
fn glb_is_valid_for_the_khronos_validator_and_read_back_by_pygltflib() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = document(dir.path());
    let (editor, _) = Editor::open_read_only(&doc).expect("the document opens");
    let trees = editor.trees().trees().len();
    assert!(trees > 2, "{trees} trees");
    let trees = trees.to_string();
    outside_check(
        "glb_is_valid_for_the_khronos_validator",
        "gltf_peer.py",
        &[
            env!("CARGO_BIN_EXE_penmodel").as_ref(),
            doc.as_ref(),
            trees.as_ref(),
            "150.5,60.5".as_ref(),
        ],
    );
}

#[test]
fn bad_tree_detail_is_refused() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = document(dir.path());
    for q in ["0.01", "1.5", "x", "NaN"] {
        let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
            .args([
                "generate",
                doc.to_str().expect("utf-8"),
                "--glb",
                "o.glb",
                "--tree-detail",
                q,
            ])
            .current_dir(dir.path())
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{q}: {err}");
        assert!(err.contains("expected a roughness"), "{q}: {err}");
    }
}

#[test]
fn obj_follows_the_same_flags() {
    let dir = tempfile::tempdir().expect("dir");
    let doc = document(dir.path());
    let obj = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_penmodel"))
            .args(["generate", doc.to_str().expect("utf-8"), "--obj", "o.obj"])
            .args(extra)
            .current_dir(dir.path())
            .output()
            .expect("runs");
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::read_to_string(dir.path().join("o.obj")).expect("obj")
    };
    let objects = |text: &str| -> Vec<String> {
        text.lines()
            .filter_map(|l| l.strip_prefix("o "))
            .map(str::to_string)
            .collect()
    };
    let full = obj(&[]);
    assert_eq!(objects(&full), ["terrain", "rocks 0", "water", "trees"]);
    let coarse = obj(&["--tree-detail", "0.3"]);
    assert_eq!(objects(&coarse), objects(&full));
    assert!(coarse.len() < full.len(), "{} < {}", coarse.len(), full.len());
    assert_eq!(objects(&obj(&["--no-trees", "--no-rocks", "--no-water"])), ["terrain"]);
    assert_eq!(objects(&obj(&["--no-rocks"])), ["terrain", "water", "trees"]);
}
