//! Where the modeler's pen events come from, on a thread of their own.
//!
//! - [`PenSource::Demo`]: the built-in demo. The simulated pen (pen-sim: hand, acoustics, the
//!   real firmware core) on a display that is not where the tracker thinks it is; the host's
//!   calibration procedure touches nine targets and fits the display's pose, and the pen tilted about
//!   its tip on the centre (the pivot) says where the tip is from the emitter; then the hand
//!   performs the seed-like modeling session ([`pen_sim::session`]). Every report goes as bytes
//!   through the host's decoding, the fitted calibration and the event detector — the chain a
//!   real pen goes through.
//! - [`PenSource::Daemon`]: events from `pend`'s socket.
//! - [`PenSource::Device`]: a base station over USB HID or serial, with a calibration file.
//! - [`PenSource::Mouse`]: the window's pointer as the pen ([`crate::mouse`]).
//! - [`PenSource::None`]: no pen; the document is looked at and edited from the keyboard.
//!
//! The thread sends [`Feed`] messages over a bounded channel: when the modeler is slower than
//! the source (rendering frames of a demo that runs faster than real time), the source waits.
//! It stops when the receiver is dropped.

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;
use std::time::Duration;

use glam::DVec2;
use pen_host::calibration::pivot::{fit_pivot, tip_offset};
use pen_host::calibration::procedure::{CalibrateError, Prompt, attach, collect_pivot, collect_touches, prepare};
use pen_host::calibration::{Calibration, DisplaySize, FitKind, fit};
use pen_host::client::{Client, ClientError, Line};
use pen_host::device::Device;
use pen_host::events::PenEvent;
use pen_host::pipeline::Pipeline;
use pen_host::source::{Source, SourceError};
use pen_host::transport::sim::{DeviceClock, SimOptions, SimPlug};
use pen_sim::Scenario;
use pen_sim::acoustics::Acoustics;
use pen_sim::rig::Rig;

/// What the pen thread says.
#[derive(Debug, Clone, PartialEq)]
pub enum Feed {
    /// The display the events are calibrated to, `[width, height]` mm.
    Display([f64; 2]),
    /// Something to tell the user: attaching, calibrating.
    Status(String),
    /// The simulated device's clock (the demo, `sim:SCENARIO`): frames are timed on it against
    /// the head reports' timestamps ([`crate::latency`]).
    Clock(DeviceClock),
    /// The calibration procedure as it goes: the targets and the pen, for a picture of it.
    Calibrating(Calibrating),
    /// A pen event in the display frame.
    Event(PenEvent),
    /// The source has ended normally (the demo's session is over, pend closed the socket).
    End(String),
    /// The source failed and cannot go on.
    Failed(String),
}

/// The calibration procedure as it goes, in display mm (`v` up from the lower edge).
#[derive(Debug, Clone, PartialEq)]
pub struct Calibrating {
    /// The targets, in the order they are touched.
    pub targets: Vec<[f64; 2]>,
    /// How many are taken: the next to touch is `targets[taken]`.
    pub taken: usize,
    /// The pen's tip, where the display probably is: before the fit, the tracker frame shifted
    /// by the mean offset between the targets taken and where they were touched. `None` out of
    /// range.
    pub pen_mm: Option<[f64; 2]>,
    /// The tip is pressed.
    pub pressed: bool,
}

/// Device µs between two pictures of the pen during calibration: 30 a second is smooth enough.
const CALIBRATION_PEN_US: u64 = 33_000;

/// Turns the procedure's prompts into [`Calibrating`] pictures (the demo's, `penmodel
/// calibrate`'s).
pub struct CalibrationPicture {
    state: Calibrating,
    /// Sum of (target − touched) over the taken targets, for the pen's guessed offset.
    offset_sum: DVec2,
    last_pen_us: Option<u64>,
}

