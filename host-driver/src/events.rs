//! Pen events: what happened, derived from samples in the display frame.
//!
//! Each sample yields, in this order: `proximity_in` if the pen came into range; `tip_down` /
//! `tip_up` (SW1) and `button_down` / `button_up` (SW2, SW3) for each switch that changed;
//! `motion` while in range; `proximity_out` if it left. Every down is followed by exactly one up:
//! when the device is lost, `device_lost` is followed by an up for each switch still pressed and
//! a `proximity_out` if the pen was in range, so a client never waits for a release that cannot
//! come; when it returns, `device_found` starts from nothing pressed and out of range. The JSON
//! form is in docs/events.md.
//!
//! `PenState` is what a client knows from the events it has read; pend uses it to bring a client
//! that joins late, or lost events, up to date with the same kinds of events.

use crate::sample::Sample;

/// A point in the display frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayPoint {
    /// Along the display's width, mm.
    pub u_mm: f64,
    /// Along its height, mm.
    pub v_mm: f64,
    /// Above the surface, along its normal, mm.
    pub h_mm: f64,
    /// `u` in pixels.
    pub u_px: f64,
    /// `v` in pixels (from the bottom edge, like `v`).
    pub v_px: f64,
}

/// What happened.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub enum EventKind {
    /// The pen came into range.
    ProximityIn,
    /// The pen left range.
    ProximityOut,
    /// SW1 closed: the tip touched the surface.
    TipDown,
    /// SW1 opened.
    TipUp,
    /// SW2 or SW3 pressed.
    ButtonDown {
        /// 2 or 3.
        button: u8,
    },
    /// SW2 or SW3 released.
    ButtonUp {
        /// 2 or 3.
        button: u8,
    },
    /// A new position while in range.
    Motion,
    /// The device went away.
    DeviceLost {
        /// Why, as the transport said.
        reason: String,
    },
    /// A device was attached (or reattached).
    DeviceFound { device: String },
    /// This client lost `count` events because it did not read them fast enough.
    Missed { count: u64 },
    /// The tracked head's pose (a head report): fresh, held or refused.
    Head(HeadPose),
}

impl EventKind {
    /// The event's `type` in JSON.
    pub fn name(&self) -> &'static str {
        match self {
            EventKind::ProximityIn => "proximity_in",
            EventKind::ProximityOut => "proximity_out",
            EventKind::TipDown => "tip_down",
            EventKind::TipUp => "tip_up",
            EventKind::ButtonDown { .. } => "button_down",
            EventKind::ButtonUp { .. } => "button_up",
            EventKind::Motion => "motion",
            EventKind::DeviceLost { .. } => "device_lost",
            EventKind::DeviceFound { .. } => "device_found",
            EventKind::Missed { .. } => "missed",
            EventKind::Head(_) => "head",
        }
    }
}

/// What a `head` event says about its pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeadStatus {
    /// A fresh pose from this report.
    Tracked,
    /// No fix in this report: the last pose, kept.
    Held,
    /// This report put the head behind the display: refused, the last pose kept.
    Refused,
}

impl HeadStatus {
    /// The status as the socket writes it.
    pub fn name(self) -> &'static str {
        match self {
            HeadStatus::Tracked => "tracked",
            HeadStatus::Held => "held",
            HeadStatus::Refused => "refused",
        }
    }

    /// The status written `name`.
    pub fn from_name(name: &str) -> Option<HeadStatus> {
        [HeadStatus::Tracked, HeadStatus::Held, HeadStatus::Refused]
            .into_iter()
            .find(|s| s.name() == name)
    }
}

/// A `head` event's content.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadPose {
    /// The pose to use: fresh, or the last good one when held or refused; `None` before the
    /// first good one.
    pub at: Option<DisplayPoint>,
    /// Whether `at` is fresh.
    pub status: HeadStatus,
    /// How far ahead of the report's device time the pose is predicted, ms.
    pub prediction_ms: u8,
    /// Head reports refused since pend started.
    pub refused: u64,
    /// Why the pose is not fresh, for a person (held and refused only).
    pub reason: Option<String>,
}

/// An event with its time and, for positional events, where.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub struct PenEvent {
    pub kind: EventKind,
    /// Host time, µs since the Unix epoch.
    pub t_us: u64,
    /// Where, for events about the pen.
    pub point: Option<DisplayPoint>,
    /// The sample's switches, for events about the pen.
    pub sw: Option<[bool; 3]>,
    /// The sample's sequence number and device time, for events from a sample.
    pub seq: Option<(u16, u64)>,
}

impl PenEvent {
    fn bare(kind: EventKind, t_us: u64) -> PenEvent {
        PenEvent {
            kind,
            t_us,
            point: None,
            sw: None,
            seq: None,
        }
    }

