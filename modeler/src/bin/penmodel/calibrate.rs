//! `penmodel calibrate`: the calibration on the display itself. A full-screen window draws the
//! targets one at a time with the progress, takes the pen's touch at each through the host
//! driver's own procedure (`pen_host::calibration::run`, as `penctl calibrate`), and ends with
//! the residual plot: the display's axes in mm, each target, where its touch landed after the
//! fit with the error magnified, and a legend. Without a display the terminal prompts, as
//! `penctl calibrate` does.

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::Duration;

use anyhow::{Context, Result, bail};
use glam::DVec2;
use pen_host::calibration::procedure::{self, Prompt};
use pen_host::calibration::run::{self, Outcome, Plan};
use pen_host::calibration::{self, Calibration, plot};
use pen_host::device::Device;
use pen_host::source::Source;
use penmodel::feed::{Calibrating, CalibrationPicture};
use penmodel_render::output::{Viewer, ViewerEvent, WindowError, window};
use penmodel_render::{Bounds, Frame, Place, Rgba, Style, panel};

use crate::live::Show;

/// `penmodel calibrate`'s flags.
#[derive(clap::Args)]
#[command(after_help = "Examples:\n  \
    penmodel calibrate                                   # the first base station on USB, full screen\n  \
    penmodel calibrate --source sim --speed 4            # the simulated pen touches the targets\n  \
    penmodel calibrate --source serial:/dev/ttyACM0 --targets 9 --plot residuals.png\n\
    docs/calibration.md; penctl calibrate is the same calibration at a terminal.")]
pub struct Args {
    /// Which base station: hid (the first on USB), hid:PATH, serial:PATH, or sim (the simulated
    /// pen touching the targets).
    #[arg(long, default_value = "hid", value_name = "SOURCE", value_parser = source_arg)]
    source: String,
    /// The simulated pen's speed: device seconds per second (0: as fast as it is read) [default: 1].
    #[arg(long, value_parser = pen_host::source::speed_value)]
    speed: Option<f64>,
    #[command(flatten)]
    display: pen_host::calibration::args::DisplayArgs,
    /// Where to save the calibration [default: $XDG_CONFIG_HOME/penscape/calibration.toml;
    /// calibration-sim.toml for the simulated pen]. The file pend reads.
    #[arg(long, value_name = "FILE")]
    calibration: Option<PathBuf>,
    /// Also draw the residuals into this PNG (as `penctl calibrate --plot`).
    #[arg(long, value_name = "PNG")]
    plot: Option<PathBuf>,
    /// Skip the pivot (docs/calibration.md, "The pivot").
    #[arg(long)]
    no_pivot: bool,
    /// Seconds to wait for each touch.
    #[arg(long, default_value_t = 60.0)]
    patience: f64,
    /// A window (full screen) if there is a display, else the terminal's prompts.
    #[arg(long, value_enum, default_value_t = Show::Auto)]
    show: Show,
    /// The window at its own size, not full screen (the targets are then not where the tip is).
    #[arg(long)]
    windowed: bool,
    /// Close the window this many seconds after the residual plot is shown (default: at a key).
    #[arg(long, value_name = "SECONDS")]
    close_after: Option<f64>,
}

/// A source `--source` names, for clap (a usage error otherwise).
fn source_arg(s: &str) -> Result<String, String> {
    if s == "sim" {
        return Ok(s.to_string());
    }
    s.parse::<Source>().map(|_| s.to_string()).map_err(|e| e.to_string())
}

/// What the calibration thread tells the window.
enum Step {
    Prompt(Prompt),
    Done(Result<Outcome, String>),
}

