//! `penmodel bench`: the renderer's frame time and the terrain update while pulling.
//!
//! - Document: the seed's example 1 (`examples/01-ridges-and-peaks.json`: one region over most of
//!   the grid, eight control figures) on an N × N grid over the same 320 m square, N = 256, 512,
//!   1024 — the documents of the criterion bench `benches/terrain.rs`.
//! - Frame: 1280 × 720, mono, the orbit camera [`Camera::overview`] at azimuth 30°, elevation 35°
//!   (45° field of view, 1.75 ground half-diagonals away), with the document's figures and
//!   boundaries draped on the terrain, a slope bar and a mode line: what a live pull shows.
//! - Each timed frame follows a pull step (the first figure's height changes through
//!   [`Editor::preview`], untimed), so the renderer sees a changed terrain every frame, as it does
//!   live. The land look (`--look land`, the default) remakes its shadows and sky light for each of
//!   them ([`penmodel_render::land`]); `--look classic` measures the first renderer's look.
//! - Pull update: [`Editor::preview`] of the first figure's height, alternating between two
//!   values after a first (untimed) step that starts the pull.
//! - Medians over repeated runs after warm-up.
//! - Terrain engine (issue 18), for each grid and both metrics (`taxicab`, `euclidean`): a full
//!   regeneration ([`TerrainEngine::new`]), a moved vertex (the fourth figure's second point
//!   moved 2 m and back, as the criterion bench's `move_point`) and a slope change of the first
//!   figure (−1.5 ↔ −1.4), each an edit applied to the document and the engine brought up to date
//!   with its scope; medians. `--terrain-only` measures only these.
//! - Memory, measured first: the peak resident set (`VmHWM` of /proc/self/status, Linux) after
//!   building the terrain of a document with K point figures in one region over most of an
//!   N × N grid (default 100 figures on 1024², cell size 1 m), beside the bound validation
//!   computes for it ([`validate::engine_bytes`], at most [`validate::MAX_ENGINE_BYTES`]).

mod erosion;
mod still;

use std::io::IsTerminal;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use penmodel_render::{Camera, Frame, Renderer, Scene, SlopeBar, Style};
use penmodel_terrain::{
    CurvePath, Document, Edit, Editor, Figure, FigureKind, FigurePath, Grid, Metric, Region, TerrainEngine, validate,
};

/// Grid sizes measured.
const GRIDS: [u32; 3] = [256, 512, 1024];
/// The frame measured.
pub const FRAME: (u32, u32) = (1280, 720);
/// Timed frames per grid.
const FRAMES: usize = 25;
/// Timed pull updates per grid.
const PULLS: usize = 60;
/// Untimed frames first.
const WARM_UP: usize = 3;
/// Timed full regenerations per grid and metric.
const FULLS: usize = 7;
/// Timed vertex moves and slope changes per grid and metric.
const EDITS: usize = 30;