impl CalibrationPicture {
    /// Nothing taken yet of `targets`.
    pub fn new(targets: &[DVec2]) -> CalibrationPicture {
        CalibrationPicture {
            state: Calibrating {
                targets: targets.iter().map(|t| [t.x, t.y]).collect(),
                taken: 0,
                pen_mm: None,
                pressed: false,
            },
            offset_sum: DVec2::ZERO,
            last_pen_us: None,
        }
    }

    /// The picture after `prompt`, if it changed enough to be worth sending.
    pub fn after(&mut self, prompt: &Prompt) -> Option<Calibrating> {
        match prompt {
            Prompt::Touch { index, .. } => self.state.taken = *index,
            Prompt::Taken { touched_mm, .. } => {
                if let Some(t) = self.state.targets.get(self.state.taken) {
                    self.offset_sum += DVec2::from(*t) - touched_mm.truncate();
                }
                self.state.taken += 1;
            }
            Prompt::Pen {
                position_mm,
                pressed,
                device_us,
            } => {
                let press_changed = *pressed != self.state.pressed;
                if !press_changed
                    && self
                        .last_pen_us
                        .is_some_and(|t| device_us.saturating_sub(t) < CALIBRATION_PEN_US)
                {
                    return None;
                }
                self.last_pen_us = Some(*device_us);
                let offset = match self.state.taken {
                    0 => DVec2::ZERO,
                    n => self.offset_sum / n.min(self.state.targets.len()) as f64,
                };
                let at = position_mm.truncate() + offset;
                self.state.pen_mm = Some([at.x, at.y]);
                self.state.pressed = *pressed;
            }
            Prompt::Lift
            | Prompt::Again { .. }
            | Prompt::Pivot { .. }
            | Prompt::PivotAgain { .. }
            | Prompt::Pivoted { .. } => return None,
        }
        Some(self.state.clone())
    }
}

/// A pen to model with.
#[derive(Debug, Clone)]
// One per session, never in a collection: a device source may carry a simulated scenario.
#[allow(clippy::large_enum_variant)]
pub enum PenSource {
    /// The built-in demo through the whole chain.
    Demo {
        /// Device seconds per wall-clock second; 0 runs as fast as the modeler reads.
        speed: f64,
        /// The simulation's randomness.
        seed: u64,
    },
    /// `pend`'s socket.
    Daemon(PathBuf),
    /// No pen: the session is looked at and edited from the keyboard.
    None,
    /// The window's mouse or tablet pointer as the pen ([`crate::mouse`]); the window makes its
    /// events, the pen thread only says so.
    Mouse,
    /// A device, and its calibration file (`None`: the default file if it exists).
    Device {
        /// HID, serial, or a named simulated scenario.
        source: Source,
        /// The calibration file.
        calibration: Option<PathBuf>,
        /// A simulated scenario plays again and again rather than once (`--loop`).
        looping: bool,
    },
}

impl PenSource {
    /// `sim` (the demo), `none`, `mouse`, `daemon`, `daemon:SOCKET`, `hid`, `hid:PATH`, `serial:PATH` or
    /// `sim:SCENARIO` (a named pen-sim scenario with an identity calibration).
    pub fn parse(s: &str, speed: f64) -> Result<PenSource, String> {
        match s.split_once(':') {
            None if s == "sim" => Ok(PenSource::Demo { speed, seed: 1 }),
            None if s == "none" => Ok(PenSource::None),
            None if s == "mouse" => Ok(PenSource::Mouse),
            None if s == "daemon" => Ok(PenSource::Daemon(pen_host::daemon::default_socket())),
            Some(("daemon", path)) if !path.is_empty() => Ok(PenSource::Daemon(PathBuf::from(path))),
            _ => {
                let mut source: Source = s.parse().map_err(|e| match e {
                    SourceError::UnknownKind { given } => format!(
                        "unknown source {given:?}: sim (the built-in demo), sim:SCENARIO, mouse, none, daemon, \
                         daemon:SOCKET, hid, hid:PATH or serial:PATH"
                    ),
                    other => other.to_string(),
                })?;
                if let Source::Sim(o) = &mut source {
                    o.speed = speed;
                }
                Ok(PenSource::Device {
                    source,
                    calibration: None,
                    looping: false,
                })
            }
        }
    }
}