/// Runs `penmodel calibrate`.
pub fn run(a: &Args) -> Result<()> {
    let display = a.display.display();
    display.check().context("--display-mm or --display-px")?;
    let mut plan = Plan::new(
        display,
        usize::from(a.display.targets),
        Duration::from_secs_f64(a.patience.max(1.0)),
    );
    if a.no_pivot {
        plan.pivot_at = None;
    }
    let sim = a.source == "sim";
    let mut source = if sim {
        run::sim_source(&plan.targets, plan.pivot_at, 1.0)
    } else {
        a.source
            .parse::<Source>()
            .map_err(|e| anyhow::anyhow!("--source: {e}"))?
    };
    match (&mut source, a.speed) {
        (Source::Sim(o), Some(speed)) => o.speed = speed,
        (_, None) => {}
        // As in pend and penctl: a usage error (2), before anything is opened.
        (_, Some(_)) => clap::Error::raw(
            clap::error::ErrorKind::ArgumentConflict,
            format!(
                "--speed is the simulated pen's (--source sim); {} runs in real time\n",
                a.source
            ),
        )
        .exit(),
    }
    let window_wanted = match a.show {
        Show::Headless => false,
        Show::Window => true,
        Show::Auto => window::has_display(),
    };
    let viewer = if window_wanted {
        match Viewer::open("penmodel calibrate", 1280, 720) {
            Ok(mut v) => {
                if !a.windowed {
                    v.set_fullscreen(true)?;
                }
                Some(v)
            }
            Err(e @ WindowError::NoDisplay) if a.show == Show::Auto => {
                eprintln!("penmodel: {e}; the terminal's prompts instead");
                None
            }
            Err(e) => return Err(e.into()),
        }
    } else {
        None
    };
    // The device lives on the calibration's thread (the simulated pen is not Send).
    let (tx, rx) = mpsc::channel();
    let thread_plan = plan.clone();
    let worker = std::thread::Builder::new()
        .name("calibration".into())
        .spawn(move || calibrate_on_thread(source, &thread_plan, &tx))
        .context("cannot start the calibration's thread")?;
    let outcome = match viewer {
        Some(v) => run_window(v, &rx, &plan, a)?,
        None => run_terminal(&rx)?,
    };
    // Stopped before the end, the calibration's thread may be waiting for a touch: it ends with
    // the process, as `penctl calibrate` stopped by Ctrl-C does.
    let Some(outcome) = outcome else {
        bail!("stopped before the calibration ended: nothing saved");
    };
    let _ = worker.join();
    save(&outcome.calibration, a, sim)
}

fn calibrate_on_thread(source: Source, plan: &Plan, tx: &Sender<Step>) {
    let mut device = Device::new(source);
    let result = procedure::attach(&mut device, Duration::from_secs(5))
        .map_err(anyhow::Error::from)
        .and_then(|()| {
            run::calibrate(&mut device, plan, |p| {
                let _ = tx.send(Step::Prompt(p.clone()));
            })
        })
        .map_err(|e| format!("{e:#}"));
    let _ = tx.send(Step::Done(result));
}