    /// A client's `missed` notice.
    pub fn missed(count: u64, t_us: u64) -> PenEvent {
        PenEvent::bare(EventKind::Missed { count }, t_us)
    }
}

/// Derives events from samples; keeps the pen's last known state.
#[derive(Debug, Default, Clone)]
pub struct EventDetector {
    in_range: bool,
    sw: [bool; 3],
    last_point: Option<DisplayPoint>,
}

impl EventDetector {
    /// Nothing pressed, out of range.
    pub fn new() -> EventDetector {
        EventDetector::default()
    }

    /// Whether the pen is in range.
    pub fn in_range(&self) -> bool {
        self.in_range
    }

    /// The switches as last reported.
    pub fn switches(&self) -> [bool; 3] {
        self.sw
    }

    /// The events of one sample; `point` is its position in the display frame.
    pub fn on_sample(&mut self, s: &Sample, point: DisplayPoint, out: &mut Vec<PenEvent>) {
        let ev = |kind, point| PenEvent {
            kind,
            t_us: s.host_us,
            point,
            sw: Some(s.sw),
            seq: Some((s.seq, s.device_us)),
        };
        let here = s.in_range.then_some(point);
        if s.in_range && !self.in_range {
            out.push(ev(EventKind::ProximityIn, here));
        }
        // Position with a switch event: here if in range, else where the pen was last seen.
        let at = here.or(self.last_point);
        for (i, (&was, &is)) in self.sw.iter().zip(&s.sw).enumerate() {
            if was == is {
                continue;
            }
            let kind = match (i, is) {
                (0, true) => EventKind::TipDown,
                (0, false) => EventKind::TipUp,
                (b, true) => EventKind::ButtonDown { button: b as u8 + 1 },
                (b, false) => EventKind::ButtonUp { button: b as u8 + 1 },
            };
            out.push(ev(kind, at));
        }
        if s.in_range {
            out.push(ev(EventKind::Motion, here));
        }
        if !s.in_range && self.in_range {
            out.push(ev(EventKind::ProximityOut, self.last_point));
        }
        self.in_range = s.in_range;
        self.sw = s.sw;
        if s.in_range {
            self.last_point = Some(point);
        }
    }

    /// The device went away: `device_lost`, then a release for each switch still pressed and
    /// `proximity_out` if the pen was in range.
    pub fn on_device_lost(&mut self, t_us: u64, reason: &str, out: &mut Vec<PenEvent>) {
        out.push(PenEvent::bare(
            EventKind::DeviceLost {
                reason: reason.to_string(),
            },
            t_us,
        ));
        let mut sw = self.sw;
        for i in 0..3 {
            if sw[i] {
                sw[i] = false;
                let kind = if i == 0 {
                    EventKind::TipUp
                } else {
                    EventKind::ButtonUp { button: i as u8 + 1 }
                };
                out.push(PenEvent {
                    kind,
                    t_us,
                    point: self.last_point,
                    sw: Some(sw),
                    seq: None,
                });
            }
        }
        if self.in_range {
            out.push(PenEvent {
                kind: EventKind::ProximityOut,
                t_us,
                point: self.last_point,
                sw: Some(sw),
                seq: None,
            });
        }
        *self = EventDetector::new();
    }

    /// A device was attached.
    pub fn on_device_found(&mut self, t_us: u64, device: &str, out: &mut Vec<PenEvent>) {
        *self = EventDetector::new();
        out.push(PenEvent::bare(
            EventKind::DeviceFound {
                device: device.to_string(),
            },
            t_us,
        ));
    }
}

/// The pen's state as a client knows it from the events it has read: whether a device is
/// attached (and which attachment), whether the pen is in range, its switches and where it was
/// last seen. pend keeps the current one, and the one a lagging client last saw, so it can
/// bring a client that joins late or lost events up to date with events (`resync`).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct PenState {
    /// The attached device, as its last `device_found` named it.
    pub device: Option<String>,
    /// Attachments seen (`device_found` events): a device lost and found again while a client
    /// was not reading differs from one that stayed, even under the same name.
    pub attachments: u64,
    /// In range (after `proximity_in`, until `proximity_out`).
    pub in_range: bool,
    /// [SW1, SW2, SW3].
    pub sw: [bool; 3],
    /// Where the pen was last seen.
    pub point: Option<DisplayPoint>,
}

/// `device_lost`'s reason when a client lost the real one in a gap.
pub const LOST_IN_GAP: &str = "lost while this client was not reading";