/// Arguments of `penmodel bench`.
#[derive(clap::Args)]
#[command(after_help = "Examples:\n  penmodel bench\n  penmodel bench --json > bench.json")]
pub struct Args {
    /// Print `{"render": [...], "pull_update": [...], "memory": {...}, "terrain": [...]}` on stdout
    /// instead of a table.
    #[arg(long)]
    json: bool,
    /// Measure only the terrain engine (full regeneration, moved vertex, slope change).
    #[arg(long)]
    terrain_only: bool,
    /// Grid sizes to measure (repeatable; default 256, 512 and 1024).
    #[arg(long = "grid", value_name = "N", value_parser = clap::value_parser!(u32).range(2..=4096))]
    grids: Vec<u32>,
    /// The memory case's grid: N × N cells.
    #[arg(long, value_name = "N", default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=4096))]
    memory_grid: u32,
    /// The look rendered: the land look (what `penmodel render` and the demo show; its shadows
    /// and sky light are remade every frame, since every frame follows a pull) or the classic one.
    #[arg(long, value_enum, default_value = "land")]
    look: crate::render::LookArg,
    /// The terrain's level of detail in the pulls' frames and the still frames' second run: the
    /// largest error on screen, pixels (0: every cell).
    #[arg(long, value_name = "PX", default_value_t = penmodel_render::DEFAULT_LOD_PIXELS, value_parser = crate::render::lod_error)]
    lod_error: f32,
    /// Measure only the still frames (`frames.rs`: LOD off and on, mono and stereo); grids above
    /// 1024 are measured this way only.
    #[arg(long)]
    still_only: bool,
    /// The still frames at `--lod-error` only, not also at full detail (a profile of the LOD
    /// frames).
    #[arg(long)]
    still_lod_only: bool,
    /// The memory case's number of point figures.
    #[arg(long, value_name = "K", default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..=10000))]
    memory_figures: u32,
    /// Timed still frames per case (their median is reported); more make a longer profile.
    #[arg(long, value_name = "N", default_value_t = 9, value_parser = clap::value_parser!(u32).range(1..=100000))]
    still_frames: u32,
    /// Write each still case's last frame into this directory as
    /// `still-<grid>-lod<px>-<eyes>eye.png` (to look at what the level of detail and the shading
    /// show).
    #[arg(long, value_name = "DIR")]
    still_png: Option<std::path::PathBuf>,
    /// Measure only the fluvial erosion's time per step on a cone (`bench/erosion.rs`; default
    /// grids 512 and 1024), as `scripts/erosion_peer.py` runs fastscapelib.
    #[arg(long)]
    erosion: bool,
    /// Steps per --erosion run (the best of three runs' mean is reported).
    #[arg(long, value_name = "N", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=5000))]
    erosion_steps: u32,
}

/// The memory case: `k` point figures on a lattice in one square region over most of an n × n
/// grid of 1 m cells.
fn memory_document(n: u32, k: u32) -> Document {
    let size = f64::from(n);
    let (lo, hi) = (0.02 * size, 0.98 * size);
    let side = (f64::from(k).sqrt().ceil() as u32).max(1);
    let step = (hi - lo) / f64::from(side + 1);
    let figures = (0..k)
        .map(|i| Figure {
            kind: FigureKind::Point,
            points: vec![[lo + step * f64::from(i % side + 1), lo + step * f64::from(i / side + 1)]],
            height: 10.0 + f64::from(i % 7) * 5.0,
            slope: 0.0,
            figures: Vec::new(),
        })
        .collect();
    let mut doc = Document::new(Grid {
        cols: n,
        rows: n,
        cell_size: 1.0,
    });
    doc.regions.push(Region {
        metric: None,
        boundary: vec![[lo, lo], [hi, lo], [hi, hi], [lo, hi], [lo, lo]],
        figures,
    });
    doc
}

/// `VmHWM` (peak resident set) from /proc/self/status, in bytes; `None` where there is none.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line
        .trim_start_matches("VmHWM:")
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}

struct Memory {
    grid: u32,
    figures: u32,
    estimate: u64,
    before: Option<u64>,
    peak: Option<u64>,
}

fn measure_memory(n: u32, k: u32) -> Result<Memory> {
    let doc = memory_document(n, k);
    let (estimate, _, _) = validate::engine_bytes(&doc);
    let before = peak_rss();
    let engine = TerrainEngine::new(&doc)?;
    let peak = peak_rss();
    drop(engine);
    Ok(Memory {
        grid: n,
        figures: k,
        estimate,
        before,
        peak,
    })
}

fn mb(bytes: u64) -> f64 {
    (bytes as f64 / 1e6 * 10.0).round() / 10.0
}

pub fn document(n: u32) -> Result<Document> {
    let mut doc = Document::from_json(include_str!("../../../examples/01-ridges-and-peaks.json"))
        .context("example 1 is not valid")?;
    let extent = doc.grid.width();
    doc.grid.cols = n;
    doc.grid.rows = n;
    doc.grid.cell_size = extent / f64::from(n);
    Ok(doc)
}

pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// The style the bench draws `look` in: the classic ramp topped at the bench document's 70 m.
pub fn style(look: crate::render::LookArg) -> Style {
    match look {
        crate::render::LookArg::Land => Style::land(),
        crate::render::LookArg::Classic => Style {
            ramp_top: 70.0,
            ..Style::default()
        },
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

struct Figures {
    grid: u32,
    frame_ms: f64,
    /// The mean: the land look remakes its maps every third frame of a pull, which the median
    /// alone would hide.
    frame_mean_ms: f64,
    pull_ms: f64,
    covered: f64,
}

fn measure(n: u32, look: crate::render::LookArg, lod_error: f32, bar: &ProgressBar) -> Result<Figures> {
    let doc = document(n)?;
    let extent = [doc.grid.width(), doc.grid.height()];
    let overlays = penmodel::picture::document_overlays(&doc);
    let mut editor = Editor::new(doc)?;
    let peak = FigurePath::new(0, 0);
    let base = editor.document().regions[0].figures[0].height;
    let mut step = 0usize;
    let mut pull = |editor: &mut Editor| -> Result<f64> {
        step += 1;
        let height = base + if step.is_multiple_of(2) { 1.0 } else { 2.0 };
        let t = Instant::now();
        editor.preview(&Edit::SetHeight {
            at: peak.clone(),
            height,
        })?;
        Ok(ms(t))
    };
    pull(&mut editor)?;

    let mut renderer = Renderer::new();
    let mut frame = Frame::new(FRAME.0, FRAME.1)?;
    let camera = Camera::overview(extent, 30f64.to_radians(), 35f64.to_radians());
    let mut times = Vec::with_capacity(FRAMES);
    for i in 0..WARM_UP + FRAMES {
        pull(&mut editor)?;
        let mut scene = Scene::new(editor.heightmap(), camera);
        // As the live loop: the land look learns what changed from the editor.
        scene.revisions = Some(editor.revisions());
        scene.terrain_lod = lod_error;
        scene.overlays = &overlays;
        scene.selection = Some(1);
        scene.mode = "pull  height 62.0 m";
        scene.slope_bar = Some(SlopeBar {
            value: -1.5,
            min: -4.0,
            max: 4.0,
            label: "slope".into(),
        });
        scene.style = style(look);
        let t = Instant::now();
        renderer.render(&scene, &mut frame)?;
        if i >= WARM_UP {
            times.push(ms(t));
        }
        bar.inc(1);
    }
    let frame_mean_ms = times.iter().sum::<f64>() / times.len().max(1) as f64;
    let frame_ms = median(times);

    let scene = Scene::new(editor.heightmap(), camera);
    let counts = renderer.coverage(&scene, FRAME.0, FRAME.1)?;
    let covered = counts.iter().filter(|&&c| c > 0).count() as f64 / counts.len() as f64;

    let mut pulls = Vec::with_capacity(PULLS);
    for _ in 0..PULLS {
        pulls.push(pull(&mut editor)?);
        bar.inc(1);
    }
    Ok(Figures {
        grid: n,
        frame_ms,
        frame_mean_ms,
        pull_ms: median(pulls),
        covered,
    })
}

/// The terrain engine's figures for one grid and metric.
struct Engine {
    grid: u32,
    metric: Metric,
    full_ms: f64,
    move_point_ms: f64,
    slope_ms: f64,
}

fn measure_engine(n: u32, metric: Metric, bar: &ProgressBar) -> Result<Engine> {
    let mut doc = document(n)?;
    doc.terrain.metric = metric;
    let mut fulls = Vec::with_capacity(FULLS);
    for _ in 0..FULLS {
        let t = Instant::now();
        let engine = TerrainEngine::new(&doc)?;
        fulls.push(ms(t));
        drop(engine);
        bar.inc(1);
    }
    let mut terrain = TerrainEngine::new(&doc)?;
    let mut edit = |doc: &mut Document, edit: Edit| -> Result<f64> {
        let t = Instant::now();
        let applied = edit.apply_to(doc)?;
        terrain.update(doc, &applied.scope);
        Ok(ms(t))
    };
    let curve = CurvePath::Figure(FigurePath::new(0, 3));
    let mut moves = Vec::with_capacity(EDITS);
    let mut slopes = Vec::with_capacity(EDITS);
    for i in 0..EDITS {
        let x = if i % 2 == 0 { 112.0 } else { 110.0 };
        moves.push(edit(
            &mut doc,
            Edit::MovePoint {
                curve: curve.clone(),
                index: 1,
                to: [x, 170.0],
            },
        )?);
        let slope = if i % 2 == 0 { -1.4 } else { -1.5 };
        slopes.push(edit(
            &mut doc,
            Edit::SetSlope {
                at: FigurePath::new(0, 0),
                slope,
            },
        )?);
        bar.inc(1);
    }
    Ok(Engine {
        grid: n,
        metric,
        full_ms: median(fulls),
        move_point_ms: median(moves),
        slope_ms: median(slopes),
    })
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let grids = if args.grids.is_empty() {
        GRIDS.to_vec()
    } else {
        args.grids.clone()
    };
    if args.erosion {
        let grids = if args.grids.is_empty() {
            vec![512, 1024]
        } else {
            args.grids.clone()
        };
        let bar = if std::io::stderr().is_terminal() {
            ProgressBar::with_draw_target(
                Some(grids.len() as u64 * 3 * u64::from(args.erosion_steps)),
                ProgressDrawTarget::stderr(),
            )
        } else {
            ProgressBar::hidden()
        };
        let figures = erosion::measure(&grids, args.erosion_steps, &bar)?;
        bar.finish_and_clear();
        if args.json {
            let list: Vec<_> = figures
                .iter()
                .map(|f| serde_json::json!({"grid": f.grid, "ms_per_step": f.ms_per_step, "steps": f.steps}))
                .collect();
            pen_host::outln!("{}", serde_json::json!({ "erosion": list }));
        } else {
            for f in &figures {
                pen_host::outln!(
                    "erosion {0}×{0}: {1:.1} ms a step ({2} steps)",
                    f.grid,
                    f.ms_per_step,
                    f.steps
                );
            }
        }
        return Ok(());
    }
    if args.still_only {
        let still = still_figures(&grids, args)?;
        if args.json {
            pen_host::outln!("{}", serde_json::json!({ "still": still_json(&still) }));
        } else {
            print_still(&still, args.still_frames)?;
        }
        return Ok(());
    }
    let metrics = [Metric::Taxicab, Metric::Euclidean];
    let render_steps = if args.terrain_only { 0 } else { WARM_UP + FRAMES + PULLS };
    let total = grids.len() * (render_steps + metrics.len() * (FULLS + EDITS));
    let bar = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len}") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    // First, while the process is small, so the peak is the engine's.
    let memory = measure_memory(args.memory_grid, args.memory_figures)?;
    let mut results = Vec::new();
    let mut engines = Vec::new();
    // The engine of example 1 above 1024² would need gigabytes: those grids get still frames only.
    for &n in grids.iter().filter(|&&n| n <= 1024) {
        bar.set_message(format!("{n}×{n}"));
        if !args.terrain_only {
            results.push(measure(n, args.look, args.lod_error, &bar)?);
        }
        for metric in metrics {
            engines.push(measure_engine(n, metric, &bar)?);
        }
    }
    bar.finish_and_clear();
    let still = if args.terrain_only {
        Vec::new()
    } else {
        still_figures(&grids, args)?
    };
    let (w, h) = FRAME;
    let look = match args.look {
        crate::render::LookArg::Land => "land",
        crate::render::LookArg::Classic => "classic",
    };
    if args.json {
        let render: Vec<_> = results
            .iter()
            .map(|r| {
                serde_json::json!({"grid": r.grid, "width": w, "height": h, "look": look, "frame_ms": round3(r.frame_ms),
                    "frame_mean_ms": round3(r.frame_mean_ms)})
            })
            .collect();
        let pull: Vec<_> = results
            .iter()
            .map(|r| serde_json::json!({"grid": r.grid, "ms": round3(r.pull_ms)}))
            .collect();
        let memory = serde_json::json!({
            "grid": memory.grid,
            "figures": memory.figures,
            "estimate_mb": mb(memory.estimate),
            "peak_rss_mb": memory.peak.map(mb),
            "rss_before_mb": memory.before.map(mb),
        });
        let terrain: Vec<_> = engines
            .iter()
            .map(|e| {
                serde_json::json!({"grid": e.grid, "metric": e.metric.name(), "full_ms": round3(e.full_ms),
                    "move_point_ms": round3(e.move_point_ms), "slope_ms": round3(e.slope_ms)})
            })
            .collect();
        pen_host::outln!(
            "{}",
            serde_json::json!({"render": render, "pull_update": pull, "memory": memory, "terrain": terrain,
                "still": still_json(&still)})
        );
    } else {
        if !results.is_empty() {
            pen_host::outln!("grid        frame {w}×{h}   (mean)      frames/s   terrain on screen   pull update");
        }
        for r in &results {
            pen_host::outln!(
                "{:>4}×{:<4}   {:>8.2} ms   ({:>6.2} ms)   {:>9.1}   {:>16.0} %   {:>8.3} ms",
                r.grid,
                r.grid,
                r.frame_ms,
                r.frame_mean_ms,
                1e3 / r.frame_ms,
                r.covered * 100.0,
                r.pull_ms
            );
        }
        if !results.is_empty() {
            pen_host::outln!(
                "{look} look; medians of {FRAMES} frames and {PULLS} pull updates per grid; targets at 512×512: ≤ 16.7 ms, ≤ 2 ms"
            );
        }
        pen_host::outln!("grid        metric       full regeneration   move one vertex   slope change");
        for e in &engines {
            pen_host::outln!(
                "{:>4}×{:<4}   {:<9}   {:>14.3} ms   {:>12.3} ms   {:>9.3} ms",
                e.grid,
                e.grid,
                e.metric.name(),
                e.full_ms,
                e.move_point_ms,
                e.slope_ms
            );
        }
        pen_host::outln!(
            "terrain engine: medians of {FULLS} regenerations, {EDITS} moves and {EDITS} slope changes; targets at 512×512: ≤ 10 ms, ≤ 4 ms, ≤ 1 ms"
        );
        print_still(&still, args.still_frames)?;
        let show = |v: Option<u64>| v.map_or("unknown".to_owned(), |b| format!("{} MB", mb(b)));
        pen_host::outln!(
            "memory: {} figures on {}×{}: peak resident {} (before building {}), bound {} MB (limit {} MB)",
            memory.figures,
            memory.grid,
            memory.grid,
            show(memory.peak),
            show(memory.before),
            mb(memory.estimate),
            mb(validate::MAX_ENGINE_BYTES)
        );
    }
    Ok(())
}

/// Still frames ([`crate::frames`]) of every grid: LOD off and at `--lod-error`, mono and stereo.
fn still_figures(grids: &[u32], args: &Args) -> Result<Vec<still::Still>> {
    let mut out = Vec::new();
    for &n in grids {
        let map = still::terrain(n)?;
        for stereo in [false, true] {
            for lod in [0.0, args.lod_error] {
                if args.still_lod_only && lod != args.lod_error {
                    continue;
                }
                let png = args
                    .still_png
                    .as_ref()
                    .map(|dir| dir.join(format!("still-{n}-lod{lod}-{}eye.png", if stereo { 2 } else { 1 })));
                out.push(still::measure(
                    &map,
                    lod,
                    stereo,
                    args.look,
                    args.still_frames as usize,
                    png.as_deref(),
                )?);
            }
        }
    }
    Ok(out)
}

fn still_json(still: &[still::Still]) -> Vec<serde_json::Value> {
    still
        .iter()
        .map(|s| {
            serde_json::json!({"grid": s.grid, "lod_error": s.lod_error, "stereo": s.stereo,
                "frame_ms": round3(s.frame_ms), "nodes_per_level": s.levels})
        })
        .collect()
}

fn print_still(still: &[still::Still], frames: u32) -> Result<()> {
    if still.is_empty() {
        return Ok(());
    }
    pen_host::outln!("still frames  LOD error   eyes   frame        nodes per level (0 first)");
    for s in still {
        pen_host::outln!(
            "{:>4}×{:<4}   {:>6} px   {:>4}   {:>8.2} ms   {:?}",
            s.grid,
            s.grid,
            s.lod_error,
            if s.stereo { 2 } else { 1 },
            s.frame_ms,
            s.levels
        );
    }
    pen_host::outln!("medians of {frames} frames, the view turning 0.1° a frame; target: ≤ 16.7 ms");
    Ok(())
}

fn round3(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}
