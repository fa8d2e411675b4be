//! `penmodel` without a subcommand, and `penmodel open`: model terrain with the pen.
//!
//! The pen comes from `--source` (default: pend's socket if pend is running, else the built-in
//! demo); the session is shown in a window when there is a display, else written to a folder
//! (`--out`): PNG frames and their animation, then the final terrain (16-bit PNG, float32,
//! OBJ, glTF), a render of it, and the document (JSON), which is also journaled as it is edited.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use penmodel::feed::{self, Feed, PenSource};
use penmodel::interaction::{Tuning, View};
use penmodel::keys::{self, KeyAction};
use penmodel::picture::{Look, Picture};
use penmodel::session::{Session, State, blank_document};
use penmodel_render::output::{self, Sequence, Viewer, ViewerEvent, WindowError};
use penmodel_render::ui::{self, Place};
use penmodel_render::{Frame, Renderer, Scene, Stereo};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::revision::Revisions;
use penmodel_terrain::{Heightmap, export};
use serde_json::json;

use crate::render::{StereoArg, head, head_mm, size, vertical_scale};

/// How the session is shown.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Show {
    /// A window if there is a display, else files.
    Auto,
    /// A window.
    Window,
    /// Files in the --out folder.
    Headless,
}

/// Options of a modeling session.
#[derive(clap::Args, Clone)]
pub struct LiveArgs {
    /// The pen: daemon (pend's), daemon:SOCKET, hid (the first base station on USB), hid:PATH,
    /// serial:PATH, none (keyboard only), sim (the built-in demo: the simulated pen calibrates on
    /// nine targets, then plays modeling-session) or sim:SCENARIO (a pen-sim scenario,
    /// uncalibrated) [default: daemon if pend is running; else sim for a new session, none for
    /// `open` in a window].
    #[arg(long, value_name = "SOURCE", value_parser = source)]
    source: Option<String>,
    /// Window, files, or a window when there is a display.
    #[arg(long, value_enum, default_value = "auto")]
    show: Show,
    /// The folder for frames and results (always a folder: the document, the terrain, renders).
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: PathBuf,
    /// Frame size in pixels [default: 1280x720 in a window; for files, 640x360 for the
    /// animation's frames and 960x540 for the final renders].
    #[arg(long, value_name = "WxH", value_parser = size)]
    size: Option<(u32, u32)>,
    /// Leave out the overview: the terrain from an orbit camera, where heights read at a glance,
    /// beside the display's view in the frames written to files (in a window, key `o` shows it
    /// in a corner).
    #[arg(long)]
    no_overview: bool,
    /// Frames per second of the session's animation (OUT/frames/animation.png) when headless;
    /// 0 draws none.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(0..=60))]
    fps: u16,
    /// Keep every frame of the animation as its own PNG in OUT/frames (large).
    #[arg(long)]
    frames: bool,
    /// Where the view moves (most of the picture changes from frame to frame: the ground tilting
    /// while a figure is pulled, the view following a tracked head), the animation holds every
    /// Nth frame, each shown until the next: a whole changed frame costs ~250 KB. 1 holds every
    /// frame (with --frames, each is also its own PNG).
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..))]
    moving_every: u16,
    /// Also write the terrain as meshes: OUT/terrain.obj and OUT/terrain.glb (large).
    #[arg(long)]
    meshes: bool,
    /// The simulated pen's speed (sim, sim:SCENARIO): device seconds per second, 0 as fast as
    /// frames are drawn [default: 1 in a window, 0 when headless].
    #[arg(long, value_name = "X", value_parser = pen_host::source::speed_value, allow_negative_numbers = true)]
    speed: Option<f64>,
    /// The demo's randomness.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Stereo mode.
    #[arg(long, value_enum, default_value = "none")]
    stereo: StereoArg,
    /// The viewer's head in the display's frame, mm from its centre (x right, y up the display,
    /// z out of it towards the viewer) [default: 0,-350,700].
    #[arg(long, value_name = "X,Y,Z", value_parser = head_mm, allow_hyphen_values = true)]
    head_mm: Option<[f64; 3]>,
    /// Earlier spelling of --head-mm, in metres.
    #[arg(long, value_name = "X,Y,Z", value_parser = head, allow_hyphen_values = true, hide = true,
          conflicts_with = "head_mm")]
    head: Option<[f64; 3]>,
    /// The distance between the viewer's eyes, mm (40…80): stereo places each eye half of it
    /// from the head, the tracked one's or --head-mm's.
    #[arg(long, value_name = "MM", default_value_t = 63.0, value_parser = eye_separation_mm)]
    eye_separation_mm: f64,
    /// Vertical scale of the terrain (exaggeration; 1: true heights). A pull follows it: the
    /// figure stays at the pen's tip.
    #[arg(long, default_value_t = 1.0, value_parser = vertical_scale, alias = "exaggeration", allow_negative_numbers = true)]
    vertical_scale: f64,
    /// The document's file for a new session [default: OUT/document.json].
    #[arg(long, value_name = "DOC.json")]
    doc: Option<PathBuf>,
    /// Print a JSON summary on stdout at the end.
    #[arg(long)]
    json: bool,
}

/// `n` and the noun, plural unless one: "1 region", "2 regions".
use penmodel::interaction::stats::count;

/// The file beside the demo's document that says an earlier demo wrote it, so the next demo may
/// replace it; a user's document has none.
const DEMO_MARK: &str = ".penmodel-demo";
const DEMO_MARK_TEXT: &str = "document.json here was written by penmodel's built-in demo; the next demo replaces it.\n";

/// A pen source's name, checked.
fn source(s: &str) -> Result<String, String> {
    PenSource::parse(s, 0.0).map(|_| s.to_string())
}

/// What a session created, to remove when nothing is modeled.
#[derive(Default)]
struct Created {
    /// The --out folder, when it did not exist.
    out: Option<PathBuf>,
    /// Its frames folder, when it did not exist.
    frames: Option<PathBuf>,
    /// A new session's document (and its journal).
    document: Option<PathBuf>,
    /// The demo's mark beside it.
    demo_mark: Option<PathBuf>,
}

impl Created {
    /// Removes what was created; folders only if empty.
    fn remove(&self) -> Result<()> {
        let remove = |path: &Path| match std::fs::remove_file(path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(e).with_context(|| format!("cannot remove {}", path.display()))
            }
            _ => Ok(()),
        };
        if let Some(doc) = &self.document {
            remove(doc)?;
            remove(&penmodel_terrain::journal::path_for(doc))?;
        }
        if let Some(mark) = &self.demo_mark {
            remove(mark)?;
        }
        // A folder goes only if empty (remove_dir refuses any other): its frames folder first.
        for dir in self.frames.iter().chain(&self.out) {
            let _ = std::fs::remove_dir(dir);
        }
        Ok(())
    }
}

/// Where the results went.
struct Written {
    frames: usize,
    animation: Option<PathBuf>,
    /// How many of the frames the animation holds (--moving-every).
    held: usize,
    /// The frames were shown in a window, not written.
    shown: bool,
}

