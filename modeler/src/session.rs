//! A modeling session: a document being edited by the pen, fed from a [`feed`](crate::feed).

use pen_host::events::{EventKind, PenEvent};
use pen_host::transport::sim::DeviceClock;

use crate::feed::{Calibrating, Feed};
use crate::head_prediction::HeadPredictor;
use crate::interaction::{Interaction, Tuning, View};
use crate::latency::{HeadLatency, LatencySummary};
use penmodel_terrain::document::{Document, Erosion, Fluvial, Grid};
use penmodel_terrain::editor::Editor;

/// A new session's document: a 6 × 3.4 km map of 12.5 m cells (480 × 272), which the reference
/// display (600 × 340 mm) shows at 1:10 000 — a millimetre on the display is 10 m, a cell 1.25 mm.
/// Its land is eroded by the fluvial erosion with its defaults (`docs/erosion.md`), so what the
/// pen pulls up drains like land; no thermal pass (`"iterations": 0`), which would redo a
/// pulled figure's whole window 16 times per pen move.
pub fn blank_document() -> Document {
    let mut doc = Document::new(Grid {
        cols: 480,
        rows: 272,
        cell_size: 12.5,
    });
    doc.terrain.erosion = Some(Erosion {
        iterations: 0,
        fluvial: Some(Fluvial::default()),
        ..Erosion::default()
    });
    doc
}

/// How the feed stands.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// Events are coming.
    Running,
    /// The source ended normally, saying this.
    Ended(String),
    /// The source failed, saying why.
    Failed(String),
}

/// Steps of a running fluvial erosion per frame: the demo's 480 × 272 grid takes about 8 ms a
/// step (`penmodel bench --erosion`), so two keep a frame near 60 Hz's budget.
const EROSION_STEPS_PER_FRAME: u32 = 2;

/// The editor, the pen interaction, and what the feed last said.
pub struct Session {
    /// The document and its terrain.
    pub editor: Editor,
    /// The pen's state machine and the view.
    pub interaction: Interaction,
    status: String,
    calibrating: Option<Calibrating>,
    state: State,
    events: u64,
    last_event_us: Option<u64>,
    /// The tracked head's last pose as reported, display frame mm (issue 16).
    head_mm: Option<[f64; 3]>,
    /// The pose the frame being drawn takes: the last one carried on to the frame's expected
    /// end ([`crate::head_prediction`]), until the next pose comes.
    head_drawn_mm: Option<[f64; 3]>,
    /// The host's prediction of the head.
    predictor: HeadPredictor,
    /// How far the frame being drawn carried the pose on, µs.
    head_lead_us: i64,
    /// The head's true path, device µs to display mm, when the feed is a simulation that knows
    /// it: how far the poses drawn are from it is measured.
    head_truth: Option<HeadTruth>,
    /// The device time of that pose's burst, and how far past it the pose was predicted, ms.
    head_burst: Option<(u64, u8)>,
    /// Tracked poses taken.
    head_poses: u64,
    /// The simulated device's clock, when the feed has one.
    clock: Option<DeviceClock>,
    /// Emission to frame of the frames drawn with a tracked pose.
    latency: HeadLatency,
    /// When the frame being drawn was started, device µs.
    frame_started_us: Option<u64>,
    /// And on the host's clock: its draw time.
    frame_started_at: Option<std::time::Instant>,
}

/// The head's true path: device µs to the emitter's place, display frame mm.
pub type HeadTruth = Box<dyn Fn(u64) -> [f64; 3] + Send>;

impl Session {
    /// A session on `editor`, shown on a display of `display_mm` fitted to the document's grid.
    pub fn new(mut editor: Editor, display_mm: [f64; 2], tuning: Tuning) -> Session {
        let view = View::fit(display_mm, &editor.document().grid);
        // Under the pen the eroded land follows a pull at once, and the exact erosion catches up
        // over the next frames (`frame_started`).
        editor.set_progressive_erosion(true);
        Session {
            editor,
            interaction: Interaction::new(view, tuning),
            status: String::new(),
            calibrating: None,
            state: State::Running,
            events: 0,
            last_event_us: None,
            head_mm: None,
            head_drawn_mm: None,
            predictor: HeadPredictor::default(),
            head_lead_us: 0,
            head_truth: None,
            head_burst: None,
            head_poses: 0,
            clock: None,
            latency: HeadLatency::default(),
            frame_started_us: None,
            frame_started_at: None,
        }
    }