/// Saves the calibration where pend reads it, and the plot if asked; prints the residuals.
fn save(cal: &Calibration, a: &Args, sim: bool) -> Result<()> {
    let simulated = sim || cal.device.is_some_and(|d| d.is_simulated());
    let out = match &a.calibration {
        Some(p) => p.clone(),
        None => calibration::default_path_for(simulated)
            .context("neither XDG_CONFIG_HOME nor HOME is set; give --calibration")?,
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    cal.save(&out).with_context(|| format!("saving {}", out.display()))?;
    println!(
        "calibrated over {} targets: RMS {:.3} mm, max {:.3} mm, scale {:.5}; saved {}",
        cal.residuals.len(),
        cal.rms_mm(),
        cal.max_mm(),
        cal.transform.scale,
        out.display()
    );
    if let Some(png) = &a.plot {
        plot::write_residual_plot(cal, png, 900).with_context(|| format!("writing {}", png.display()))?;
        println!("plot {}", png.display());
    }
    Ok(())
}

/// The terminal's prompts, as `penctl calibrate` says them.
fn run_terminal(rx: &Receiver<Step>) -> Result<Option<Outcome>> {
    for step in rx {
        match step {
            Step::Prompt(p) => {
                if let Some(line) = p.says() {
                    eprintln!("{line}");
                }
            }
            Step::Done(result) => return result.map(Some).map_err(anyhow::Error::msg),
        }
    }
    bail!("the calibration's thread stopped")
}

/// Where the window is in the calibration.
enum Phase {
    Touching,
    Pivot(DVec2),
    Plot(Box<Outcome>, Option<std::time::Instant>),
}

/// The window: the targets one at a time, then the residual plot until a key (or
/// `--close-after`).
fn run_window(mut viewer: Viewer, rx: &Receiver<Step>, plan: &Plan, a: &Args) -> Result<Option<Outcome>> {
    let mut picture = CalibrationPicture::new(&plan.targets);
    let mut state: Calibrating = Calibrating {
        targets: plan.targets.iter().map(|t| [t.x, t.y]).collect(),
        taken: 0,
        pen_mm: None,
        pressed: false,
    };
    let mut phase = Phase::Touching;
    let mut note = String::new();
    let (mut w, mut h) = (1280u32, 720u32);
    let mut dirty = true;
    let display = [plan.display.width_mm, plan.display.height_mm];
    loop {
        while let Some(e) = viewer.poll() {
            match e {
                // Closed at the plot, the calibration is kept; before it, nothing is.
                ViewerEvent::Closed => return Ok(take(phase)),
                ViewerEvent::Resized { width, height } => {
                    (w, h) = (width.max(1), height.max(1));
                    dirty = true;
                }
                ViewerEvent::Key(k) => match (&phase, k.as_str()) {
                    (Phase::Plot(..), _) => return Ok(take(phase)),
                    (_, "Escape" | "q") => return Ok(None),
                    _ => {}
                },
                ViewerEvent::Pointer(_) => {}
            }
        }
        // Everything the calibration said since the last frame, then one frame.
        let first = rx.recv_timeout(Duration::from_millis(16));
        let more = std::iter::from_fn(|| rx.try_recv().ok().map(Ok));
        for step in std::iter::once(first).chain(more) {
            match step {
                Ok(Step::Prompt(p)) => {
                    if let Some(s) = picture.after(&p) {
                        state = s;
                    }
                    match &p {
                        Prompt::Pivot { at_mm } => phase = Phase::Pivot(*at_mm),
                        Prompt::Lift | Prompt::Again { .. } | Prompt::PivotAgain { .. } => {
                            note = p.says().unwrap_or_default().trim().to_string();
                        }
                        Prompt::Touch { .. } | Prompt::Taken { .. } | Prompt::Pivoted { .. } => note.clear(),
                        Prompt::Pen { .. } => {}
                    }
                    dirty = true;
                }
                Ok(Step::Done(Ok(outcome))) => {
                    let until = a
                        .close_after
                        .map(|s| std::time::Instant::now() + Duration::from_secs_f64(s.max(0.0)));
                    phase = Phase::Plot(Box::new(outcome), until);
                    dirty = true;
                }
                Ok(Step::Done(Err(why))) => bail!("calibration: {why}"),
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    if !matches!(phase, Phase::Plot(..)) {
                        bail!("the calibration's thread stopped");
                    }
                    std::thread::sleep(Duration::from_millis(16));
                }
            }
        }
        if let Phase::Plot(_, Some(until)) = &phase
            && std::time::Instant::now() >= *until
        {
            return Ok(take(phase));
        }
        if dirty {
            let mut frame = Frame::new(w, h)?;
            match &phase {
                Phase::Touching => draw_targets(&mut frame, display, &state, None, &note),
                Phase::Pivot(at) => draw_targets(&mut frame, display, &state, Some(*at), &note),
                Phase::Plot(outcome, _) => draw_plot(&mut frame, display, &outcome.calibration),
            }
            if viewer.show(frame).is_err() {
                return Ok(take(phase));
            }
            dirty = false;
        }
    }
}

fn take(phase: Phase) -> Option<Outcome> {
    match phase {
        Phase::Plot(o, _) => Some(*o),
        _ => None,
    }
}

const BACKGROUND: Rgba = [24, 26, 30, 255];
const TARGET: Rgba = [255, 214, 64, 255];
const DONE: Rgba = [90, 200, 110, 255];
const FAINT: Rgba = [90, 94, 102, 255];
const PEN: Rgba = [240, 240, 240, 255];
const PRESSED: Rgba = [80, 160, 255, 255];
const AXIS: Rgba = [170, 174, 182, 255];
const RESIDUAL: Rgba = [240, 90, 80, 255];

/// Display mm (`v` up from the lower edge) to the frame's pixels, the frame showing the whole
/// display.
fn to_px(frame: &Frame, display: [f64; 2], [u, v]: [f64; 2]) -> (f64, f64) {
    (
        u / display[0] * f64::from(frame.width()),
        (1.0 - v / display[1]) * f64::from(frame.height()),
    )
}