/// The pen when `--source` is not given: pend if it is running; otherwise the demo for a new
/// session. An opened document is the user's: the demo never plays into it unless asked
/// (`--source sim`), so without pend it is opened with no pen in a window, and refused headless
/// (there would be nothing to do).
fn default_source(open: Option<&Path>, window: bool) -> Result<String> {
    let socket = pen_host::daemon::default_socket();
    if std::os::unix::net::UnixStream::connect(&socket).is_ok() {
        return Ok("daemon".into());
    }
    match open {
        None => Ok("sim".into()),
        Some(_) if window => {
            eprintln!(
                "penmodel: no pen (pend is not running at {}): the document is open to look at and to edit \
                 from the keyboard; start pend, or give --source hid|serial:PATH, to model with the pen",
                socket.display()
            );
            Ok("none".into())
        }
        Some(doc) => bail!(
            "no pen to model {} with: pend is not running at {}. Start pend (pend --hid, or pend --serial PATH), \
             or give --source hid|serial:PATH; --source sim plays the built-in demo into this document",
            doc.display(),
            socket.display()
        ),
    }
}

/// A new session (`doc` = None) or `penmodel open DOC`.
pub fn run(args: &LiveArgs, open: Option<&Path>) -> Result<()> {
    let window_wanted = match args.show {
        Show::Headless => false,
        Show::Window => true,
        Show::Auto => output::window::has_display(),
    };
    let source_name = match &args.source {
        Some(s) => s.clone(),
        None => default_source(open, window_wanted)?,
    };
    let speed = args.speed.unwrap_or(if window_wanted { 1.0 } else { 0.0 });
    let mut source = PenSource::parse(&source_name, speed).map_err(anyhow::Error::msg)?;
    let demo = matches!(source, PenSource::Demo { .. });
    let simulated = demo
        || matches!(
            source,
            PenSource::Device {
                source: pen_host::source::Source::Sim(_),
                ..
            }
        );
    if args.speed.is_some() && !simulated {
        // As in pend and penctl: a usage error (2), before anything is created.
        clap::Error::raw(
            clap::error::ErrorKind::ArgumentConflict,
            format!("--speed is the simulated pen's (--source sim); {source_name} runs in real time\n"),
        )
        .exit();
    }
    if let PenSource::Demo { seed, .. } = &mut source {
        *seed = args.seed;
    }
    // What this session creates it removes again if nothing is modeled: no empty results.
    let mut created = Created {
        out: (!args.out.exists()).then(|| args.out.clone()),
        frames: (!args.out.join("frames").exists()).then(|| args.out.join("frames")),
        ..Created::default()
    };
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let (editor, doc_path) = match open {
        Some(path) => {
            let (editor, report) = Editor::open(path)?;
            if report.replayed > 0 {
                eprintln!("penmodel: {} journal entries replayed", report.replayed);
            }
            if let Some(stale) = report.stale_journal {
                eprintln!(
                    "penmodel: a journal of another version was set aside: {}",
                    stale.display()
                );
            }
            (editor, path.to_owned())
        }
        None => {
            let path = args.doc.clone().unwrap_or_else(|| args.out.join("document.json"));
            // The demo replaces only a document an earlier demo wrote (its mark beside it); a
            // real session never overwrites anything, and no session plays the demo into work.
            let demo_mark = args.out.join(DEMO_MARK);
            let replaceable = demo && args.doc.is_none() && demo_mark.exists();
            if path.exists() && !replaceable {
                let hint = if demo {
                    "; give the demo another --out"
                } else {
                    ", or give another --doc"
                };
                bail!(
                    "{} exists: `penmodel open {}` continues it{hint}",
                    path.display(),
                    path.display()
                );
            }
            let editor = match Editor::create(&path, blank_document()) {
                Ok(editor) => editor,
                Err(e) => {
                    // The --out folder made for it goes again.
                    created.remove()?;
                    return Err(e.into());
                }
            };
            created.document = Some(path.clone());
            if demo && args.doc.is_none() {
                std::fs::write(&demo_mark, DEMO_MARK_TEXT)
                    .with_context(|| format!("cannot write {}", demo_mark.display()))?;
                created.demo_mark = Some(demo_mark.clone());
            } else if path == args.out.join("document.json") && demo_mark.exists() {
                // This document is the user's now: the next demo must not replace it.
                std::fs::remove_file(&demo_mark).with_context(|| format!("cannot remove {}", demo_mark.display()))?;
            }
            (editor, path)
        }
    };
    let tuning = Tuning::default();
    let mut session = Session::new(editor, [600.0, 340.0], tuning);
    let mut look = Look::default();
    session.set_vertical_scale(args.vertical_scale);
    if let Some(h) = args.head_mm.or(args.head) {
        look.head_m = h;
    }
    look.eye_separation_m = args.eye_separation_mm * 1e-3;
    look.stereo = match args.stereo {
        StereoArg::None => Stereo::None,
        StereoArg::Anaglyph => Stereo::Anaglyph,
        StereoArg::SideBySide => Stereo::SideBySide,
    };

    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        signal_hook::flag::register(signal, stop.clone()).context("installing signal handlers")?;
    }
    let demo_us = demo.then(|| (feed::demo_scenario().0.timeline.duration_s() * 1e6) as u64);
    if let PenSource::Demo { seed, .. } = &source {
        // The simulator knows where the viewer's head is: frames measure the prediction by it.
        if let Some(viewer) = pen_sim::Simulation::new(&feed::demo_scenario().0, *seed).viewer() {
            session.set_head_truth(Box::new(move |device_us| {
                viewer.emitter_display(device_us as f64 * 1e-6).to_array()
            }));
        }
    }
    // The pen thread is not joined: it notices the closed channel only at its next message, and
    // a silent pen (pend without a device, a base station unplugged) sends none. It ends with
    // the process; it holds nothing that needs closing beyond what the process's end closes.
    let (rx, _thread) = feed::spawn(source, 256);
    eprintln!("penmodel: pen from {source_name}");

    let viewer = if window_wanted {
        let (w, h) = args.size.unwrap_or((1280, 720));
        match Viewer::open("penmodel", w, h) {
            Ok(v) => Some(v),
            Err(e @ WindowError::NoDisplay) if args.show == Show::Auto => {
                eprintln!("penmodel: {e}; writing files instead");
                None
            }
            Err(e) => return Err(e.into()),
        }
    } else {
        None
    };
    // Headless, the animation's frames are small enough to mail (640 × 360 views, 960 × 360
    // with the overview beside them: the demo's animation is a few MB) and the final renders
    // are 960 × 540; `--size` sets both. In a window, the window's size.
    let windowed = viewer.is_some();
    let (w, h) = args.size.unwrap_or(if windowed { (1280, 720) } else { (640, 360) });
    let layout = match (args.no_overview, viewer.is_some()) {
        (true, _) | (false, true) => Overview::Off,
        (false, false) => Overview::Beside,
    };
    let mut painter = Painter::new(w, h, layout)?;
    let written = match viewer {
        Some(v) => run_window(v, &rx, &mut session, &look, &mut painter, &stop)?,
        None => run_headless(args, &rx, &mut session, &look, &mut painter, &stop, demo_us)?,
    };
    drop(rx);

    // Nothing modeled (the pen never came, pend is not running, the session was stopped at
    // once): nothing is written, and only a window closed by its user is a success.
    if !(session.editor.can_undo() || session.editor.can_redo()) {
        created.remove()?;
        let stopped = stop.load(Ordering::Relaxed);
        return match session.state() {
            State::Failed(why) => bail!("the pen failed: {why}; nothing modeled, nothing written"),
            State::Ended(why) => bail!("{why}; nothing modeled, nothing written"),
            State::Running if stopped => bail!("stopped before anything was modeled: nothing written"),
            State::Running => {
                eprintln!("penmodel: nothing modeled: nothing written");
                Ok(())
            }
        };
    }
    session
        .editor
        .save()
        .with_context(|| format!("cannot save {}", doc_path.display()))?;
    let results_size = match (args.size, windowed) {
        (Some(size), _) => size,
        (None, true) => (painter.view.width(), painter.view.height()),
        (None, false) => (960, 540),
    };
    let mut results_painter = Painter::new(results_size.0, results_size.1, Overview::Off)?;
    let results = write_results(&args.out, args.meshes, &session, &look, &mut results_painter)?;
    let stats = session.interaction.stats().clone();
    let state = match session.state() {
        State::Running => "stopped".to_string(),
        State::Ended(s) => s.clone(),
        State::Failed(s) => format!("failed: {s}"),
    };
    let (lo, hi) = session.editor.heightmap().range();
    if args.json {
        let summary = json!({
            "source": source_name,
            "state": state,
            "events": session.events(),
            "device_seconds": session.last_event_us().map(|t| t as f64 * 1e-6),
            "document": doc_path,
            "frames": written.frames,
            "frames_shown_in_window": written.shown,
            "animation": written.animation,
            "animation_frames": written.held,
            "results": results,
            "heights_m": [lo, hi],
            "stats": stats.to_json(),
            "head_latency": head_latency_json(&session, &painter.checks),
        });
        pen_host::outln!("{summary}");
    } else {
        pen_host::outln!(
            "{state}: {}; {}; terrain {lo:.0} to {hi:.0} m",
            count(session.events(), "pen event"),
            stats.summary(),
        );
        let what = match (written.shown, &written.animation) {
            (true, _) => format!("showed {}; wrote", count(written.frames as u64, "frame")),
            (false, Some(anim)) if args.frames => {
                format!(
                    "wrote {} and their animation {},",
                    count(written.frames as u64, "frame"),
                    anim.display()
                )
            }
            (false, Some(anim)) if written.held < written.frames => format!(
                "wrote the animation of {} ({}; {} of them: 1 in {} where the view moves),",
                count(written.frames as u64, "frame"),
                anim.display(),
                written.held,
                args.moving_every,
            ),
            (false, Some(anim)) => format!(
                "wrote the animation of {} ({}),",
                count(written.frames as u64, "frame"),
                anim.display()
            ),
            (false, None) => "wrote".to_string(),
        };
        if let Some(line) = head_latency_line(&session, &painter.checks) {
            pen_host::outln!("{line}");
        }
        let meshes = if args.meshes { ", its meshes" } else { "" };
        pen_host::outln!(
            "{what} the terrain{meshes}, its render and the document to {}/ (document: {})",
            args.out.display(),
            doc_path.display()
        );
    }
    if let State::Failed(why) = session.state() {
        bail!("the pen failed: {why}");
    }
    Ok(())
}

