//! docs/architecture.md against the code: the dependency arrows it lists are exactly those
//! `cargo metadata` reports, nothing depends on the HIL harness, every file it names exists, and
//! no crate has an import cycle between its modules, in its library or a binary's modules (their
//! unit tests aside).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn doc() -> String {
    std::fs::read_to_string(root().join("docs/architecture.md")).expect("docs/architecture.md is readable")
}

/// A package of this repository as its manifest declares it.
struct Package {
    name: String,
    dir: PathBuf,
    /// Dependencies on other packages of ours: (name, kind: normal, build or dev).
    deps: Vec<(String, String)>,
}

/// The workspace's packages (`--no-deps`: as declared, no resolution, no download).
fn packages(manifest: &Path) -> Vec<Package> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--no-deps", "--manifest-path"])
        .arg(manifest)
        .output()
        .expect("cargo metadata runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON");
    let mut list = Vec::new();
    for p in meta["packages"].as_array().expect("packages") {
        let name = p["name"].as_str().expect("a name").to_string();
        let dir = PathBuf::from(p["manifest_path"].as_str().expect("a manifest"))
            .parent()
            .expect("a folder")
            .to_path_buf();
        let deps = p["dependencies"]
            .as_array()
            .expect("dependencies")
            .iter()
            // Only path dependencies: the crates of this repository.
            .filter(|d| d["path"].is_string())
            .map(|d| {
                let kind = d["kind"].as_str().unwrap_or("normal").to_string();
                (d["name"].as_str().expect("a name").to_string(), kind)
            })
            .collect();
        list.push(Package { name, dir, deps });
    }
    list
}

fn all_packages() -> Vec<Package> {
    let mut list = packages(&root().join("Cargo.toml"));
    list.extend(packages(&root().join("firmware/Cargo.toml")));
    list.extend(packages(&root().join("hil-tests/rig/Cargo.toml")));
    list
}

/// The arrows of the ```arrows block: `a → b, c` says a depends on b and c.
fn documented_arrows() -> BTreeSet<(String, String)> {
    let text = doc();
    let block = text
        .split("```arrows\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("docs/architecture.md has an ```arrows block");
    let mut arrows = BTreeSet::new();
    for line in block.lines().filter(|l| !l.trim().is_empty()) {
        let (from, to) = line.split_once('→').expect("a line `crate → crate, crate`");
        // `pen-sim (feature sim, on by default)`: notes in brackets are for the reader.
        let mut names = String::new();
        let mut depth = 0;
        for c in to.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                c if depth == 0 => names.push(c),
                _ => {}
            }
        }
        for t in names.split(',') {
            arrows.insert((from.trim().to_string(), t.trim().to_string()));
        }
    }
    arrows
}

#[test]
fn the_documented_arrows_are_the_real_ones() {
    let real: BTreeSet<(String, String)> = all_packages()
        .into_iter()
        .flat_map(|p| {
            let name = p.name;
            p.deps
                .into_iter()
                .filter(|(_, kind)| kind == "normal" || kind == "build")
                .map(move |(d, _)| (name.clone(), d))
        })
        .collect();
    let documented = documented_arrows();
    let missing: Vec<_> = real.difference(&documented).collect();
    let stale: Vec<_> = documented.difference(&real).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "docs/architecture.md's arrows differ from Cargo.toml: not documented {missing:?}, documented but not real {stale:?}"
    );
}

#[test]
fn nothing_depends_on_the_hil_harness() {
    for p in all_packages() {
        assert!(
            p.deps.iter().all(|(d, _)| d != "pen-hil"),
            "{} depends on pen-hil, the test harness",
            p.name
        );
    }
}

#[test]
fn every_file_the_architecture_names_exists() {
    let text = doc();
    let mut named = 0;
    for (i, chunk) in text.split('`').enumerate() {
        // Odd chunks are inside backticks; a path has a slash and no spaces.
        let looks_like_path = i % 2 == 1 && chunk.contains('/') && !chunk.contains(' ') && !chunk.contains("://");
        if looks_like_path && (chunk.ends_with(".rs") || chunk.ends_with('/') || chunk.ends_with(".md")) {
            named += 1;
            assert!(
                root().join(chunk).exists(),
                "docs/architecture.md names {chunk}, which does not exist"
            );
        }
    }
    assert!(named > 40, "only {named} paths found: the parsing broke");
}