fn put(frame: &mut Frame, x: i64, y: i64, c: Rgba) {
    let (w, h) = (i64::from(frame.width()), i64::from(frame.height()));
    if (0..w).contains(&x) && (0..h).contains(&y) {
        frame.pixels_mut()[(y * w + x) as usize] = c;
    }
}

/// A line `r` pixels thick (a square pen) from `a` to `b`.
fn line(frame: &mut Frame, a: (f64, f64), b: (f64, f64), r: i64, c: Rgba) {
    let n = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as i64).max(1);
    for i in 0..=n {
        let t = i as f64 / n as f64;
        let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        for dx in -r..=r {
            for dy in -r..=r {
                put(frame, x.round() as i64 + dx, y.round() as i64 + dy, c);
            }
        }
    }
}

/// A ring of `radius` pixels, `thick` wide.
fn ring(frame: &mut Frame, (cx, cy): (f64, f64), radius: f64, thick: f64, c: Rgba) {
    let reach = (radius + thick).ceil() as i64;
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            let d = ((dx * dx + dy * dy) as f64).sqrt();
            if (d - radius).abs() <= thick / 2.0 {
                put(frame, cx.round() as i64 + dx, cy.round() as i64 + dy, c);
            }
        }
    }
}

fn disc(frame: &mut Frame, (cx, cy): (f64, f64), radius: f64, c: Rgba) {
    let reach = radius.ceil() as i64;
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            if ((dx * dx + dy * dy) as f64).sqrt() <= radius {
                put(frame, cx.round() as i64 + dx, cy.round() as i64 + dy, c);
            }
        }
    }
}

fn all(frame: &Frame) -> Bounds {
    Bounds {
        x0: 0,
        y0: 0,
        x1: frame.width() as i32,
        y1: frame.height() as i32,
    }
}

fn text(frame: &mut Frame, lines: &[String], place: Place) {
    let b = all(frame);
    panel(frame, &b, lines, place, &Style::default());
}

/// The target to touch (a ring with a cross, and the others faint: taken green), the pen's tip,
/// and the progress at the top: `pivot` instead during the pivot.
fn draw_targets(frame: &mut Frame, display: [f64; 2], s: &Calibrating, pivot: Option<DVec2>, note: &str) {
    frame.pixels_mut().fill(BACKGROUND);
    let mm = f64::from(frame.width()) / display[0];
    for (i, t) in s.targets.iter().enumerate() {
        let at = to_px(frame, display, *t);
        if i < s.taken {
            disc(frame, at, 1.5 * mm, DONE);
        } else if i > s.taken || pivot.is_some() {
            ring(frame, at, 3.0 * mm, 2.0, FAINT);
        }
    }
    let (next, what) = match pivot {
        Some(at) => (
            Some([at.x, at.y]),
            "pivot: hold the tip on the ring and press; tilt the pen, its top circling once; then lift".to_string(),
        ),
        None => (
            s.targets.get(s.taken).copied(),
            format!(
                "target {} of {}: touch the centre of the ring with the tip and press",
                (s.taken + 1).min(s.targets.len()),
                s.targets.len()
            ),
        ),
    };
    if let Some(t) = next {
        let at = to_px(frame, display, t);
        ring(frame, at, 6.0 * mm, 3.0, TARGET);
        let arm = 12.0 * mm;
        line(frame, (at.0 - arm, at.1), (at.0 + arm, at.1), 0, TARGET);
        line(frame, (at.0, at.1 - arm), (at.0, at.1 + arm), 0, TARGET);
    }
    if let Some(p) = s.pen_mm {
        let at = to_px(frame, display, p);
        disc(frame, at, 1.2 * mm, if s.pressed { PRESSED } else { PEN });
    }
    // The progress: a bar across the top, a segment per target, and the words under it.
    let (w, count) = (f64::from(frame.width()), s.targets.len().max(1));
    let (x0, x1, y) = (0.25 * w, 0.75 * w, 0.12 * f64::from(frame.height()));
    for i in 0..count {
        let a = x0 + (x1 - x0) * i as f64 / count as f64;
        let b = x0 + (x1 - x0) * (i + 1) as f64 / count as f64 - 4.0;
        line(frame, (a, y), (b, y), 3, if i < s.taken { DONE } else { FAINT });
    }
    let mut lines = vec![what];
    if !note.is_empty() {
        lines.push(note.to_string());
    }
    lines.push("Esc: stop without saving".to_string());
    text(
        frame,
        &lines,
        Place::CentredOn {
            x: (w / 2.0) as i64,
            y: (y + 48.0) as i64,
        },
    );
}