/// The tracked head's emission-to-frame latency for the JSON summary (issue 16), or null
/// without a tracked head on a paced simulated device's clock (`--source sim --speed 1`).
fn head_latency_json(session: &Session, checks: &[Check]) -> serde_json::Value {
    match session.head_latency() {
        None => serde_json::Value::Null,
        Some(l) => json!({
            "reprojection": reprojection_json(checks),
            "frames": l.frames, "p50_ms": l.p50_ms, "p95_ms": l.p95_ms, "max_ms": l.max_ms,
            "prediction_ms": l.prediction_ms, "uncovered_p95_ms": l.uncovered_p95_ms(),
            "draw_start_p50_ms": l.start_p50_ms, "draw_start_p95_ms": l.start_p95_ms,
            "target_ms": penmodel::latency::TARGET_MS, "meets_target": l.meets_target(),
            "host_lead_p50_ms": l.host_lead_p50_ms,
            "reported_error_mm": error_json(l.reported_error), "drawn_error_mm": error_json(l.drawn_error),
            "tracking_error_mm": error_json(l.tracking_error), "bias_mm": l.bias_mm,
        }),
    }
}

/// How the views moved to their poses compare with views drawn whole from them
/// ([`Painter::check_reprojection`]), or null when none was moved.
fn reprojection_json(checks: &[Check]) -> serde_json::Value {
    match Reprojection::of(checks) {
        None => serde_json::Value::Null,
        Some(r) => json!({
            "frames": r.frames, "mean_abs_p50": r.mean_abs_p50, "mean_abs_max": r.mean_abs_max,
            "visibly_different_p50": r.visible_p50, "visibly_different_p95": r.visible_p95,
            "visible_levels": VISIBLE_LEVELS,
        }),
    }
}

/// [`Check`]s summed up.
struct Reprojection {
    frames: usize,
    mean_abs_p50: f64,
    mean_abs_max: f64,
    /// Shares of pixels, 0–1.
    visible_p50: f64,
    visible_p95: f64,
}