/// Top-level modules of a crate's `src/` (a file `x.rs` or a folder `x/`), and for each the
/// other top-level modules it names through `crate::` (or `super::` from a file directly in
/// `src/`).
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    fn files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                files(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut list = Vec::new();
    files(src, &mut list);
    let top = |p: &Path| -> Option<String> {
        let rel = p.strip_prefix(src).ok()?;
        let first = rel.components().next()?.as_os_str().to_str()?;
        let name = first.trim_end_matches(".rs");
        // The crate root and binaries are not modules of the library.
        (!matches!(name, "lib" | "main" | "bin")).then(|| name.to_string())
    };
    let modules: BTreeSet<String> = list.iter().filter_map(|p| top(p)).collect();
    let mut graph: BTreeMap<String, BTreeSet<String>> = modules.iter().map(|m| (m.clone(), BTreeSet::new())).collect();
    for p in &list {
        let Some(from) = top(p) else { continue };
        let directly_in_src = p.parent() == Some(src);
        let text = std::fs::read_to_string(p).expect("readable source");
        // A module's unit tests may reach a sibling to check a round trip; that is no part of
        // the crate's structure.
        let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
        let code: String = text
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        let mut prefixes = vec!["crate::"];
        if directly_in_src {
            prefixes.push("super::");
        }
        for prefix in prefixes {
            for (at, _) in code.match_indices(prefix) {
                for n in first_segments(&code[at + prefix.len()..]) {
                    if n != from && modules.contains(n) {
                        graph.entry(from.clone()).or_default().insert(n.to_string());
                    }
                }
            }
        }
    }
    graph
}

/// The first segments of the path(s) at the start of `rest`: `a::X` gives `a`; a group
/// `{a::{X, Y}, b}` gives `a` and `b` (commas at the group's top level only).
fn first_segments(rest: &str) -> Vec<&str> {
    let ident = |s: &str| -> usize { s.find(|c: char| !(c.is_alphanumeric() || c == '_')).unwrap_or(s.len()) };
    let Some(group) = rest.strip_prefix('{') else {
        return vec![&rest[..ident(rest)]];
    };
    let mut names = Vec::new();
    let (mut depth, mut start) = (0usize, 0usize);
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                names.push(group[start..i].trim());
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                names.push(group[start..i].trim());
                start = i + 1;
            }
            _ => {}
        }
    }
    names.into_iter().map(|n| &n[..ident(n)]).collect()
}

/// A cycle in `graph`, if there is one.
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        stack.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m.as_str()) {
                Some(1) => {
                    let start = stack.iter().position(|s| s == m).unwrap_or(0);
                    let mut cycle = stack[start..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(m, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if !state.contains_key(n.as_str()) {
            let mut stack = Vec::new();
            if let Some(c) = visit(n, graph, &mut state, &mut stack) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    g.entry("c".into()).or_default().insert("a".into());
    assert_eq!(
        find_cycle(&g),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
    g.get_mut("c").expect("c").clear();
    assert_eq!(find_cycle(&g), None);
    assert_eq!(first_segments("document::{Figure, Point};"), vec!["document"]);
    assert_eq!(
        first_segments("{cells::{self, Mask},\n    engine::Terrain, persist};"),
        vec!["cells", "engine", "persist"]
    );
}

/// A package's module trees: its library's `src/`, and each binary with modules of its own
/// (`src/bin/NAME/`, whose `main.rs` is the root).
fn module_roots(dir: &Path) -> Vec<(String, PathBuf)> {
    let mut roots = vec![("the library".to_string(), dir.join("src"))];
    for e in std::fs::read_dir(dir.join("src/bin")).into_iter().flatten().flatten() {
        if e.path().join("main.rs").exists() {
            roots.push((format!("binary {}", e.file_name().to_string_lossy()), e.path()));
        }
    }
    roots
}

#[test]
fn no_crate_has_an_import_cycle_between_its_modules() {
    let (mut checked, mut binaries) = (0, 0);
    for p in all_packages() {
        for (what, src) in module_roots(&p.dir) {
            let graph = module_graph(&src);
            checked += graph.len();
            binaries += usize::from(what.starts_with("binary") && !graph.is_empty());
            if let Some(cycle) = find_cycle(&graph) {
                panic!("{} ({what}) has an import cycle: {}", p.name, cycle.join(" → "));
            }
        }
    }
    assert!(checked > 60, "only {checked} modules found: the scan broke");
    assert!(binaries >= 1, "no binary's modules were scanned: the scan broke");
}
