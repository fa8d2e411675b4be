//! `penmodel river` and the rivers in `penmodel generate` end to end: the masks and JSON of
//! docs/rivers.md, the water mesh, errors naming the flag, and the examples of its --help.

use std::path::PathBuf;

use serde_json::Value;

use crate::common::{example, penmodel};

#[test]
fn river_writes_masks_preview_and_json() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &[
            "river",
            &example("rivers/omega.json"),
            "--masks",
            "m",
            "--json",
            "r.json",
            "--morph",
            "3",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: Value = serde_json::from_slice(&std::fs::read(dir.path().join("r.json")).expect("json")).expect("parses");
    let iterations = json["iterations"].as_array().expect("iterations");
    assert_eq!(iterations.len(), 5, "the example's 5 iterations");
    for k in 0..=5 {
        assert!(dir.path().join(format!("m/mask-{k}.png")).exists(), "mask-{k}.png");
    }
    for name in ["preview.png", "morph-mask.png", "morph-dilate.png", "morph-erode.png"] {
        assert!(dir.path().join("m").join(name).exists(), "{name}");
    }
    // The Ω's neck closes: an oxbow lake, counted with its area.
    let oxbows: u64 = iterations
        .iter()
        .map(|it| it["oxbows"]["count"].as_u64().expect("count"))
        .sum();
    assert!(oxbows >= 1);
    let last = iterations.last().expect("one");
    assert!(last["lakes"].as_u64() >= Some(1) && last["lake_area"].as_u64() > Some(0));
    // Per sample: position, curvature, side, level; a straight leg has curvature ~0 and level 1.
    let samples = json["samples"].as_array().expect("samples");
    assert!(samples.len() > 300);
    let first = &samples[0];
    assert!(first["curvature"].as_f64().expect("κ") < 1e-6);
    assert_eq!(first["level"], 1);
    assert!(
        samples
            .iter()
            .all(|s| (1..=6).contains(&s["level"].as_u64().expect("level")))
    );
    // Masks are the window's size.
    let (w, h) = (
        json["window"]["width"].as_u64().expect("w"),
        json["window"]["height"].as_u64().expect("h"),
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path().join("m/mask-0.png")).expect("png"),
    ));
    let info = decoder.read_info().expect("png");
    assert_eq!((u64::from(info.info().width), u64::from(info.info().height)), (w, h));
}

#[test]
fn river_errors_name_the_flag() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(dir.path(), &["river", &example("rivers/omega.json"), "--index", "3"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--index 3"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = penmodel(
        dir.path(),
        &["river", &example("rivers/omega.json"), "--iterations", "21"],
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("--iterations 21"));
}

#[test]
fn generate_writes_the_water_as_its_own_mesh() {
    let dir = tempfile::tempdir().expect("dir");
    let out = penmodel(
        dir.path(),
        &[
            "generate",
            &example("rivers/omega.json"),
            "--obj",
            "t.obj",
            "--raw",
            "t.f32",
            "--glb",
            "t.glb",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The glTF's JSON chunk names a node and a mesh "water" beside the terrain's.
    let glb = std::fs::read(dir.path().join("t.glb")).expect("glb");
    let json_len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    let gltf: Value = serde_json::from_slice(&glb[20..20 + json_len]).expect("the JSON chunk");
    let names = |key: &str| -> Vec<String> {
        gltf[key]
            .as_array()
            .expect(key)
            .iter()
            .filter_map(|n| n["name"].as_str().map(str::to_string))
            .collect()
    };
    assert!(names("nodes").contains(&"water".to_string()), "{:?}", names("nodes"));
    assert!(names("meshes").contains(&"water".to_string()), "{:?}", names("meshes"));
    let obj = std::fs::read_to_string(dir.path().join("t.obj")).expect("obj");
    let objects: Vec<&str> = obj.lines().filter(|l| l.starts_with("o ")).collect();
    assert_eq!(objects, ["o terrain", "o water"]);
    // Water vertices stand above the carved terrain under them.
    let raw = std::fs::read(dir.path().join("t.f32")).expect("raw");
    let heights: Vec<f32> = raw
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let water = &obj[obj.find("o water").expect("water")..];
    let vertices: Vec<Vec<f32>> = water
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| l[2..].split_whitespace().map(|x| x.parse().expect("number")).collect())
        .collect();
    assert!(
        !vertices.is_empty() && vertices.len().is_multiple_of(4),
        "a square of 4 vertices per wet cell"
    );
    // A square's first vertex is its cell's corner (x = c, z = r on 1 m cells): the water stands
    // above the carved bed there.
    for v in vertices.chunks_exact(4).map(|q| &q[0]) {
        let (c, r) = (v[0].round() as usize, v[2].round() as usize);
        assert!(v[1] > heights[r * 200 + c], "dry water at ({c}, {r})");
    }
    let carved_below = heights.iter().filter(|&&h| h < 0.5).count();
    assert!(carved_below > 0, "the river is carved into the 2 m plain");
}

#[test]
fn river_help_examples_run() {
    let dir = tempfile::tempdir().expect("dir");
    let help = penmodel(dir.path(), &["river", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout).into_owned();
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("repository")
        .to_owned();
    let mut ran = 0;
    for line in help.lines().map(str::trim).filter_map(|l| l.strip_prefix("penmodel ")) {
        let args: Vec<String> = line
            .split('#')
            .next()
            .unwrap_or_default()
            .split_whitespace()
            .map(|a| {
                if a.starts_with("modeler/") {
                    repo.join(a).display().to_string()
                } else {
                    a.to_string()
                }
            })
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = penmodel(dir.path(), &args);
        assert!(
            out.status.success(),
            "penmodel {line}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        ran += 1;
    }
    assert_eq!(ran, 3);
}