impl Reprojection {
    fn of(checks: &[Check]) -> Option<Reprojection> {
        use penmodel::latency::nearest_rank;
        let sorted = |f: fn(&Check) -> f64| {
            let mut v: Vec<f64> = checks.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let (mean_abs, visible) = (sorted(|c| c.mean_abs), sorted(|c| c.visible));
        (!checks.is_empty()).then(|| Reprojection {
            frames: checks.len(),
            mean_abs_p50: nearest_rank(&mean_abs, 0.5),
            mean_abs_max: nearest_rank(&mean_abs, 1.0),
            visible_p50: nearest_rank(&visible, 0.5),
            visible_p95: nearest_rank(&visible, 0.95),
        })
    }
}

/// Distances of the poses from the head's true path, or null without it.
fn error_json(e: Option<penmodel::latency::ErrorSummary>) -> serde_json::Value {
    e.map_or(
        serde_json::Value::Null,
        |e| json!({"p50": e.p50_mm, "p95": e.p95_mm, "rms": e.rms_mm}),
    )
}

/// The same for a person: emission to frame against the 20 ms target, and what prediction
/// leaves uncovered.
fn head_latency_line(session: &Session, checks: &[Check]) -> Option<String> {
    let l = session.head_latency()?;
    let moved = Reprojection::of(checks).map_or(String::new(), |r| {
        format!(
            "; {} moved to their poses after the latch, against the same drawn whole: p50 {:.2}/255 \
             (most {:.2}), pixels differing visibly p50 {:.2} % / p95 {:.2} %",
            count(r.frames as u64, "view"),
            r.mean_abs_p50,
            r.mean_abs_max,
            r.visible_p50 * 100.0,
            r.visible_p95 * 100.0
        )
    });
    let truth = match (l.reported_error, l.drawn_error, l.tracking_error) {
        (Some(r), Some(d), Some(t)) => format!(
            "; from the true head when the frame was done: as reported p50 {:.1} / p95 {:.1} mm, as drawn p50 {:.1} / \
             p95 {:.1} mm (at the pose's own instant p50 {:.1} / p95 {:.1} mm)",
            r.p50_mm, r.p95_mm, d.p50_mm, d.p95_mm, t.p50_mm, t.p95_mm
        ),
        _ => String::new(),
    };
    Some(format!(
        "head: emission to frame on the device's clock p50 {:.1} ms, p95 {:.1} ms, max {:.1} ms over {} \
         (to the start of drawing p50 {:.1}, p95 {:.1}); target {} ms {}; predicted {} ms ahead, p95 uncovered {:.1} ms, \
         carried on by the host p50 {:.1} ms{truth}{moved}",
        l.p50_ms,
        l.p95_ms,
        l.max_ms,
        count(l.frames as u64, "frame"),
        l.start_p50_ms,
        l.start_p95_ms,
        penmodel::latency::TARGET_MS,
        if l.meets_target() { "met" } else { "missed" },
        l.prediction_ms,
        l.uncovered_p95_ms(),
        l.host_lead_p50_ms,
    ))
}

fn say(messages: Vec<String>, progress: Option<&ProgressBar>) {
    for m in messages {
        match progress {
            // A hidden bar (not a terminal) prints nothing.
            Some(p) if !p.is_hidden() => p.println(format!("penmodel: {m}")),
            _ => eprintln!("penmodel: {m}"),
        }
    }
}

/// Where the overview goes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Overview {
    /// Not drawn.
    Off,
    /// In the lower right corner, a quarter of each side (clear of the slope bar, which takes
    /// the middle 40 % of the bottom).
    Corner,
    /// In a column half as wide as the display's view, to its right: the overview above, a map
    /// from straight above below.
    Beside,
}

/// Draws frames: the display's view, and the overview.
struct Painter {
    frame: Frame,
    view: Frame,
    renderer: Renderer,
    overview: Overview,
    inset: Frame,
    inset_renderer: Renderer,
    /// The trees' detail in latched frames ([`TreeBudget`]).
    trees: TreeBudget,
    /// How long the last view drawn before the head's pose took, µs: how far ahead of now the
    /// next one is drawn ([`Session::head_ahead`]).
    held_view_us: u64,
    /// Whether the last frame's view was moved to its pose (`Renderer::reproject`).
    reprojected: bool,
    /// How the moved views compare with views drawn whole from the same poses
    /// ([`Painter::check_reprojection`]).
    checks: Vec<Check>,
    /// The renderer and frame of those whole views: apart, so that the session's renderer keeps
    /// its held eyes and caches as they were.
    checker: Option<(Renderer, Frame)>,
}

/// A view moved to its pose against the view drawn whole from it.
#[derive(Debug, Clone, Copy)]
struct Check {
    /// Mean absolute difference per channel, 0–255.
    mean_abs: f64,
    /// The share of pixels that differ by more than [`VISIBLE_LEVELS`].
    visible: f64,
}

/// A pixel differs visibly by more than this many levels in a channel.
const VISIBLE_LEVELS: u8 = 8;

/// The longest a latched frame's view should take, ms. Drawn before the head's pose and moved to
/// it after (`Renderer::reproject`), the view is no longer in the head's latency, but it is most
/// of the frame's period (15 ms and the latch's wait: about 50 frames a second), and the older the
/// pose it was drawn from, the more its reprojection moves and uncovers. (It was the 20 ms from
/// the head's emission to the frame, issue 16, less the chain's own 4.6 ms, when the view was
/// drawn after the latch.)
const VIEW_BUDGET_MS: f64 = 15.0;

/// The trees' level of detail held to the view's budget in real time: after a view over
/// [`VIEW_BUDGET_MS`] the roughness at the gaze, `Q0`, is raised by half (up to the seed's
/// `Q ≈ 0.10` its subjects accepted for small trees); after one under 60 % of it, lowered by a
/// fifth back towards the default. This is the seed's own lever: its Q was chosen to hold a frame
/// time. A grove planted under the pen, at `Q0` = 0.02 by the gaze, drew 38 000 polygons and
/// 26 000 simplified shapes for four frames of 44–72 ms. Only latched frames use it: the
/// unpaced demo's frames stay the same from run to run.
#[derive(Debug, Clone, Copy)]
struct TreeBudget {
    /// `Q0` over its default.
    scale: f64,
}

impl TreeBudget {
    /// The largest `Q0`.
    const MAX_Q0: f64 = 0.10;

    fn new() -> TreeBudget {
        TreeBudget { scale: 1.0 }
    }

    /// `roughness` with this budget's `Q0`.
    fn apply(&self, roughness: penmodel_terrain::trees::Roughness) -> penmodel_terrain::trees::Roughness {
        penmodel_terrain::trees::Roughness {
            q0: (roughness.q0 * self.scale).min(Self::MAX_Q0.max(roughness.q0)),
            ..roughness
        }
    }

    /// [`scene`] with the trees at this budget's detail.
    fn scene<'a>(&self, p: &'a Picture, map: &'a Heightmap, revisions: Option<&'a Revisions>) -> Scene<'a> {
        let mut scene = scene(p, map, revisions);
        scene.tree_lod = scene.tree_lod.map(|r| self.apply(r));
        scene
    }

    /// Takes a view that took `ms`.
    fn after(&mut self, ms: f64) {
        let max = Self::MAX_Q0 / penmodel_terrain::trees::Roughness::default().q0;
        if ms > VIEW_BUDGET_MS {
            self.scale = (self.scale * 1.5).min(max);
        } else if ms < 0.6 * VIEW_BUDGET_MS {
            self.scale = (self.scale / 1.2).max(1.0);
        }
    }
}

impl Painter {
    /// Frames whose display view is `width × height`.
    fn new(width: u32, height: u32, overview: Overview) -> Result<Painter> {
        let mut painter = Painter {
            frame: Frame::new(width, height)?,
            view: Frame::new(width, height)?,
            renderer: Renderer::new(),
            overview: Overview::Off,
            inset: Frame::new(1, 1)?,
            inset_renderer: Renderer::new(),
            trees: TreeBudget::new(),
            held_view_us: 0,
            reprojected: false,
            checks: Vec::new(),
            checker: None,
        };
        painter.set_overview(overview)?;
        Ok(painter)
    }

    fn set_overview(&mut self, overview: Overview) -> Result<()> {
        let (w, h) = (self.view.width(), self.view.height());
        let (frame_w, inset) = match overview {
            Overview::Off => (w, (1, 1)),
            Overview::Corner => (w, ((w / 4).max(1), (h / 4).max(1))),
            Overview::Beside => (w + (w / 2).max(1), ((w / 2).max(1), (h / 2).max(1))),
        };
        self.frame = Frame::new(frame_w, h)?;
        self.inset = Frame::new(inset.0, inset.1)?;
        self.overview = overview;
        Ok(())
    }