/// The residual plot: the display as axes in mm (ticks every 100 mm), each target (a ring),
/// where its touch landed after the fit with the error × [`plot::MAGNIFY`] (a line to a dot),
/// a scale bar, the figures and a legend.
fn draw_plot(frame: &mut Frame, display: [f64; 2], cal: &Calibration) {
    frame.pixels_mut().fill(BACKGROUND);
    let (w, h) = (f64::from(frame.width()), f64::from(frame.height()));
    // The plot's area: the display's shape, inset for the labels.
    // Above it the legend (four lines), below it the u axis's labels.
    let scale = ((w - 160.0) / display[0]).min((h - 260.0) / display[1]).max(0.1);
    let (ox, oy) = (100.0, h - 80.0);
    let at = |[u, v]: [f64; 2]| (ox + u * scale, oy - v * scale);
    let (x1, y1) = at(display);
    line(frame, (ox, oy), (x1, oy), 0, AXIS);
    line(frame, (ox, oy), (ox, y1), 0, AXIS);
    line(frame, (x1, oy), (x1, y1), 0, FAINT);
    line(frame, (ox, y1), (x1, y1), 0, FAINT);
    let tick = |frame: &mut Frame, label: String, (x, y): (f64, f64)| {
        text(
            frame,
            &[label],
            Place::CentredOn {
                x: x as i64,
                y: y as i64,
            },
        );
    };
    let mut u = 0.0;
    while u <= display[0] + 1e-9 {
        let (x, _) = at([u, 0.0]);
        line(frame, (x, oy), (x, oy + 6.0), 0, AXIS);
        tick(frame, format!("{u:.0}"), (x, oy + 22.0));
        u += 100.0;
    }
    let mut v = 0.0;
    while v <= display[1] + 1e-9 {
        let (_, y) = at([0.0, v]);
        line(frame, (ox - 6.0, y), (ox, y), 0, AXIS);
        tick(frame, format!("{v:.0}"), (ox - 36.0, y));
        v += 100.0;
    }
    tick(frame, "u (mm, along the display)".into(), ((ox + x1) / 2.0, oy + 48.0));
    tick(frame, "v (mm)".into(), (ox - 40.0, y1 - 24.0));
    for r in &cal.residuals {
        let t = at([r.target_mm.x, r.target_mm.y]);
        let fitted = cal.transform.apply(r.touched_mm);
        let e = (DVec2::new(fitted.x, fitted.y) - r.target_mm) * plot::MAGNIFY;
        let landed = at([r.target_mm.x + e.x, r.target_mm.y + e.y]);
        ring(frame, t, 7.0, 2.0, TARGET);
        line(frame, t, landed, 1, RESIDUAL);
        disc(frame, landed, 3.5, RESIDUAL);
    }
    // The scale bar: 1 mm of error, magnified.
    let (bx, by) = (x1 - plot::MAGNIFY * scale, y1 - 16.0);
    line(frame, (bx, by), (x1, by), 1, RESIDUAL);
    text(
        frame,
        &[format!("1 mm error (× {:.0})", plot::MAGNIFY)],
        Place::CentredOn {
            x: ((bx + x1) / 2.0) as i64,
            y: (by - 18.0) as i64,
        },
    );
    let legend = vec![
        format!(
            "calibrated over {} targets: RMS {:.3} mm, max {:.3} mm, scale {:.5}",
            cal.residuals.len(),
            cal.rms_mm(),
            cal.max_mm(),
            cal.transform.scale
        ),
        "yellow ring: a target, where it is on the display (axes in mm)".to_string(),
        format!(
            "red line and dot: where its touch landed after the fit, the error × {:.0}",
            plot::MAGNIFY
        ),
        "any key (or closing the window) saves it and ends".to_string(),
    ];
    text(frame, &legend, Place::UnderModeLine);
}
