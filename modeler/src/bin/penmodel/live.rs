//! `penmodel` without a subcommand, and `penmodel open`: model terrain with the pen.
//!
//! The pen comes from `--source` (default: pend's socket if pend is running, else the built-in
//! demo); the session is shown in a window when there is a display, else written to a folder
//! (`--out`): PNG frames and their animation, then the final terrain (16-bit PNG, float32,
//! OBJ, glTF), a render of it, and the document (JSON), which is also journaled as it is edited.

mod document;
mod headless;
mod results;
mod window;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result, bail};
use indicatif::ProgressBar;
use penmodel::feed::{self, PenSource};
use penmodel::interaction::Tuning;
use penmodel::interaction::stats::count;
use penmodel::latency;
use penmodel::painter::{Overview, Painter};
use penmodel::picture::Look;
use penmodel::session::{Session, State};
use penmodel_render::Stereo;
use penmodel_render::output::{self, Viewer, WindowError};
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
    /// serial:PATH, mouse (the window's mouse or tablet pointer: left draws, right is SW2, the
    /// wheel lifts, middle or Space is SW3), none (keyboard only), sim (the built-in demo: the
    /// simulated pen calibrates on nine targets, then plays modeling-session) or sim:SCENARIO (a
    /// pen-sim scenario, uncalibrated) [default: daemon if pend is running; else sim for a new
    /// session, mouse for `open` in a window].
    #[arg(long, value_name = "SOURCE", value_parser = source)]
    source: Option<String>,
    /// Window, files, or a window when there is a display.
    #[arg(long, value_enum, default_value = "auto")]
    show: Show,
    /// The folder for frames and results (always a folder: the document, the terrain, renders)
    /// [default: out for a new session; for `open DOC`, DOC's name with `.out` beside it, so
    /// `open maps/alps.json` writes maps/alps.out/].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
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
    /// Open the window full screen (F11 toggles it), so the picture covers the display and lines
    /// up with the pen's tip.
    #[arg(long)]
    fullscreen: bool,
    /// Play a pen-sim scenario (sim:SCENARIO) again and again; without it the session ends with
    /// the scenario.
    #[arg(long = "loop")]
    r#loop: bool,
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

impl LiveArgs {
    /// The results' folder: `--out`, or its default for a session on `open`.
    fn out(&self) -> &Path {
        self.out.as_deref().unwrap_or(Path::new("out"))
    }

    /// These options with `--out`'s default for `open` filled in.
    fn resolved(&self, open: Option<&Path>) -> LiveArgs {
        let mut args = self.clone();
        if args.out.is_none()
            && let Some(doc) = open
        {
            let stem = doc
                .file_stem()
                .map(|s| s.to_os_string())
                .unwrap_or_else(|| "document".into());
            let mut name = stem;
            name.push(".out");
            args.out = Some(doc.with_file_name(name));
        }
        args
    }
}

/// A pen source's name, checked.
fn source(s: &str) -> Result<String, String> {
    PenSource::parse(s, 0.0).map(|_| s.to_string())
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
                "penmodel: no pen (pend is not running at {}): the mouse is the pen; start pend, or give \
                 --source hid|serial:PATH, to model with the 3D pen",
                socket.display()
            );
            Ok("mouse".into())
        }
        Some(doc) => bail!(
            "no pen to model {} with: pend is not running at {}. Start pend (pend --source hid, or pend --source serial:PATH), \
             or give --source hid|serial:PATH; --source sim plays the built-in demo into this document",
            doc.display(),
            socket.display()
        ),
    }
}