    /// `picture` with the overview; `revisions`, the terrain's history when `map` is an editor's,
    /// lets the land look recompute only what changed since the last frame.
    fn draw(&mut self, picture: &Picture, map: &Heightmap, revisions: Option<&Revisions>) -> Result<&Frame> {
        self.insets(picture, map, revisions)?;
        self.view(picture, map, revisions)
    }

    /// Draws what does not follow the head: the overview (and beside it the map), so that a
    /// tracked frame can draw them before it takes the head's newest pose for its view (issue
    /// 16). [`view`](Self::view) completes the frame.
    fn insets(&mut self, picture: &Picture, map: &Heightmap, revisions: Option<&Revisions>) -> Result<()> {
        if self.overview == Overview::Off {
            return Ok(());
        }
        let extent = [
            f64::from(map.cols()) * map.cell_size(),
            f64::from(map.rows()) * map.cell_size(),
        ];
        self.inset_renderer
            .render(&scene(&picture.overview(extent), map, revisions), &mut self.inset)?;
        if self.overview == Overview::Beside {
            // Its column is clear of the view: both go straight into the frame.
            let (w, h) = (self.view.width(), self.view.height());
            self.frame.blit(&self.inset, w, 0);
            self.inset_renderer
                .render(&scene(&picture.map(extent), map, revisions), &mut self.inset)?;
            self.frame.blit(&self.inset, w, h - self.inset.height());
        }
        Ok(())
    }

    /// The display's view of `picture` into the frame, with the insets [`insets`](Self::insets)
    /// drew: the frame complete.
    fn view(&mut self, picture: &Picture, map: &Heightmap, revisions: Option<&Revisions>) -> Result<&Frame> {
        self.view_with(scene(picture, map, revisions))
    }

    /// [`view`](Self::view) of `scene`.
    fn view_with(&mut self, scene: Scene) -> Result<&Frame> {
        self.renderer.render(&scene, &mut self.view)?;
        self.compose()
    }

    /// The frame from the view drawn and the insets.
    fn compose(&mut self) -> Result<&Frame> {
        self.frame.blit(&self.view, 0, 0);
        if self.overview == Overview::Corner {
            // Over the view, so after it.
            let (w, h) = (self.view.width(), self.view.height());
            let margin = 8.min(w / 8).min(h / 8) + 1;
            // At least 1 from the edge, for the border; blit clips what does not fit.
            let x = w.saturating_sub(self.inset.width() + margin).max(1);
            let y = h.saturating_sub(self.inset.height() + margin).max(1);
            let mut border = Frame::new(self.inset.width() + 2, self.inset.height() + 2)?;
            border.pixels_mut().fill([255, 255, 255, 255]);
            self.frame.blit(&border, x - 1, y - 1);
            self.frame.blit(&self.inset, x, y);
        }
        Ok(&self.frame)
    }

    /// `picture` alone, at the display view's size.
    fn plain(&mut self, picture: &Picture, map: &Heightmap) -> Result<&Frame> {
        self.renderer.render(&picture.scene(map), &mut self.view)?;
        Ok(&self.view)
    }

    fn session(&mut self, session: &Session, look: &Look) -> Result<&Frame> {
        let picture = Picture::of(session, look);
        self.draw(&picture, session.editor.heightmap(), Some(session.editor.revisions()))
    }

    /// A frame of `session` in real time: the insets from what it shows now, then the feed
    /// [latched](latch_head) to the head's next pose, then the view from that pose. Returns
    /// the frame and whether the feed ended meanwhile. `advance`: the interaction's own clock
    /// is moved to the last event's time first (the window's); `said` takes what the feed said.
    ///
    /// With a tracked head the view is drawn *before* the latch, from the pose predicted for
    /// when the frame will be done, and after the latch only moved to the newest pose by its
    /// depth (`Renderer::reproject`): what stands between the head's report and the frame is
    /// then a pass over the pixels, not the view's drawing (17–25 ms at 640 × 360 on two
    /// cores). The view shows the pen's edits up to the view's start, as the insets do (at the
    /// frame, older than before by the latch's wait and the move); the slope bar and the mode
    /// line are drawn after the latch.
    fn session_latched(
        &mut self,
        rx: &std::sync::mpsc::Receiver<Feed>,
        session: &mut Session,
        look: &Look,
        advance: bool,
        said: &mut dyn FnMut(Vec<String>),
    ) -> Result<(&Frame, bool)> {
        let tracked = session.head_m().is_some();
        if tracked {
            session.head_ahead(self.held_view_us);
        }
        let revisions = Some(session.editor.revisions());
        let picture = Picture::of(session, look);
        self.insets(&picture, session.editor.heightmap(), revisions)?;
        if tracked {
            let before = self.trees.scene(&picture, session.editor.heightmap(), revisions);
            let started = Instant::now();
            self.renderer.render_held(&before, &mut self.view)?;
            self.held_view_us = started.elapsed().as_micros() as u64;
            self.trees.after(self.held_view_us as f64 * 1e-3);
        } else {
            // The terrain's changes taken in before the pose, not in the view after it: a frame
            // after a burst of edits spent up to 26 ms on them inside the latency window.
            let before = self.trees.scene(&picture, session.editor.heightmap(), revisions);
            self.renderer.prepare_terrain(&before);
            // The trees' new simplified shapes baked for the last pose, at the budget's detail,
            // not in the view.
            self.renderer
                .prepare_trees(&before, self.view.width(), self.view.height());
        }
        let ended = latch_head(rx, session, said, Duration::from_micros(HEAD_WAIT_US));
        if let Some(t) = session.last_event_us().filter(|_| advance) {
            session.interaction.advance(t);
        }
        session.frame_started();
        let picture = Picture::of(session, look);
        let latched = self
            .trees
            .scene(&picture, session.editor.heightmap(), Some(session.editor.revisions()));
        // Moved to the newest pose; drawn whole when the held view cannot be (the stereo mode
        // or the size changed, or no pose came before the view).
        self.reprojected = tracked && self.renderer.reproject(&latched, &mut self.view).is_ok();
        if !self.reprojected {
            let started = Instant::now();
            self.renderer.render(&latched, &mut self.view)?;
            self.trees.after(started.elapsed().as_secs_f64() * 1e3);
        }
        Ok((self.compose()?, ended))
    }
}

impl Painter {
    /// After a frame whose view was moved to its pose: the view drawn whole from the same pose
    /// and compared with it ([`Check`]), so the demo reports how near the moved views are.
    /// Outside the frame's latency (it is done); the headless demo's frames are 200 ms apart.
    fn check_reprojection(&mut self, session: &Session, look: &Look) -> Result<()> {
        if !std::mem::take(&mut self.reprojected) {
            return Ok(());
        }
        let (renderer, whole) = match &mut self.checker {
            Some(c) if c.1.width() == self.view.width() && c.1.height() == self.view.height() => c,
            slot => slot.insert((Renderer::new(), Frame::new(self.view.width(), self.view.height())?)),
        };
        let picture = Picture::of(session, look);
        let map = session.editor.heightmap();
        renderer.render(
            &self.trees.scene(&picture, map, Some(session.editor.revisions())),
            whole,
        )?;
        if let (Some((mean_abs, _)), Some(visible)) = (
            self.view.difference(whole),
            self.view.visibly_different(whole, VISIBLE_LEVELS),
        ) {
            self.checks.push(Check { mean_abs, visible });
        }
        Ok(())
    }
}

