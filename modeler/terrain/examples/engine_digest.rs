//! Digests of the terrain engine's heights, to show that a change to the engine keeps them bit for
//! bit: run it before and after and compare the lines.
//!
//! For each of the modeler's examples 1–5, in both metrics, on its own grid and on 512² (the
//! bench's scaling: the same square, finer cells): the heights after a full regeneration, then
//! after each edit of a sequence applied to the same engine — per figure (nested ones too) a
//! slope change, a slope of the other sign, a pull and a move (a vertex of a curve, a whole
//! point) — and the heights of a fresh engine for the document at the end. An edit the document
//! refuses prints `refused` instead of a digest.
//!
//! Run: `cargo run --release -p penmodel-terrain --example engine_digest`.
//!
//! `engine_digest --dump FILE` also writes every terrain's heights (`f32`, little-endian, in the
//! order of the lines) to FILE; `engine_digest --compare FILE` reads such a file, written by
//! another build, and reports the largest difference of a height from that build's, in metres and
//! relative to the terrain's relief (its highest cell less its lowest), instead of equality.
//!
//! `engine_digest --full N taxicab|euclidean` instead builds example 1's 512² terrain N times
//! (for `valgrind --tool=callgrind`: the difference of two counts is the cost of the extra
//! builds). `engine_digest --moves N METRIC` and `--slopes N METRIC` build it once, then move
//! its second figure's middle vertex, or change that figure's slope, N times back and forth.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};

use penmodel_terrain::{CurvePath, Document, Edit, Figure, FigureKind, FigurePath, Metric, TerrainEngine};

