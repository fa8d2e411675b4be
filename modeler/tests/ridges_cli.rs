//! `penmodel analyze`, `penmodel ridges` and the ridgelines in `generate` and `render` end to
//! end: map sizes and values checked against the document's own numbers, errors naming the
//! flag or element.

use std::path::Path;

use serde_json::Value;

use crate::common::{example, penmodel};

fn floats(path: &Path) -> Vec<f32> {
    std::fs::read(path)
        .expect("map written")
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

#[test]
fn analyze_writes_every_map_with_the_grids_size() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &[
            "analyze",
            &example("ridges/ridgelines.json"),
            "--flow",
            "f.f32",
            "--ridges",
            "r.f32",
            "--valleys",
            "v.f32",
            "--sun",
            "135,25",
            "--direct",
            "d.f32",
            "--sky",
            "s.f32",
            "--sky-directions",
            "16",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = penmodel(
        dir.path(),
        &[
            "analyze",
            &example("ridges/ridgelines.json"),
            "--insolation",
            "i.f32",
            "--sun",
            "135,25",
            "--sky-directions",
            "16",
            "--flow",
            "f.png",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let n = 256 * 256;
    let flow = floats(&dir.path().join("f.f32"));
    assert_eq!(flow.len(), n);
    // One drop per cell: every count at least 1; the counts along the flow conserve drops, so
    // the largest is at most the number of cells.
    assert!(flow.iter().all(|&c| c >= 1.0 && c <= n as f32));
    let (ridges, valleys) = (floats(&dir.path().join("r.f32")), floats(&dir.path().join("v.f32")));
    for i in 0..n {
        assert!(ridges[i] == 0.0 || ridges[i] == 1.0);
        // Valley: 32 drops or more, gathered (a flank's long run alone is not valley).
        assert!(valleys[i] == 0.0 || (valleys[i] == 1.0 && flow[i] >= 32.0), "cell {i}");
        assert!(
            !(ridges[i] == 1.0 && flow[i] > 1.0),
            "cell {i}: a ridge passed by others' drops"
        );
    }
    let valley = valleys.iter().filter(|&&v| v == 1.0).count();
    let many = flow.iter().filter(|&&c| c >= 32.0).count();
    assert!(
        valley > 0 && valley < many,
        "{valley} valley cells of {many} passed by 32 drops or more"
    );
    let (d, s, ins) = (
        floats(&dir.path().join("d.f32")),
        floats(&dir.path().join("s.f32")),
        floats(&dir.path().join("i.f32")),
    );
    for i in 0..n {
        assert!((0.0..=1.0).contains(&d[i]) && (0.0..=1.0).contains(&s[i]));
        assert!((ins[i] - (0.8 * d[i] + 0.2 * s[i])).abs() < 1e-5, "cell {i}");
    }
    // Open flat ground far from the ridges: the sun's sine and the whole sky.
    assert!((d[0] - 25f32.to_radians().sin()).abs() < 1e-4, "corner {}", d[0]);
    assert!(d.contains(&0.0), "some cell is in shadow");
    assert!(dir.path().join("f.png").exists());
}

#[test]
fn analyze_refuses_a_sun_below_the_horizon_and_a_missing_sun() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &[
            "analyze",
            &example("ridges/ridgelines.json"),
            "--sun",
            "30,-2",
            "--direct",
            "d.f32",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--sun") && e.contains("horizon"), "{e}");
    let out = penmodel(
        dir.path(),
        &["analyze", &example("ridges/ridgelines.json"), "--direct", "d.f32"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--sun"));
}

#[test]
fn ridges_prints_elevations_and_grows_a_document_that_generates() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &["ridges", &example("ridges/ridgelines.json"), "--elevations", "--json"],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let nodes = json["trees"][0]["nodes"].as_array().expect("nodes");
    // The example's tree: node 1 is an end (5 m); node 6 joins ends 1 and 2 and the centre 0.
    let at = |i: usize, k: &str| nodes[i][k].as_f64().expect("number");
    assert_eq!(at(1, "elevation"), 5.0);
    let d6 = (200.0f64 - 150.0)
        .hypot(400.0 - 350.0)
        .min((200.0f64 - 120.0).hypot(400.0 - 440.0));
    assert!((at(6, "distance") - d6).abs() < 1e-9, "{}", at(6, "distance"));
    assert!((at(6, "elevation") - (5.0 + d6 * 25f64.to_radians().tan())).abs() < 1e-9);
    let out = penmodel(
        dir.path(),
        &[
            "ridges",
            &example("ridges/ridgelines.json"),
            "--grow",
            "1",
            "--seed",
            "3",
            "--out",
            "g.json",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let grown: Value = serde_json::from_slice(&std::fs::read(dir.path().join("g.json")).expect("saved")).expect("JSON");
    assert!(grown["ridges"]["lines"].as_array().expect("lines").len() > 1);
    // The example's 35° and a round's 5°.
    assert_eq!(grown["ridges"]["slope"].as_f64(), Some(40.0));
    let out = penmodel(dir.path(), &["generate", "g.json", "--raw", "g.f32"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = penmodel(
        dir.path(),
        &["generate", &example("ridges/ridgelines.json"), "--raw", "e.f32"],
    );
    assert!(out.status.success());
    // The ridgelines are in the export: the example's top is its ridgeline's (140 m), filtered.
    let top = floats(&dir.path().join("e.f32")).into_iter().fold(0.0f32, f32::max);
    assert!(top > 130.0 && top <= 140.0, "top {top}");
    let out = penmodel(
        dir.path(),
        &[
            "render",
            &example("ridges/ridgelines.json"),
            "--png",
            "f.png",
            "--size",
            "160x100",
            "--sun",
            "135,25",
            "--areas",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}