/// The demo: nine calibration touches, then the modeling session; and the calibration targets.
pub fn demo_scenario() -> (Scenario, Vec<DVec2>) {
    let rig = Rig::hand_placed_display();
    let targets = DisplaySize::REFERENCE.targets(9);
    let calibration =
        pen_sim::scenarios::calibration(&targets, Some(DisplaySize::REFERENCE.pivot_target()), rig.clone());
    let session = pen_sim::session::timeline(&pen_sim::session::steps(), pen_sim::scenarios::home());
    let timeline = calibration.timeline.then(&session);
    let scenario = pen_sim::session::watched(Scenario::new("demo", rig, Acoustics::clean(), timeline));
    (scenario, targets)
}

/// Starts the pen thread; `capacity` bounds the messages waiting to be read.
pub fn spawn(source: PenSource, capacity: usize) -> (Receiver<Feed>, JoinHandle<()>) {
    let (tx, rx) = sync_channel(capacity);
    let handle = std::thread::Builder::new()
        .name("pen".into())
        .spawn(move || {
            let result = match source {
                PenSource::Demo { speed, seed } => run_demo(&tx, speed, seed),
                PenSource::Daemon(path) => run_daemon(&tx, &path),
                // Said once; the channel then closes and the session goes on without a pen.
                PenSource::None => send(&tx, Feed::Status("no pen: keyboard only".into())),
                PenSource::Mouse => send(
                    &tx,
                    Feed::Status("the mouse is the pen; h shows its buttons and every tool's gestures".into()),
                ),
                PenSource::Device {
                    source,
                    calibration,
                    looping,
                } => run_device(&tx, source, calibration, looping),
            };
            // A closed channel means the modeler is gone: nothing to tell.
            if let Err(Stop::Failed(why)) = result {
                let _ = tx.send(Feed::Failed(why));
            }
        })
        .map_err(|e| e.to_string());
    match handle {
        Ok(h) => (rx, h),
        Err(why) => {
            // No thread: the receiver reports the failure at once.
            let (tx, rx) = sync_channel(1);
            let _ = tx.send(Feed::Failed(format!("cannot start the pen thread: {why}")));
            (rx, std::thread::spawn(|| {}))
        }
    }
}

enum Stop {
    /// The receiver is gone.
    Closed,
    /// The source failed.
    Failed(String),
}

fn send(tx: &SyncSender<Feed>, feed: Feed) -> Result<(), Stop> {
    tx.send(feed).map_err(|_| Stop::Closed)
}