    /// Sets the terrain's vertical scale (exaggeration) before the session starts: heights are
    /// drawn and pulled `scale` times their metres (the pulled figure stays at the pen's tip).
    pub fn set_vertical_scale(&mut self, scale: f64) {
        let tuning = *self.interaction.tuning();
        let view = View {
            exaggeration: scale,
            ..*self.interaction.view()
        };
        self.interaction = Interaction::new(view, tuning);
    }

    /// Takes one message from the feed; returns what the interaction said about it.
    pub fn feed(&mut self, feed: Feed) -> Vec<String> {
        match feed {
            Feed::Calibrating(c) => {
                self.calibrating = Some(c);
                Vec::new()
            }
            Feed::Display(mm) => {
                // Sent once the calibration is fitted: the procedure is over.
                self.calibrating = None;
                if mm != self.interaction.view().display_mm {
                    let tuning = *self.interaction.tuning();
                    let view = View {
                        // The vertical scale is the user's, whatever the display.
                        exaggeration: self.interaction.view().exaggeration,
                        ..View::fit(mm, &self.editor.document().grid)
                    };
                    self.interaction = Interaction::new(view, tuning);
                }
                Vec::new()
            }
            Feed::Status(s) => {
                self.status = s.clone();
                vec![s]
            }
            Feed::Clock(clock) => {
                self.clock = Some(clock);
                Vec::new()
            }
            Feed::Event(e) => {
                self.calibrating = None;
                self.event(&e);
                self.interaction.take_messages()
            }
            Feed::End(s) => {
                self.state = State::Ended(s.clone());
                vec![s]
            }
            Feed::Failed(s) => {
                self.state = State::Failed(s.clone());
                vec![s]
            }
        }
    }

    /// Handles one pen event.
    pub fn event(&mut self, e: &PenEvent) {
        self.events += 1;
        if let Some((_, device_us)) = e.seq {
            self.last_event_us = Some(device_us);
            self.predictor.arrived(device_us, e.t_us);
        }
        if let EventKind::Head(h) = &e.kind
            && let Some(at) = h.at
        {
            // pend's pose is the last good one when held or refused: always usable.
            let mm = [at.u_mm, at.v_mm, at.h_mm];
            self.head_mm = Some(mm);
            self.head_drawn_mm = None;
            // A held or refused pose is an older burst's: its age is measured from this report
            // only when the report brought it.
            if h.status == pen_host::events::HeadStatus::Tracked
                && let Some((_, device_us)) = e.seq
            {
                self.head_burst = Some((device_us, h.prediction_ms));
                self.head_poses += 1;
                self.predictor
                    .pose(device_us.saturating_add(u64::from(h.prediction_ms) * 1000), mm);
            }
        }
        self.interaction.handle(&mut self.editor, e);
    }

    /// Where the tracked head is, once a head event gave a pose: the point between the eyes in
    /// the display's frame, metres from its centre (x right, y up the display, z towards the
    /// viewer), as the camera takes it.
    /// The pose is the last one reported, or while a frame is drawn, the one it predicted.
    pub fn head_m(&self) -> Option<[f64; 3]> {
        // From the display frame (mm from the lower-left corner) to the camera's (metres from
        // the centre); the emitter on the bridge stands for the point between the eyes.
        let [w, hgt] = self.interaction.view().display_mm;
        self.head_drawn_mm
            .or(self.head_mm)
            .map(|p| [(p[0] - 0.5 * w) * 1e-3, (p[1] - 0.5 * hgt) * 1e-3, p[2] * 1e-3])
    }

    /// The head's true path, for a simulation that knows it: frames then measure how far the
    /// pose they drew is from where the head was when they were done.
    pub fn set_head_truth(&mut self, truth: HeadTruth) {
        self.head_truth = Some(truth);
    }

    /// A frame showing the session is about to be drawn: the device time it starts at. The
    /// tracked head's pose is carried on to the frame's expected end: now plus the last frames'
    /// median draw time ([`crate::head_prediction`]).
    pub fn frame_started(&mut self) {
        // A fixed number of steps, not a time budget, so a headless session's frames are the
        // same on every machine.
        self.editor.settle_erosion(EROSION_STEPS_PER_FRAME);
        self.frame_started_us = self.paced_now_us();
        self.frame_started_at = Some(std::time::Instant::now());
        let carried = self.head_carried(self.predictor.expected_draw_us());
        self.head_drawn_mm = carried.map(|(mm, _)| mm);
        self.head_lead_us = carried.map_or(0, |(_, lead_us)| lead_us);
    }