/// A new session (`doc` = None) or `penmodel open DOC` (`--recover`: `recover`).
pub fn run(args: &LiveArgs, open: Option<&Path>, recover: bool) -> Result<()> {
    let args = &args.resolved(open);
    let window_wanted = match args.show {
        Show::Headless => false,
        Show::Window => true,
        Show::Auto => output::window::has_display(),
    };
    let (source_name, source) = pen_source(args, open, window_wanted)?;
    if matches!(source, PenSource::Mouse) && !window_wanted {
        // A usage error (2), before anything is created.
        clap::Error::raw(
            clap::error::ErrorKind::ArgumentConflict,
            "--source mouse needs a window (--show window, or a display for --show auto)\n",
        )
        .exit();
    }
    // The mouse's mapping is read first, so a bad settings file ends the run before anything
    // is created (exit 1, naming the file and the key).
    let mouse_map = match source {
        PenSource::Mouse => Some(penmodel::config::load()?.mouse),
        _ => None,
    };
    let demo = matches!(source, PenSource::Demo { .. });
    // What this session creates it removes again if nothing is modeled: no empty results.
    let mut created = document::Created {
        out: (!args.out().exists()).then(|| args.out().to_path_buf()),
        frames: (!args.out().join("frames").exists()).then(|| args.out().join("frames")),
        ..document::Created::default()
    };
    std::fs::create_dir_all(args.out()).with_context(|| format!("cannot create {}", args.out().display()))?;
    let opened = document::open(args, open, recover, demo, &mut created);
    let (editor, doc_path) = created.on_error(opened)?;
    let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
    session.set_vertical_scale(args.vertical_scale);
    let look = look(args);

    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        created.on_error(signal_hook::flag::register(signal, stop.clone()).context("installing signal handlers"))?;
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
            Ok(mut v) => {
                if args.fullscreen {
                    v.set_fullscreen(true)?;
                }
                Some(v)
            }
            Err(e @ WindowError::NoDisplay) if args.show == Show::Auto => {
                eprintln!("penmodel: {e}; writing files instead");
                None
            }
            Err(e) => return created.on_error(Err(e.into())),
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
    let mut painter = created.on_error(Painter::new(w, h, layout).map_err(anyhow::Error::from))?;
    let written = match viewer {
        Some(v) => {
            let mouse = mouse_map.map(penmodel::mouse::MousePen::with_map);
            let options = window::Options {
                mouse,
                fullscreen: args.fullscreen,
            };
            window::run(v, &rx, &mut session, &look, &mut painter, &stop, options)
        }
        None => headless::run(args, &rx, &mut session, &look, &mut painter, &stop, demo_us),
    };
    // A session that failed before modeling anything leaves nothing behind; one that modeled
    // keeps its document and journal.
    let written = if session.editor.can_undo() || session.editor.can_redo() {
        written?
    } else {
        created.on_error(written)?
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
    // The results show the document's land: the erosion a last edit started runs to its end.
    session.editor.finish_erosion();
    session
        .editor
        .save()
        .with_context(|| format!("cannot save {}", doc_path.display()))?;
    let results_size = match (args.size, windowed) {
        (Some(size), _) => size,
        (None, true) => (painter.view_frame().width(), painter.view_frame().height()),
        (None, false) => (960, 540),
    };
    let mut results_painter = Painter::new(results_size.0, results_size.1, Overview::Off)?;
    let results = results::write(args.out(), args.meshes, &session, &look, &mut results_painter)?;
    summary(args, &source_name, &doc_path, &session, &painter, &written, results)?;
    if let State::Failed(why) = session.state() {
        bail!("the pen failed: {why}");
    }
    Ok(())
}

/// The pen `--source` names (or the default one), with `--speed` and `--seed` applied.
fn pen_source(args: &LiveArgs, open: Option<&Path>, window_wanted: bool) -> Result<(String, PenSource)> {
    let source_name = match &args.source {
        Some(s) => s.clone(),
        None => default_source(open, window_wanted)?,
    };
    let speed = args.speed.unwrap_or(if window_wanted { 1.0 } else { 0.0 });
    let mut source = PenSource::parse(&source_name, speed).map_err(anyhow::Error::msg)?;
    let simulated = matches!(source, PenSource::Demo { .. })
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
    if let PenSource::Device { looping, .. } = &mut source {
        *looping = args.r#loop;
    }
    if let PenSource::Demo { seed, .. } = &mut source {
        *seed = args.seed;
    }
    Ok((source_name, source))
}

/// How the session is looked at: `--head-mm`, `--eye-separation-mm`, `--stereo`.
fn look(args: &LiveArgs) -> Look {
    let mut look = Look::default();
    if let Some(h) = args.head_mm.or(args.head) {
        look.head_m = h;
    }
    look.eye_separation_m = args.eye_separation_mm * 1e-3;
    look.stereo = match args.stereo {
        StereoArg::None => Stereo::None,
        StereoArg::Anaglyph => Stereo::Anaglyph,
        StereoArg::SideBySide => Stereo::SideBySide,
    };
    look
}

/// Prints what the session did: a line for a person, or the JSON summary (`--json`).
fn summary(
    args: &LiveArgs,
    source_name: &str,
    doc_path: &Path,
    session: &Session,
    painter: &Painter,
    written: &Written,
    results: serde_json::Value,
) -> Result<()> {
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
            "head_latency": latency::head_json(session.head_latency(), painter.checks()),
        });
        pen_host::outln!("{summary}");
    } else {
        pen_host::outln!(
            "{state}: {}; {}; terrain {}",
            count(session.events(), "pen event"),
            stats.summary(),
            crate::out::metres_range(lo, hi),
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
        if let Some(line) = latency::head_line(session.head_latency(), painter.checks()) {
            pen_host::outln!("{line}");
        }
        let meshes = if args.meshes { ", its meshes" } else { "" };
        pen_host::outln!(
            "{what} the terrain{meshes}, its render and the document to {}/ (document: {})",
            args.out().display(),
            doc_path.display()
        );
    }
    Ok(())
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

/// `--eye-separation-mm`: a number of mm an adult's eyes can be apart, 40…80.
fn eye_separation_mm(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(mm) if (40.0..=80.0).contains(&mm) => Ok(mm),
        _ => Err(format!("{s:?} is not a distance between eyes of 40…80 mm")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eye_separation_is_a_plausible_distance() {
        assert_eq!(eye_separation_mm("63"), Ok(63.0));
        assert_eq!(eye_separation_mm(" 70.5 "), Ok(70.5));
        for bad in ["", "abc", "39.9", "81", "NaN", "-63"] {
            let e = eye_separation_mm(bad).expect_err(bad);
            assert!(e.contains("40…80 mm"), "{e}");
        }
    }
}