fn run_demo(tx: &SyncSender<Feed>, speed: f64, seed: u64) -> Result<(), Stop> {
    let (scenario, targets) = demo_scenario();
    let end_us = (scenario.timeline.duration_s() * 1e6) as u64;
    let plug = SimPlug::default();
    send(tx, Feed::Clock(plug.clock()))?;
    let mut device = Device::new(Source::Sim(SimOptions {
        scenario,
        seed,
        speed,
        plug,
    }));
    attach(&mut device, Duration::from_secs(5)).map_err(failed("the simulated pen"))?;
    prepare(&mut device).map_err(failed("calibration"))?;
    send(
        tx,
        Feed::Status(format!("calibrating: the pen touches {} targets", targets.len())),
    )?;
    let mut closed = false;
    let mut taken = 0;
    let count = targets.len();
    let mut picture = CalibrationPicture::new(&targets);
    let touched = collect_touches(&mut device, &targets, Duration::from_secs(60), |step| {
        if let Some(p) = picture.after(step) {
            closed |= tx.send(Feed::Calibrating(p)).is_err();
        }
        if let Prompt::Taken { fixes, .. } = step {
            taken += 1;
            let line = format!("calibrating: target {taken} of {count} taken ({fixes} fixes)");
            closed |= tx.send(Feed::Status(line)).is_err();
        }
    })
    .map_err(failed("calibration"))?;
    if closed {
        return Err(Stop::Closed);
    }
    // The pivot: where the tip is from the emitter, for the glasses' positions (issue 16).
    let at = DisplaySize::REFERENCE.pivot_target();
    send(
        tx,
        Feed::Status("calibrating: the pen tilts about its tip on the centre".into()),
    )?;
    let mut picture_pen = |step: &Prompt| {
        if let Some(p) = picture.after(step) {
            closed |= tx.send(Feed::Calibrating(p)).is_err();
        }
    };
    let fixes =
        collect_pivot(&mut device, at, Duration::from_secs(60), &mut picture_pen).map_err(failed("calibration"))?;
    if closed {
        return Err(Stop::Closed);
    }
    let pivot = fit_pivot(&fixes).map_err(|e| Stop::Failed(format!("calibration: {e}")))?;
    let mut calibration = fit(&targets, &touched, FitKind::Similarity, DisplaySize::REFERENCE)
        .map_err(|e| Stop::Failed(format!("calibration: {e}")))?;
    calibration.tip_offset_mm = Some(tip_offset(&calibration, &pivot, at));
    send(tx, Feed::Display(display_mm(&calibration)))?;
    send(
        tx,
        Feed::Status(format!(
            "calibrated over {count} targets: RMS {:.2} mm, worst {:.2} mm; the emitter {:.1} mm from the tip",
            calibration.rms_mm(),
            calibration.max_mm(),
            pivot.radius_mm
        )),
    )?;
    let mut pipeline = Pipeline::with_device(device, calibration);
    let mut events = Vec::new();
    loop {
        let sample = pipeline.poll(Duration::from_millis(100), &mut events);
        for e in events.drain(..) {
            send(tx, Feed::Event(e))?;
        }
        if sample.is_some_and(|s| s.device_us >= end_us) {
            let lost = pipeline.lost();
            return send(tx, Feed::End(format!("the demo session is over ({lost} reports lost)")));
        }
    }
}

fn failed(what: &'static str) -> impl Fn(CalibrateError) -> Stop {
    move |e| Stop::Failed(format!("{what}: {e}"))
}

fn display_mm(c: &Calibration) -> [f64; 2] {
    [c.display.width_mm, c.display.height_mm]
}

fn run_daemon(tx: &SyncSender<Feed>, path: &std::path::Path) -> Result<(), Stop> {
    let mut client = Client::connect(path).map_err(|e| Stop::Failed(not_connected(path, &e)))?;
    send(tx, Feed::Status(format!("connected to pend at {}", path.display())))?;
    let mut bad = 0u64;
    loop {
        match client.next_line() {
            None => return send(tx, Feed::End("pend closed the connection".into())),
            Some(Ok(Line::Hello { device })) => {
                let what = device.unwrap_or_else(|| "no pen attached yet".into());
                send(tx, Feed::Status(format!("pend: {what}")))?;
            }
            Some(Ok(Line::Event(e))) => send(tx, Feed::Event(e))?,
            // pend has as many clients as it serves (`pend --max-clients`): the session ends
            // with pend's reason rather than wait for a place that may never come.
            Some(Err(ClientError::Io(e))) if e.kind() == std::io::ErrorKind::ConnectionRefused => {
                return Err(Stop::Failed(e.to_string()));
            }
            Some(Err(e @ ClientError::Io(_))) => return Err(Stop::Failed(e.to_string())),
            Some(Err(e)) => {
                // A line that is not an event is dropped, counted and told.
                bad += 1;
                send(
                    tx,
                    Feed::Status(format!("dropped {bad} bad lines from pend; last: {e}")),
                )?;
            }
        }
    }
}

/// Why pend's socket at `path` did not take a connection, and what to do.
fn not_connected(path: &std::path::Path, e: &ClientError) -> String {
    let not_running = match e {
        ClientError::Io(io) => matches!(
            io.kind(),
            std::io::ErrorKind::NotFound | std::io::ErrorKind::ConnectionRefused
        ),
        ClientError::Bad { .. } => false,
    };
    if not_running {
        format!(
            "pend is not running (nothing listens at {}): start it (`pend`, or `systemctl --user start pend`; \
             pend --help), or give another --source (hid, serial:PATH, sim)",
            path.display()
        )
    } else {
        format!("cannot connect to pend at {}: {e}", path.display())
    }
}