    /// Before a frame latched to the head: the pose its view is drawn from before the head's
    /// newest pose comes, the last one carried on past now by `view_us` (the view's drawing) and
    /// the last frames' median draw after the latch — to about when the frame will be done, so
    /// that moving the view to the newest pose after the latch (`Renderer::reproject`) has little
    /// to move. [`frame_started`](Self::frame_started) then takes the newest pose.
    pub fn head_ahead(&mut self, view_us: u64) {
        let ahead_us = view_us.saturating_add(self.predictor.expected_draw_us());
        self.head_drawn_mm = self.head_carried(ahead_us).map(|(mm, _)| mm);
    }

    /// The tracked head's last pose carried on to `ahead_us` past now, and how far from its own
    /// instant that is, µs (negative: back); `None` without a pose, or for an unpaced simulation (whose device
    /// time is not now: nothing to predict to).
    fn head_carried(&self, ahead_us: u64) -> Option<([f64; 3], i64)> {
        let now_us = match &self.clock {
            Some(_) => self.paced_now_us(),
            None => self.predictor.device_at(unix_now_us()),
        };
        let now_us = now_us.filter(|_| self.head_burst.is_some())?;
        self.predictor.predict(now_us.saturating_add(ahead_us))
    }

    /// A frame showing the session was just produced: with a tracked pose and the clock of a
    /// simulated device paced to the wall clock, how old the pose's burst is (when the frame
    /// was started, and now) goes into [`head_latency`](Self::head_latency). An unpaced
    /// simulation runs ahead of what is drawn by as much as the feed holds and takes no device
    /// time to draw: nothing is measured.
    pub fn frame_produced(&mut self) {
        let started = self.frame_started_us.take();
        if let Some(at) = self.frame_started_at.take() {
            self.predictor.drawn(at.elapsed().as_micros() as u64);
        }
        // Once the pen has ended, its last head pose only grows older: frames after it measure
        // nothing of the chain.
        let live = matches!(self.state, State::Running);
        if let (true, Some(done_us), Some((burst_us, prediction_ms))) = (live, self.paced_now_us(), self.head_burst) {
            self.latency.frame(
                started.unwrap_or(done_us),
                done_us,
                burst_us,
                prediction_ms,
                self.head_lead_us,
            );
            // How far the pose reported and the pose drawn are from where the head was.
            if let (Some(truth), Some(reported)) = (&self.head_truth, self.head_mm) {
                let true_mm = truth(done_us);
                let drawn = self.head_drawn_mm.unwrap_or(reported);
                let own = truth(burst_us.saturating_add(u64::from(prediction_ms) * 1000));
                let less = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
                self.latency
                    .error(less(reported, true_mm), less(drawn, true_mm), less(reported, own));
            }
        }
    }

    /// Whether events come in real time: from a device, or a simulated one paced to the wall
    /// clock. An unpaced simulation (`--speed 0`) runs as far ahead as the feed holds, so a
    /// frame must not wait for its next event or take everything it holds.
    pub fn realtime(&self) -> bool {
        self.clock.as_ref().is_none_or(DeviceClock::is_paced)
    }

    /// Tracked head poses taken so far: a frame waiting for a fresh pose watches this change.
    pub fn head_poses(&self) -> u64 {
        self.head_poses
    }

    /// Whether a tracked pose came within `us` device µs of the last event: the glasses are
    /// reporting, so another pose is due soon.
    pub fn head_tracked_within(&self, us: u64) -> bool {
        match (self.head_burst, self.last_event_us) {
            (Some((burst_us, _)), Some(last_us)) => last_us.saturating_sub(burst_us) <= us,
            _ => false,
        }
    }

    /// The paced simulated device's time now, µs.
    fn paced_now_us(&self) -> Option<u64> {
        self.clock
            .as_ref()
            .filter(|c| c.is_paced())
            .and_then(DeviceClock::now_us)
    }

    /// The tracked head's latency from emission to frame on the device's clock, once frames
    /// were produced with a tracked pose from a paced simulated device ([`crate::latency`]).
    pub fn head_latency(&self) -> Option<LatencySummary> {
        self.latency.summary()
    }