/// `p`'s scene of `map`, with the terrain's history when known.
fn scene<'a>(p: &'a Picture, map: &'a Heightmap, revisions: Option<&'a Revisions>) -> Scene<'a> {
    Scene {
        revisions,
        ..p.scene(map)
    }
}

/// How long a due frame waits for the head's next pose, device µs: a little over the head's
/// period (60 poses/s and more), so glasses that stop reporting hold no frame up for long.
const HEAD_WAIT_US: u64 = 25_000;

/// The longest a frame takes events before it is drawn anyway.
const LATCH_MAX: Duration = Duration::from_millis(100);

/// Late latching for the tracked head (issue 16): a due frame takes everything the feed holds,
/// and while the glasses report, waits for their next pose, so its view starts right after a
/// pose arrived and shows the newest one, not the one that happened to be in when the frame
/// fell due (up to a head period older), nor one queued behind events that arrived while the
/// last frame was drawn. Only for a real-time feed ([`Session::realtime`]): an unpaced
/// simulation would be run to its end. `said` takes what the feed said; `wait` bounds the wall
/// time it waits for the next pose (a head period, [`HEAD_WAIT_US`]; the test gives a longer
/// one, so a loaded machine's scheduling cannot fail it). Returns whether the feed ended.
fn latch_head(
    rx: &std::sync::mpsc::Receiver<Feed>,
    session: &mut Session,
    said: &mut dyn FnMut(Vec<String>),
    wait: Duration,
) -> bool {
    // Whether the last thing taken was a new pose: the newest, once the feed holds no more.
    let mut fresh = false;
    let started = Instant::now();
    loop {
        let feed = match rx.try_recv() {
            Ok(f) => f,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => return true,
            // The glasses are reporting while their last pose is recent beside the last event.
            Err(std::sync::mpsc::TryRecvError::Empty) if fresh || !session.head_tracked_within(HEAD_WAIT_US) => {
                return false;
            }
            // Real time: a head period of the wall clock bounds the wait (at --speed 1 exactly).
            Err(std::sync::mpsc::TryRecvError::Empty) => match rx.recv_timeout(wait) {
                Ok(f) => f,
                Err(RecvTimeoutError::Timeout) => return false,
                Err(RecvTimeoutError::Disconnected) => return true,
            },
        };
        let done = matches!(feed, Feed::End(_) | Feed::Failed(_));
        // A failure ends the session, which says it then.
        let failed = matches!(feed, Feed::Failed(_));
        let poses = session.head_poses();
        let messages = session.feed(feed);
        if !failed {
            said(messages);
        }
        if done {
            return true;
        }
        fresh = session.head_poses() != poses;
        // Events that take longer to handle than to come would hold the frame up for ever.
        if started.elapsed() > LATCH_MAX {
            return false;
        }
    }
}

/// `--eye-separation-mm`: a number of mm an adult's eyes can be apart, 40…80.
fn eye_separation_mm(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(mm) if (40.0..=80.0).contains(&mm) => Ok(mm),
        _ => Err(format!("{s:?} is not a distance between eyes of 40…80 mm")),
    }
}