impl PenState {
    /// The state after `e`. Switch events set only their switch, so a stream that pairs its
    /// downs and ups (as `EventDetector`'s does) keeps the state exact.
    pub fn apply(&mut self, e: &PenEvent) {
        if let Some(p) = e.point {
            self.point = Some(p);
        }
        match &e.kind {
            EventKind::ProximityIn => self.in_range = true,
            EventKind::ProximityOut => self.in_range = false,
            EventKind::TipDown => self.sw[0] = true,
            EventKind::TipUp => self.sw[0] = false,
            EventKind::ButtonDown { button } => self.set_button(*button, true),
            EventKind::ButtonUp { button } => self.set_button(*button, false),
            // The head is not the pen's state: a late client has the next one in 16 ms.
            EventKind::Motion | EventKind::Missed { .. } | EventKind::Head(_) => {}
            EventKind::DeviceLost { .. } => self.device = None,
            EventKind::DeviceFound { device } => {
                // The detector starts a new device from nothing pressed and out of range.
                *self = PenState {
                    device: Some(device.clone()),
                    attachments: self.attachments + 1,
                    ..PenState::default()
                };
            }
        }
    }

    fn set_button(&mut self, button: u8, down: bool) {
        if let Some(sw) = self.sw.get_mut(usize::from(button).wrapping_sub(1)) {
            *sw = down;
        }
    }

    /// What a client that joins now already knows from the greeting: the device, nothing
    /// about the pen.
    pub fn greeted(&self) -> PenState {
        PenState {
            device: self.device.clone(),
            attachments: self.attachments,
            ..PenState::default()
        }
    }