    /// Whether the feed is still running.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The feed's last status line (calibrating, connected).
    pub fn status(&self) -> &str {
        &self.status
    }

    /// The calibration procedure, while it runs.
    pub fn calibrating(&self) -> Option<&Calibrating> {
        self.calibrating.as_ref()
    }

    /// Pen events handled.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// The device-clock time of the last event from a report, µs (it restarts when a device
    /// is reattached).
    pub fn last_event_us(&self) -> Option<u64> {
        self.last_event_us
    }
}

/// The host's clock, µs since the Unix epoch (as events are stamped).
fn unix_now_us() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vertical_scale_holds_when_the_display_is_refitted() {
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        session.set_vertical_scale(2.5);
        assert_eq!(session.interaction.view().exaggeration, 2.5);
        // The calibration reports another display: the view is fitted to it, the scale kept.
        session.feed(Feed::Display([500.0, 300.0]));
        assert_eq!(session.interaction.view().display_mm, [500.0, 300.0]);
        assert_eq!(session.interaction.view().exaggeration, 2.5);
    }

    #[test]
    fn the_tracked_head_places_the_eyes() {
        use pen_host::events::{DisplayPoint, HeadPose, HeadStatus};
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        let head = |at: Option<(f64, f64, f64)>, status| PenEvent {
            kind: EventKind::Head(HeadPose {
                at: at.map(|(u, v, h)| DisplayPoint {
                    u_mm: u,
                    v_mm: v,
                    h_mm: h,
                    u_px: 0.0,
                    v_px: 0.0,
                }),
                status,
                prediction_ms: 20,
                refused: 0,
                reason: None,
            }),
            t_us: 0,
            point: None,
            sw: None,
            seq: Some((0, 0)),
        };
        session.event(&head(None, HeadStatus::Held));
        assert_eq!(session.head_m(), None, "no pose before the first one");
        // 100 mm right of and 50 mm above the centre of the 600 × 340 display, 650 mm out.
        session.event(&head(Some((400.0, 220.0, 650.0)), HeadStatus::Tracked));
        let [x, y, z] = session.head_m().expect("a pose");
        assert!((x - 0.1).abs() < 1e-12 && (y - 0.05).abs() < 1e-12 && (z - 0.65).abs() < 1e-12);
    }

    #[test]
    fn a_frame_draws_the_head_carried_on_to_its_end() {
        use pen_host::events::{DisplayPoint, HeadPose, HeadStatus};
        let editor = Editor::new(blank_document()).expect("a valid document");
        let mut session = Session::new(editor, [600.0, 340.0], Tuning::default());
        // A head moving right at 0.1 mm/ms, reported every 15 ms, the last one 40 ms ago on the
        // host's clock (a real base station: no simulated clock, the events' host stamps).
        let host_now = unix_now_us();
        let u_at = |device_us: u64| 300.0 + 1e-4 * device_us as f64;
        for k in 0..6u16 {
            let device_us = 1_000_000 + u64::from(k) * 15_000;
            session.event(&PenEvent {
                kind: EventKind::Head(HeadPose {
                    at: Some(DisplayPoint {
                        u_mm: u_at(device_us + 20_000),
                        v_mm: 170.0,
                        h_mm: 650.0,
                        u_px: 0.0,
                        v_px: 0.0,
                    }),
                    status: HeadStatus::Tracked,
                    prediction_ms: 20,
                    refused: 0,
                    reason: None,
                }),
                t_us: host_now - 40_000 - u64::from(5 - k) * 15_000,
                point: None,
                sw: None,
                seq: Some((k, device_us)),
            });
        }
        let reported = session.head_m().expect("a pose")[0];
        session.frame_started();
        let drawn = session.head_m().expect("a pose")[0];
        // The newest pose is for 20 ms past its burst, which was 40 ms ago: the frame's end is
        // at least 20 ms later, so the pose is carried on along the motion by at least 2 mm, and
        // by no more than the limit.
        let ahead_m = drawn - reported;
        assert!(ahead_m >= 1e-4 * 20_000.0 * 1e-3 - 1e-9, "{ahead_m}");
        assert!(
            ahead_m <= 1e-4 * crate::head_prediction::MAX_LEAD_US as f64 * 1e-3 + 1e-9,
            "{ahead_m}"
        );
        // The next pose is drawn as reported until the next frame starts.
        session.frame_produced();
        assert_eq!(session.head_m().map(|h| h[0]), Some(drawn));
    }
}
