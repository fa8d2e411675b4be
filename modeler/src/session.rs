//! A modeling session: a document being edited by the pen, fed from a [`feed`](crate::feed).

use pen_host::events::{EventKind, PenEvent};
use pen_host::transport::sim::DeviceClock;

use crate::feed::{Calibrating, Feed};
use crate::interaction::{Interaction, Tuning, View};
use crate::latency::{HeadLatency, LatencySummary};
use penmodel_terrain::document::{Document, Grid};
use penmodel_terrain::editor::Editor;

/// A new session's document: a 6 × 3.4 km map of 12.5 m cells (480 × 272), which the reference
/// display (600 × 340 mm) shows at 1:10 000 — a millimetre on the display is 10 m, a cell 1.25 mm.
pub fn blank_document() -> Document {
    Document::new(Grid {
        cols: 480,
        rows: 272,
        cell_size: 12.5,
    })
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
    /// The tracked head's last pose, display-centred metres (issue 16).
    head_m: Option<[f64; 3]>,
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
}

impl Session {
    /// A session on `editor`, shown on a display of `display_mm` fitted to the document's grid.
    pub fn new(editor: Editor, display_mm: [f64; 2], tuning: Tuning) -> Session {
        let view = View::fit(display_mm, &editor.document().grid);
        Session {
            editor,
            interaction: Interaction::new(view, tuning),
            status: String::new(),
            calibrating: None,
            state: State::Running,
            events: 0,
            last_event_us: None,
            head_m: None,
            head_burst: None,
            head_poses: 0,
            clock: None,
            latency: HeadLatency::default(),
            frame_started_us: None,
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
        }
        if let EventKind::Head(h) = &e.kind
            && let Some(at) = h.at
        {
            // pend's pose is the last good one when held or refused: always usable. From the
            // display frame (mm from the lower-left corner) to the camera's (metres from the
            // centre); the emitter on the bridge stands for the point between the eyes.
            let [w, hgt] = self.interaction.view().display_mm;
            self.head_m = Some([(at.u_mm - 0.5 * w) * 1e-3, (at.v_mm - 0.5 * hgt) * 1e-3, at.h_mm * 1e-3]);
            // A held or refused pose is an older burst's: its age is measured from this report
            // only when the report brought it.
            if h.status == pen_host::events::HeadStatus::Tracked
                && let Some((_, device_us)) = e.seq
            {
                self.head_burst = Some((device_us, h.prediction_ms));
                self.head_poses += 1;
            }
        }
        self.interaction.handle(&mut self.editor, e);
    }

    /// Where the tracked head is, once a head event gave a pose: the point between the eyes in
    /// the display's frame, metres from its centre (x right, y up the display, z towards the
    /// viewer), as the camera takes it.
    pub fn head_m(&self) -> Option<[f64; 3]> {
        self.head_m
    }

    /// A frame showing the session is about to be drawn: the device time it starts at.
    pub fn frame_started(&mut self) {
        self.frame_started_us = self.paced_now_us();
    }

    /// A frame showing the session was just produced: with a tracked pose and the clock of a
    /// simulated device paced to the wall clock, how old the pose's burst is (when the frame
    /// was started, and now) goes into [`head_latency`](Self::head_latency). An unpaced
    /// simulation runs ahead of what is drawn by as much as the feed holds and takes no device
    /// time to draw: nothing is measured.
    pub fn frame_produced(&mut self) {
        let started = self.frame_started_us.take();
        if let (Some(done_us), Some((burst_us, prediction_ms))) = (self.paced_now_us(), self.head_burst) {
            self.latency
                .frame(started.unwrap_or(done_us), done_us, burst_us, prediction_ms);
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
}