fn run_device(tx: &SyncSender<Feed>, source: Source, calibration: Option<PathBuf>, looping: bool) -> Result<(), Stop> {
    // The simulated pen's calibration is its own; each is applied only to the base station it
    // records (the pipeline refuses another), and one recording none is used with a warning.
    let path = calibration.or_else(|| pen_host::calibration::default_path_for_source(&source).filter(|p| p.exists()));
    let calibration = match &path {
        Some(p) => {
            let c = Calibration::load(p).map_err(|e| Stop::Failed(e.to_string()))?;
            if let Some(warning) = c.unbound_warning(p) {
                send(tx, Feed::Status(format!("warning: {warning}")))?;
            }
            c
        }
        None => {
            send(
                tx,
                Feed::Status(
                    "no calibration: tracker coordinates are used as display coordinates (penctl calibrate)".into(),
                ),
            )?;
            Calibration::identity(DisplaySize::REFERENCE)
        }
    };
    send(tx, Feed::Display(display_mm(&calibration)))?;
    send(tx, Feed::Status(format!("pen: {source}")))?;
    // A simulated scenario plays once, unless asked to loop: its end is the session's.
    let mut ends = None;
    if let Source::Sim(o) = &source {
        send(tx, Feed::Clock(o.plug.clock()))?;
        if !looping {
            let end_us = (o.scenario.timeline.duration_s() * 1e6) as u64;
            ends = Some((o.plug.clock(), end_us, o.scenario.name.clone()));
        }
    }
    let mut pipeline = Pipeline::new(source, calibration);
    let mut events = Vec::new();
    loop {
        pipeline.poll(Duration::from_millis(100), &mut events);
        if let Some(notice) = pipeline.take_notice() {
            send(tx, Feed::Status(notice))?;
        }
        for e in events.drain(..) {
            send(tx, Feed::Event(e))?;
        }
        if let Some((clock, end_us, name)) = &ends
            && clock.now_us().is_some_and(|t| t >= *end_us)
        {
            return send(
                tx,
                Feed::End(format!("the scenario {name} is over (--loop plays it again)")),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn the_calibration_picture_follows_the_targets_and_guesses_the_pen() {
        let targets = [DVec2::new(100.0, 50.0), DVec2::new(500.0, 290.0)];
        let mut p = CalibrationPicture::new(&targets);
        let touch = |index| Prompt::Touch {
            index,
            count: 2,
            target_mm: targets[index],
        };
        let pen = |x, y, pressed, device_us| Prompt::Pen {
            position_mm: DVec3::new(x, y, 0.0),
            pressed,
            device_us,
        };
        assert_eq!(p.after(&touch(0)).map(|c| c.taken), Some(0));
        // Before any touch the tracker frame is shown as it is.
        let c = p.after(&pen(90.0, 45.0, false, 0)).expect("first pen");
        assert_eq!(c.pen_mm, Some([90.0, 45.0]));
        // Within 33 ms and no press change: not worth a picture.
        assert!(p.after(&pen(91.0, 45.0, false, 10_000)).is_none());
        // A press is shown at once.
        assert!(p.after(&pen(91.0, 45.0, true, 20_000)).is_some_and(|c| c.pressed));
        let c = p
            .after(&Prompt::Taken {
                touched_mm: DVec3::new(90.0, 45.0, 0.0),
                fixes: 30,
            })
            .expect("taken");
        assert_eq!(c.taken, 1);
        // Now the pen is shifted by the offset the first touch showed: (10, 5).
        let c = p.after(&pen(490.0, 285.0, false, 100_000)).expect("pen");
        assert_eq!(c.pen_mm, Some([500.0, 290.0]));
        assert!(p.after(&Prompt::Lift).is_none());
    }
}