#[allow(clippy::too_many_arguments)]
fn run_headless(
    args: &LiveArgs,
    rx: &std::sync::mpsc::Receiver<Feed>,
    session: &mut Session,
    look: &Look,
    painter: &mut Painter,
    stop: &AtomicBool,
    demo_us: Option<u64>,
) -> Result<Written> {
    // No frames at all with --fps 0: the results alone.
    let mut frames = match args.fps {
        0 => None,
        fps => Some(Sequence::create(&args.out.join("frames"), fps)?.moving_every(args.moving_every.into())),
    };
    let step_us = 1_000_000 / u64::from(args.fps.max(1));
    let mut next_us: Option<u64> = None;
    let progress = match demo_us {
        Some(total) => {
            let p = ProgressBar::new(total / 1000);
            p.set_style(
                ProgressStyle::with_template("{spinner} demo {bar:30} {pos}/{len} ms of the session, {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            p
        }
        None => ProgressBar::new_spinner(),
    };
    while !stop.load(Ordering::Relaxed) {
        let feed = match rx.recv_timeout(Duration::from_millis(200)) {
            Ok(f) => f,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        let mut done = matches!(feed, Feed::End(_) | Feed::Failed(_));
        // A failure ends the session, which says it then.
        let failed = matches!(feed, Feed::Failed(_));
        let messages = session.feed(feed);
        if !failed {
            say(messages, Some(&progress));
        }
        if let Some(t) = session.last_event_us() {
            progress.set_position(t / 1000);
            // A reattached device restarts its clock: so do the frames.
            if next_us.is_some_and(|due| t + step_us < due) {
                next_us = None;
            }
            let due = *next_us.get_or_insert(t);
            if let Some(frames) = frames.as_mut().filter(|_| t >= due) {
                // Its head pose's age on the device's clock, drawn and produced (issue 16). In
                // real time the frame is latched to the head's newest pose; an unpaced
                // simulation's frames show the session exactly at their tick.
                let frame = if session.realtime() && !done {
                    let (frame, ended) =
                        painter.session_latched(rx, session, look, false, &mut |m| say(m, Some(&progress)))?;
                    done |= ended;
                    frame
                } else {
                    session.frame_started();
                    painter.session(session, look)?
                };
                session.frame_produced();
                frames.push(frame)?;
                painter.check_reprojection(session, look)?;
                next_us = Some(due + step_us);
                progress.set_message(format!("{} frames", frames.frames().len()));
            }
        }
        if done {
            break;
        }
    }
    progress.finish_and_clear();
    let (count, animation, held) = match frames {
        None => (0, None, 0),
        Some(frames) => {
            let paths = frames.frames().to_vec();
            let animation = frames.finish_animation()?;
            if !args.frames {
                // The animation holds them all; the single frames only on request.
                for f in &paths {
                    std::fs::remove_file(f).with_context(|| format!("cannot remove {}", f.display()))?;
                }
            }
            let held = animation.as_ref().map_or(0, |a| a.held.len());
            (paths.len(), animation.map(|a| a.path), held)
        }
    };
    Ok(Written {
        frames: count,
        animation,
        held,
        shown: false,
    })
}

/// A message shown under the mode line for a while: what a key did (saved, undone, nothing to
/// delete), what the pen's edits said — the window's user may not see the terminal.
struct Notice {
    text: String,
    since: Instant,
}

impl Notice {
    const SHOWN: Duration = Duration::from_secs(4);

    fn lines(notice: &Option<Notice>) -> Vec<String> {
        match notice {
            Some(n) if n.since.elapsed() < Notice::SHOWN => vec![n.text.clone()],
            _ => Vec::new(),
        }
    }
}

/// Says `messages` on stderr and keeps the last for the window.
fn tell(messages: Vec<String>, notice: &mut Option<Notice>) {
    if let Some(last) = messages.last() {
        *notice = Some(Notice {
            text: last.clone(),
            since: Instant::now(),
        });
    }
    say(messages, None);
}

fn run_window(
    mut viewer: Viewer,
    rx: &std::sync::mpsc::Receiver<Feed>,
    session: &mut Session,
    look: &Look,
    painter: &mut Painter,
    stop: &AtomicBool,
) -> Result<Written> {
    const FRAME: Duration = Duration::from_millis(16);
    let mut dirty = true;
    let mut last = Instant::now() - FRAME;
    let mut frames = 0;
    let mut help = false;
    let mut notice: Option<Notice> = None;
    'session: while viewer.is_open() && !stop.load(Ordering::Relaxed) {
        while let Some(e) = viewer.poll() {
            let ViewerEvent::Key(k) = &e else {
                if e == ViewerEvent::Closed {
                    break 'session;
                }
                dirty = true;
                continue;
            };
            match keys::action(k, session.interaction.view().display_mm) {
                Some(KeyAction::Quit) => break 'session,
                Some(KeyAction::Help) => help = !help,
                Some(KeyAction::Overview) => {
                    let next = if painter.overview == Overview::Off {
                        Overview::Corner
                    } else {
                        Overview::Off
                    };
                    painter.set_overview(next)?;
                }
                Some(KeyAction::Save) => {
                    let said = match session.editor.save() {
                        Ok(()) => match session.editor.path() {
                            Some(p) => format!("saved {}", p.display()),
                            None => "saved".to_string(),
                        },
                        Err(e) => format!("cannot save: {e}"),
                    };
                    tell(vec![said], &mut notice);
                }
                Some(KeyAction::Command(c)) => {
                    session.interaction.command(&mut session.editor, c);
                    tell(session.interaction.take_messages(), &mut notice);
                }
                None => tell(vec![format!("key {k} does nothing: h shows the keys")], &mut notice),
            }
            dirty = true;
        }
        // Take what the pen sent until it is time for the next frame.
        let wait = FRAME.saturating_sub(last.elapsed());
        match rx.recv_timeout(wait.max(Duration::from_millis(1))) {
            Ok(feed) => {
                tell(session.feed(feed), &mut notice);
                dirty = true;
                while let Ok(more) = rx.try_recv() {
                    tell(session.feed(more), &mut notice);
                    if last.elapsed() >= FRAME {
                        break;
                    }
                }
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                // The pen has ended; the window stays until it is closed.
                std::thread::sleep(FRAME);
            }
        }
        // A notice going away is a change too.
        let noticed = notice
            .as_ref()
            .is_some_and(|n| n.since.elapsed() < Notice::SHOWN + FRAME * 2);
        if (dirty || noticed) && last.elapsed() >= FRAME {
            let mut frame = if session.realtime() {
                // Latched to the head's newest pose (issue 16); the feed's end shows next round.
                let said = &mut |m| tell(m, &mut notice);
                painter.session_latched(rx, session, look, true, said)?.0.clone()
            } else {
                if let Some(t) = session.last_event_us() {
                    session.interaction.advance(t);
                }
                session.frame_started();
                painter.session(session, look)?.clone()
            };
            let (w, h) = (painter.view.width() as i32, painter.view.height() as i32);
            let viewport = penmodel_render::rasterise::Bounds {
                x0: 0,
                x1: w,
                y0: 0,
                y1: h,
            };
            let style = &look.style;
            ui::panel(
                &mut frame,
                &viewport,
                &Notice::lines(&notice),
                Place::UnderModeLine,
                style,
            );
            if help {
                ui::panel(
                    &mut frame,
                    &viewport,
                    &keys::help_lines(&session.interaction.help()),
                    Place::Centre,
                    style,
                );
            }
            if viewer.show(frame).is_err() {
                break;
            }
            session.frame_produced();
            frames += 1;
            last = Instant::now();
            dirty = session.interaction.pulling() || session.interaction.view().tilt > 1e-3;
        }
    }
    Ok(Written {
        frames,
        animation: None,
        held: 0,
        shown: true,
    })
}

/// Writes the final terrain, its render and the exports; returns what was written, by kind.
fn write_results(
    out: &Path,
    meshes: bool,
    session: &Session,
    look: &Look,
    painter: &mut Painter,
) -> Result<serde_json::Value> {
    let map: &Heightmap = session.editor.heightmap();
    let write = |name: &str, bytes: &[u8]| -> Result<PathBuf> {
        let path = out.join(name);
        penmodel_terrain::persist::write_atomic(&path, bytes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(path)
    };
    let mut bytes = Vec::new();
    export::write_png(map, &mut bytes)?;
    let png = write("terrain.png", &bytes)?;
    bytes.clear();
    export::write_raw(map, &mut bytes)?;
    let raw = write("terrain.f32", &bytes)?;
    // Meshes are large (a 512² grid is 18 MB of OBJ) and derived from the heightmap: on request.
    let (mut obj, mut glb) = (None, None);
    if meshes {
        bytes.clear();
        export::write_obj_with(map, session.editor.rocks().meshes(), &mut bytes)?;
        obj = Some(write("terrain.obj", &bytes)?);
        bytes.clear();
        export::write_glb_with(map, session.editor.rocks().meshes(), &mut bytes)?;
        glb = Some(write("terrain.glb", &bytes)?);
    }
    // The final state, without the pen or a highlight, the ground level: as the display shows
    // it, and from the orbit camera of the overview.
    let view = View {
        tilt: 0.0,
        ..*session.interaction.view()
    };
    let (lo, hi) = map.range();
    let mode = format!("penmodel: final terrain, {lo:.0} to {hi:.0} m");
    // The trees at the last event's time, as the last frame drew them.
    let picture = Picture::document(session.editor.document(), &view, mode, look)
        .with_rocks(session.editor.rocks().shared())
        .with_trees(session.editor.trees().shared())
        .with_time(session.last_event_us().map_or(0.0, |us| us as f64 * 1e-6));
    bytes.clear();
    output::encode_png(painter.plain(&picture, map)?, &mut bytes)?;
    let display = write("display.png", &bytes)?;
    let extent = [
        f64::from(map.cols()) * map.cell_size(),
        f64::from(map.rows()) * map.cell_size(),
    ];
    bytes.clear();
    output::encode_png(painter.plain(&picture.overview(extent), map)?, &mut bytes)?;
    let render = write("render.png", &bytes)?;
    Ok(json!({
        "heightmap_png": png, "heightmap_f32": raw, "mesh_obj": obj, "mesh_glb": glb,
        "render": render, "display": display,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use penmodel::interaction::View;

    #[test]
    fn the_trees_budget_coarsens_late_views_and_recovers() {
        use penmodel_terrain::trees::Roughness;
        let mut b = TreeBudget::new();
        let q0 = Roughness::default().q0;
        assert_eq!(b.apply(Roughness::default()).q0, q0);
        b.after(VIEW_BUDGET_MS + 1.0);
        assert!((b.apply(Roughness::default()).q0 - 1.5 * q0).abs() < 1e-12);
        for _ in 0..20 {
            b.after(3.0 * VIEW_BUDGET_MS);
        }
        assert_eq!(b.apply(Roughness::default()).q0, TreeBudget::MAX_Q0);
        // Within the budget but over 60 % of it: held.
        b.after(0.8 * VIEW_BUDGET_MS);
        assert_eq!(b.apply(Roughness::default()).q0, TreeBudget::MAX_Q0);
        for _ in 0..20 {
            b.after(0.1 * VIEW_BUDGET_MS);
        }
        assert_eq!(b.apply(Roughness::default()).q0, q0);
        // A scene asking for coarser trees than the budget's most keeps its own.
        let coarse = Roughness {
            q0: 0.3,
            ..Roughness::default()
        };
        b.after(3.0 * VIEW_BUDGET_MS);
        assert_eq!(b.apply(coarse).q0, 0.3);
    }

    #[test]
    fn eye_separation_is_a_plausible_distance() {
        assert_eq!(eye_separation_mm("63"), Ok(63.0));
        assert_eq!(eye_separation_mm(" 70.5 "), Ok(70.5));
        for bad in ["", "abc", "39.9", "81", "NaN", "-63"] {
            let e = eye_separation_mm(bad).expect_err(bad);
            assert!(e.contains("40…80 mm"), "{e}");
        }
    }

    #[test]
    fn a_latched_frame_takes_the_newest_pose_and_the_next_one() {
        // Metres right of the 600 mm display's centre, as the camera takes the head.
        let x = |session: &Session| session.head_m().map(|h| h[0]);
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        session.feed(head_at(Some(100.0), 0));
        let (tx, rx) = std::sync::mpsc::channel();
        // Queued while the last frame was drawn: two newer poses, then a report without a fix.
        for f in [
            head_at(Some(110.0), 16_000),
            head_at(Some(120.0), 32_000),
            head_at(None, 40_000),
        ] {
            tx.send(f).expect("queued");
        }
        // The next pose comes once the queue is taken: the frame waits for it (up to `WAIT` of
        // the wall clock here, far more than the sender's 5 ms, so a busy machine cannot fail it).
        const WAIT: Duration = Duration::from_secs(1);
        let later = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(5));
            tx.send(head_at(Some(130.0), 48_000)).expect("sent");
            tx
        });
        let mut said = Vec::new();
        assert!(!latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
        assert_eq!(x(&session), Some((130.0 - 300.0) * 1e-3));
        assert_eq!(session.events(), 5, "everything queued was taken");
        // Glasses that stop reporting hold a frame up no longer than a head period.
        let tx = later.join().expect("sender");
        tx.send(head_at(None, 60_000)).expect("queued");
        assert!(!latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
        assert_eq!((x(&session), session.events()), (Some((130.0 - 300.0) * 1e-3), 6));
        // A feed that ended: said so at once.
        drop(tx);
        assert!(latch_head(&rx, &mut session, &mut |m| said.extend(m), WAIT));
    }

    /// A head report at `device_us`: a pose `u_mm` along the display, or none (no fix).
    fn head_at(u_mm: Option<f64>, device_us: u64) -> Feed {
        use pen_host::events::{DisplayPoint, EventKind, HeadPose, HeadStatus, PenEvent};
        Feed::Event(PenEvent {
            kind: EventKind::Head(HeadPose {
                at: u_mm.map(|u_mm| DisplayPoint {
                    u_mm,
                    v_mm: 170.0,
                    h_mm: 650.0,
                    u_px: 0.0,
                    v_px: 0.0,
                }),
                status: if u_mm.is_some() {
                    HeadStatus::Tracked
                } else {
                    HeadStatus::Held
                },
                prediction_ms: 20,
                refused: 0,
                reason: None,
            }),
            t_us: device_us,
            point: None,
            sw: None,
            seq: Some((0, device_us)),
        })
    }

    #[test]
    fn a_tracked_frame_is_drawn_before_the_pose_and_moved_to_it() {
        use penmodel_terrain::{Figure, FigureKind, Region};
        // An 800 m hill in the middle of the blank map: 8 cm tall on the display at 1:10 000,
        // so an 80 mm move of the head shifts its top by about 6 pixels of 320.
        let mut doc = blank_document();
        let (w, h) = (480.0 * 12.5, 272.0 * 12.5);
        doc.regions.push(Region {
            boundary: vec![
                [100.0, 100.0],
                [w - 100.0, 100.0],
                [w - 100.0, h - 100.0],
                [100.0, h - 100.0],
                [100.0, 100.0],
            ],
            figures: vec![Figure {
                kind: FigureKind::Point,
                points: vec![[0.5 * w, 0.5 * h]],
                height: 800.0,
                slope: 0.0,
                figures: Vec::new(),
            }],
            metric: None,
        });
        let session_at = |poses: &[(f64, u64)]| {
            let mut session = Session::new(
                Editor::new(doc.clone()).expect("valid"),
                [600.0, 340.0],
                Tuning::default(),
            );
            for &(u, t) in poses {
                session.feed(head_at(Some(u), t));
            }
            session
        };
        let look = Look::default();
        let whole = |session: &Session| {
            let mut painter = Painter::new(320, 180, Overview::Off).expect("painter");
            painter.session(session, &look).expect("drawn").clone()
        };
        // The view is drawn from the pose in before the frame; the latch takes a newer one.
        let mut session = session_at(&[(250.0, 0)]);
        let before = whole(&session);
        let (tx, rx) = std::sync::mpsc::channel();
        tx.send(head_at(Some(330.0), 16_000)).expect("queued");
        let mut painter = Painter::new(320, 180, Overview::Off).expect("painter");
        let (shown, ended) = painter
            .session_latched(&rx, &mut session, &look, false, &mut |_| {})
            .expect("drawn");
        let shown = shown.clone();
        assert!(!ended && painter.reprojected, "the view was moved to the newest pose");
        let after = whole(&session);
        let visible = |a: &Frame, b: &Frame| a.visibly_different(b, VISIBLE_LEVELS).expect("same size");
        let (unmoved, moved) = (visible(&before, &after), visible(&shown, &after));
        // The move shows, and the frame is the newest pose's far more than the old one's.
        assert!(unmoved > 0.01, "{unmoved}");
        assert!(moved < 0.5 * unmoved, "{moved} vs {unmoved}");
        // The demo's check compares the same two.
        painter.check_reprojection(&session, &look).expect("checked");
        assert_eq!(painter.checks.len(), 1);
        assert!((painter.checks[0].visible - moved).abs() < 1e-12);
    }

    #[test]
    fn every_layout_draws_at_any_size() {
        let doc = blank_document();
        let map = penmodel_terrain::generate(&doc).expect("valid");
        let view = View::fit([600.0, 340.0], &doc.grid);
        let picture = Picture::document(&doc, &view, "test".into(), &Look::default());
        for (w, h) in [(1, 1), (8, 8), (33, 20), (320, 180)] {
            for (overview, width) in [
                (Overview::Off, w),
                (Overview::Corner, w),
                (Overview::Beside, w + (w / 2).max(1)),
            ] {
                let mut painter = Painter::new(w, h, overview).expect("painter");
                let frame = painter.draw(&picture, &map, None).expect("drawn");
                assert_eq!((frame.width(), frame.height()), (width, h));
            }
        }
    }
}