/// FNV-1a over the heights' bits: stable across builds and Rust versions.
fn digest(heights: &[f32]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in heights {
        for x in v.to_bits().to_le_bytes() {
            h = (h ^ u64::from(x)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

const EXAMPLES: [(&str, &str); 5] = [
    ("01", include_str!("../../examples/01-ridges-and-peaks.json")),
    ("02", include_str!("../../examples/02-twin-hills.json")),
    ("03", include_str!("../../examples/03-island-with-crater.json")),
    ("04", include_str!("../../examples/04-volcano.json")),
    ("05", include_str!("../../examples/05-terraced-mountain.json")),
];

/// Example `json` in `metric`, on an n × n grid over the same square (its own grid for `None`).
fn document(json: &str, metric: Metric, n: Option<u32>) -> Result<Document, String> {
    let mut doc = Document::from_json(json).map_err(|e| e.to_string())?;
    doc.terrain.metric = metric;
    if let Some(n) = n {
        let extent = doc.grid.width();
        doc.grid.cols = n;
        doc.grid.rows = n;
        doc.grid.cell_size = extent / f64::from(n);
    }
    Ok(doc)
}

/// Every figure's path, parents before their nested figures.
fn paths(doc: &Document) -> Vec<FigurePath> {
    fn walk(figs: &[Figure], at: Option<&FigurePath>, region: usize, out: &mut Vec<FigurePath>) {
        for (i, f) in figs.iter().enumerate() {
            let p = at.map_or_else(|| FigurePath::new(region, i), |p| p.child(i));
            out.push(p.clone());
            walk(&f.figures, Some(&p), region, out);
        }
    }
    let mut out = Vec::new();
    for (r, region) in doc.regions.iter().enumerate() {
        walk(&region.figures, None, r, &mut out);
    }
    out
}

/// The edits of the sequence for the figure at `p`.
fn edits(f: &Figure, p: &FigurePath) -> Vec<(String, Edit)> {
    let mut out = vec![
        (
            format!("{p} slope+0.3"),
            Edit::SetSlope {
                at: p.clone(),
                slope: f.slope + 0.3,
            },
        ),
        (
            format!("{p} slope-sign"),
            Edit::SetSlope {
                at: p.clone(),
                slope: if f.slope > 0.0 { -0.7 } else { 0.9 },
            },
        ),
        (
            format!("{p} pull"),
            Edit::SetHeight {
                at: p.clone(),
                height: f.height + 3.5,
            },
        ),
    ];
    let [x, y] = f.points[f.points.len() / 2];
    let moved = match f.kind {
        FigureKind::Point => Edit::MoveFigure {
            at: p.clone(),
            by: [2.5, -1.5],
        },
        _ => Edit::MovePoint {
            curve: CurvePath::Figure(p.clone()),
            index: f.points.len() / 2,
            to: [x + 2.5, y - 1.5],
        },
    };
    out.push((format!("{p} move"), moved));
    out
}

/// Where the heights go besides their digests: nowhere, a file, or a comparison with a file's.
enum Record {
    None,
    Dump(BufWriter<File>),
    /// The file, and the largest difference so far: metres, relative to the relief, and where.
    Compare(BufReader<File>, f64, f64, String),
}

impl Record {
    fn heights(&mut self, tag: &str, heights: &[f32]) -> Result<(), String> {
        match self {
            Record::None => {}
            Record::Dump(out) => {
                for v in heights {
                    out.write_all(&v.to_le_bytes()).map_err(|e| e.to_string())?;
                }
            }
            Record::Compare(input, metres, relative, at) => {
                let mut bytes = vec![0u8; heights.len() * 4];
                input.read_exact(&mut bytes).map_err(|e| format!("{tag}: {e}"))?;
                let old: Vec<f32> = bytes
                    .chunks_exact(4)
                    .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                    .collect();
                let (lo, hi) = old
                    .iter()
                    .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
                let relief = f64::from(hi - lo);
                let diff = old
                    .iter()
                    .zip(heights)
                    .map(|(&a, &b)| f64::from((a - b).abs()))
                    .fold(0.0, f64::max);
                if diff > *metres {
                    (*metres, *at) = (diff, tag.to_string());
                }
                if relief > 0.0 {
                    *relative = relative.max(diff / relief);
                }
            }
        }
        Ok(())
    }
}

fn sequence(name: &str, metric: Metric, n: Option<u32>, json: &str, record: &mut Record) -> Result<(), String> {
    let mut doc = document(json, metric, n)?;
    let grid = format!("{}x{}", doc.grid.cols, doc.grid.rows);
    let tag = format!("{name} {metric:?} {grid}");
    let mut engine = TerrainEngine::new(&doc).map_err(|e| e.to_string())?;
    println!("{tag} full {:016x}", digest(engine.heightmap().heights()));
    record.heights(&format!("{tag} full"), engine.heightmap().heights())?;
    for p in paths(&doc) {
        let f = p.get(&doc).ok_or("no figure")?.clone();
        for (label, edit) in edits(&f, &p) {
            match edit.apply_to(&mut doc) {
                Ok(applied) => {
                    engine.update(&doc, &applied.scope);
                    println!("{tag} {label} {:016x}", digest(engine.heightmap().heights()));
                    record.heights(&format!("{tag} {label}"), engine.heightmap().heights())?;
                }
                Err(_) => println!("{tag} {label} refused"),
            }
        }
    }
    let fresh = TerrainEngine::new(&doc).map_err(|e| e.to_string())?;
    println!("{tag} fresh {:016x}", digest(fresh.heightmap().heights()));
    record.heights(&format!("{tag} fresh"), fresh.heightmap().heights())?;
    Ok(())
}

/// The metric a `--full`, `--moves` or `--slopes` run names (taxicab unless `euclidean`).
fn metric_arg(arg: Option<&String>) -> Metric {
    match arg.map(String::as_str) {
        Some("euclidean") => Metric::Euclidean,
        _ => Metric::Taxicab,
    }
}

/// `--moves N METRIC` / `--slopes N METRIC`: example 1's 512² terrain built once, then its
/// second figure's middle vertex moved (or its slope changed) N times, back and forth.
fn edits_only(kind: &str, args: &[String]) -> Result<(), String> {
    let count: usize = args
        .get(1)
        .and_then(|a| a.parse().ok())
        .ok_or(format!("{kind} N taxicab|euclidean"))?;
    let metric = metric_arg(args.get(2));
    let mut doc = document(EXAMPLES[0].1, metric, Some(512))?;
    let mut engine = TerrainEngine::new(&doc).map_err(|e| e.to_string())?;
    let p = FigurePath::new(0, 1);
    let f = p.get(&doc).ok_or("no figure")?.clone();
    let index = f.points.len() / 2;
    let [x, y] = f.points[index];
    for i in 0..count {
        let step = if i % 2 == 0 { 1.0 } else { 0.0 };
        let edit = if kind == "--moves" {
            Edit::MovePoint {
                curve: CurvePath::Figure(p.clone()),
                index,
                to: [x + 2.5 * step, y - 1.5 * step],
            }
        } else {
            Edit::SetSlope {
                at: p.clone(),
                slope: f.slope + 0.3 * step,
            }
        };
        let applied = edit.apply_to(&mut doc).map_err(|e| e.to_string())?;
        engine.update(&doc, &applied.scope);
    }
    println!("{:016x}", digest(engine.heightmap().heights()));
    Ok(())
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(kind @ ("--moves" | "--slopes")) = args.first().map(String::as_str) {
        return edits_only(kind, &args);
    }
    if args.first().map(String::as_str) == Some("--full") {
        let count: usize = args
            .get(1)
            .and_then(|a| a.parse().ok())
            .ok_or("--full N taxicab|euclidean")?;
        let doc = document(EXAMPLES[0].1, metric_arg(args.get(2)), Some(512))?;
        let mut last = 0;
        for _ in 0..count {
            let engine = TerrainEngine::new(&doc).map_err(|e| e.to_string())?;
            last = digest(engine.heightmap().heights());
        }
        println!("{last:016x}");
        return Ok(());
    }
    let file = |flag: &str| args.get(1).ok_or(format!("{flag} FILE"));
    let mut record = match args.first().map(String::as_str) {
        Some("--dump") => Record::Dump(BufWriter::new(
            File::create(file("--dump")?).map_err(|e| e.to_string())?,
        )),
        Some("--compare") => Record::Compare(
            BufReader::new(File::open(file("--compare")?).map_err(|e| e.to_string())?),
            0.0,
            0.0,
            String::new(),
        ),
        Some(other) => return Err(format!("unknown flag {other}")),
        None => Record::None,
    };
    for (name, json) in EXAMPLES {
        for metric in [Metric::Taxicab, Metric::Euclidean] {
            for n in [None, Some(512)] {
                sequence(name, metric, n, json, &mut record)?;
            }
        }
    }
    match record {
        Record::Dump(mut out) => out.flush().map_err(|e| e.to_string())?,
        Record::Compare(_, metres, relative, at) => {
            println!("largest difference {metres:e} m ({relative:e} of the relief), at {at}");
        }
        Record::None => {}
    }
    Ok(())
}
