//! Pen events: what happened, derived from samples in the display frame.
//!
//! Each sample yields, in this order: `proximity_in` if the pen came into range; `tip_down` /
//! `tip_up` (SW1) and `button_down` / `button_up` (SW2, SW3) for each switch that changed;
//! `motion` while in range; `proximity_out` if it left. Every down is followed by exactly one up:
//! when the device is lost, `device_lost` is followed by an up for each switch still pressed and
//! a `proximity_out` if the pen was in range, so a client never waits for a release that cannot
//! come; when it returns, `device_found` starts from nothing pressed and out of range. The JSON
//! form is in docs/events.md.

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
        }
    }
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