    /// The events that take a client from this state to `to`, at `t_us`, in the order one
    /// report's events come (docs/events.md): if the device changed, `device_lost` with the
    /// releases and `proximity_out` it implies, then `device_found`; then `proximity_in`,
    /// switch transitions, `proximity_out`. They carry no `seq` (no report made them); their
    /// position is the pen's last known one. Applying them to this state gives `to`, except
    /// for the last-seen position.
    pub fn resync(&self, to: &PenState, t_us: u64, out: &mut Vec<PenEvent>) {
        let mut at = self.clone();
        let device_changed = at.attachments != to.attachments || at.device.is_some() != to.device.is_some();
        if device_changed {
            if at.device.is_some() {
                let mut lost = Vec::new();
                let mut detector = EventDetector {
                    in_range: at.in_range,
                    sw: at.sw,
                    last_point: at.point,
                };
                detector.on_device_lost(t_us, LOST_IN_GAP, &mut lost);
                out.append(&mut lost);
            }
            at = PenState {
                device: None,
                attachments: to.attachments,
                point: at.point,
                ..PenState::default()
            };
            if let Some(device) = &to.device {
                out.push(PenEvent::bare(EventKind::DeviceFound { device: device.clone() }, t_us));
                at.device = Some(device.clone());
            }
        }
        let point = to.point.or(at.point);
        let mut push = |kind, sw: [bool; 3]| {
            out.push(PenEvent {
                kind,
                t_us,
                point,
                sw: Some(sw),
                seq: None,
            })
        };
        if to.in_range && !at.in_range {
            push(EventKind::ProximityIn, at.sw);
        }
        for i in 0..3 {
            if at.sw[i] == to.sw[i] {
                continue;
            }
            at.sw[i] = to.sw[i];
            let kind = match (i, to.sw[i]) {
                (0, true) => EventKind::TipDown,
                (0, false) => EventKind::TipUp,
                (b, true) => EventKind::ButtonDown { button: b as u8 + 1 },
                (b, false) => EventKind::ButtonUp { button: b as u8 + 1 },
            };
            push(kind, at.sw);
        }
        if at.in_range && !to.in_range {
            push(EventKind::ProximityOut, at.sw);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use pen_protocol::Quality;

    fn sample(seq: u16, in_range: bool, sw: [bool; 3]) -> Sample {
        Sample {
            seq,
            device_us: seq as u64 * 6500,
            host_us: 1000 + seq as u64,
            sw,
            in_range,
            display_frame: false,
            position_mm: DVec3::new(seq as f64, 0.0, 0.0),
            quality: Quality::NONE,
        }
    }

    fn point(u: f64) -> DisplayPoint {
        DisplayPoint {
            u_mm: u,
            v_mm: 0.0,
            h_mm: 0.0,
            u_px: 0.0,
            v_px: 0.0,
        }
    }

    fn names(events: &[PenEvent]) -> Vec<&'static str> {
        events.iter().map(|e| e.kind.name()).collect()
    }

    #[test]
    fn transitions_in_order_without_duplicates() {
        let mut d = EventDetector::new();
        let mut out = Vec::new();
        d.on_sample(&sample(0, false, [false; 3]), point(0.0), &mut out);
        assert!(out.is_empty(), "nothing while out of range and released");
        d.on_sample(&sample(1, true, [true, false, false]), point(1.0), &mut out);
        assert_eq!(names(&out), ["proximity_in", "tip_down", "motion"]);
        out.clear();
        d.on_sample(&sample(2, true, [true, true, false]), point(2.0), &mut out);
        assert_eq!(names(&out), ["button_down", "motion"]);
        assert_eq!(out[0].kind, EventKind::ButtonDown { button: 2 });
        out.clear();
        d.on_sample(&sample(3, false, [false, true, false]), point(3.0), &mut out);
        assert_eq!(names(&out), ["tip_up", "proximity_out"]);
        // Out of range: the positions are where the pen was last seen.
        assert_eq!(out[0].point, Some(point(2.0)));
        assert_eq!(out[1].point, Some(point(2.0)));
        out.clear();
        d.on_sample(&sample(4, false, [false, true, false]), point(4.0), &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn a_lost_device_releases_what_was_pressed() {
        let mut d = EventDetector::new();
        let mut out = Vec::new();
        d.on_sample(&sample(1, true, [true, false, true]), point(1.0), &mut out);
        out.clear();
        d.on_device_lost(5000, "unplugged", &mut out);
        assert_eq!(names(&out), ["device_lost", "tip_up", "button_up", "proximity_out"]);
        assert_eq!(out[2].kind, EventKind::ButtonUp { button: 3 });
        out.clear();
        d.on_device_found(6000, "sim", &mut out);
        d.on_sample(&sample(2, true, [true, false, false]), point(2.0), &mut out);
        assert_eq!(names(&out), ["device_found", "proximity_in", "tip_down", "motion"]);
    }

    /// The state after `events`, from `from`.
    fn after(from: &PenState, events: &[PenEvent]) -> PenState {
        let mut s = from.clone();
        for e in events {
            s.apply(e);
        }
        s
    }

    #[test]
    fn resync_takes_a_client_to_the_pen_s_state_in_one_report_s_order() {
        let mut d = EventDetector::new();
        let mut pen = PenState::default();
        let mut out = Vec::new();
        d.on_device_found(10, "sim", &mut out);
        d.on_sample(&sample(1, true, [true, false, true]), point(1.0), &mut out);
        for e in &out {
            pen.apply(e);
        }
        assert_eq!((pen.in_range, pen.sw, pen.attachments), (true, [true, false, true], 1));

        // Joining: the greeting names the device; the events give the pen.
        let joined = pen.greeted();
        let mut sync = Vec::new();
        joined.resync(&pen, 99, &mut sync);
        assert_eq!(names(&sync), ["proximity_in", "tip_down", "button_down"]);
        assert!(
            sync.iter()
                .all(|e| e.seq.is_none() && e.t_us == 99 && e.point == Some(point(1.0)))
        );
        assert_eq!(sync[2].sw, Some([true, false, true]));
        assert_eq!(after(&joined, &sync).sw, pen.sw);

        // Lost in a gap: the tip lifted and the pen left; SW2 pressed.
        let seen = pen.clone();
        out.clear();
        d.on_sample(&sample(2, false, [false, true, true]), point(2.0), &mut out);
        for e in &out {
            pen.apply(e);
        }
        sync.clear();
        seen.resync(&pen, 100, &mut sync);
        assert_eq!(names(&sync), ["tip_up", "button_down", "proximity_out"]);
        assert_eq!(after(&seen, &sync).sw, [false, true, true]);

        // Lost in a gap: the device lost and found again, the pen back with the tip down.
        let seen = pen.clone();
        out.clear();
        d.on_device_lost(200, "unplugged", &mut out);
        d.on_device_found(300, "sim", &mut out);
        d.on_sample(&sample(3, true, [true, false, false]), point(3.0), &mut out);
        for e in &out {
            pen.apply(e);
        }
        sync.clear();
        seen.resync(&pen, 400, &mut sync);
        assert_eq!(
            names(&sync),
            [
                "device_lost",
                "button_up",
                "button_up",
                "device_found",
                "proximity_in",
                "tip_down"
            ]
        );
        assert_eq!(
            sync[0].kind,
            EventKind::DeviceLost {
                reason: LOST_IN_GAP.into()
            }
        );
        let caught = after(&seen, &sync);
        assert_eq!(
            (caught.device, caught.attachments, caught.in_range, caught.sw),
            (Some("sim".into()), 2, true, [true, false, false])
        );

        // In step: nothing to say.
        sync.clear();
        pen.resync(&pen, 500, &mut sync);
        assert!(sync.is_empty());
    }

    #[test]
    fn json_round_trips_through_the_client_parser() {
        let mut d = EventDetector::new();
        let mut out = Vec::new();
        d.on_sample(&sample(7, true, [false, false, true]), point(12.5), &mut out);
        out.push(PenEvent::missed(3, 42));
        for e in &out {
            let line = crate::wire::line(e);
            match crate::client::parse_line(line.trim_end()) {
                Ok(crate::client::Line::Event(back)) => assert_eq!(&back, e, "{line}"),
                other => panic!("{line}: {other:?}"),
            }
        }
    }
}
