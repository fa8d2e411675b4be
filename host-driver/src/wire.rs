//! pend's socket protocol (docs/events.md) as serde types: the daemon writes these and the client
//! reads them, so the two cannot drift apart.
//!
//! A line is one JSON object whose `type` says which [`SocketLine`] it is. Reading is strict
//! about what a line has: a missing or mistyped key, a position with only some of its five
//! coordinates, `seq` without `device_us`, a button other than 2 or 3, or a time that is not a
//! non-negative number is an error naming it, never a default. Keys a line does not define are
//! ignored, so a newer pend may add some.

use serde::{Deserialize, Serialize};

use crate::events::{DisplayPoint, EventKind, HeadPose, HeadStatus, PenEvent};

/// The events schema's version, the greeting's `events`. Version 2 added the `refused` line and
/// the events that bring a client up to date when it joins and after a `missed` notice; version
/// 3 the `head` line; version 4 made `head` lines go only to clients that ask for them with a
/// [`Subscribe`] line (docs/events.md).
pub const EVENTS_VERSION: u32 = 4;

/// The lines a client may write (events version 4), by their `type`; pend ignores any other.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ClientLine {
    /// Asks for optional lines.
    Subscribe(Subscribe),
}

/// The optional lines a client reads, by their `type`: `head`. Names pend does not know are
/// ignored, so a client may ask a newer pend for more.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Subscribe {
    /// The line types asked for.
    pub lines: Vec<String>,
}

/// The `type` of the head's line, as a client names it in a [`Subscribe`].
pub const HEAD_LINES: &str = "head";

impl ClientLine {
    /// Asking for `head` lines.
    pub fn subscribe_head() -> ClientLine {
        ClientLine::Subscribe(Subscribe {
            lines: vec![HEAD_LINES.to_string()],
        })
    }

    /// Whether this line asks for `head` lines.
    pub fn wants_head(&self) -> bool {
        match self {
            ClientLine::Subscribe(s) => s.lines.iter().any(|l| l == HEAD_LINES),
        }
    }

    /// The line as written: one JSON object and a newline.
    pub fn to_text(&self) -> String {
        // Only strings: serializing cannot fail.
        let mut s = serde_json::to_string(self).unwrap_or_default();
        s.push('\n');
        s
    }
}

/// One line on the socket, by its `type`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
#[allow(missing_docs)]
pub enum SocketLine {
    /// The first line a client reads.
    Hello(Hello),
    /// The only line a client reads when pend has no room for it, instead of the greeting.
    Refused(Refused),
    ProximityIn(Pen),
    ProximityOut(Pen),
    TipDown(Pen),
    TipUp(Pen),
    ButtonDown(Button),
    ButtonUp(Button),
    Motion(Pen),
    DeviceLost(DeviceLost),
    DeviceFound(DeviceFound),
    Missed(Missed),
    Head(Head),
}

/// The greeting: the schema's version, and whether a base station is attached.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// Host time, seconds since the Unix epoch.
    pub t: f64,
    /// [`EVENTS_VERSION`].
    pub events: u32,
    /// Whether `device` is set.
    pub connected: bool,
    /// The device, `null` while none is attached.
    pub device: Option<String>,
}

/// pend turned the client away (it serves a bounded number at once); the connection closes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Refused {
    /// Host time, seconds since the Unix epoch.
    pub t: f64,
    /// Why, for a person: the limit and what to do.
    pub reason: String,
}

/// Where the pen is (or was last seen): all five keys, or none. Rounded to µm when written.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct Point {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub u_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub u_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v_px: Option<f64>,
}

/// The report an event came from: `seq` and `device_us`, both or neither.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct Report {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seq: Option<u16>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device_us: Option<u64>,
}

/// A pen event without a button: proximity, tip, motion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pen {
    /// Host time, seconds since the Unix epoch, µs resolution.
    pub t: f64,
    /// Absent when the pen has not been seen since the device was attached.
    #[serde(flatten)]
    pub point: Point,
    /// [SW1, SW2, SW3] after the event; absent on events without a sample.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sw: Option<[bool; 3]>,
    /// Absent on the releases pend makes up when the device is lost.
    #[serde(flatten)]
    pub report: Report,
}

/// A barrel button pressed or released.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct Button {
    pub t: f64,
    #[serde(flatten)]
    pub point: Point,
    /// 2 (SW2) or 3 (SW3).
    pub button: u8,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sw: Option<[bool; 3]>,
    #[serde(flatten)]
    pub report: Report,
}

/// The device went away.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct DeviceLost {
    pub t: f64,
    /// Why, as the transport said.
    pub reason: String,
}

/// A device was attached or reattached.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct DeviceFound {
    pub t: f64,
    pub device: String,
}

/// This client lost `count` events by reading too slowly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub struct Missed {
    pub t: f64,
    pub count: u64,
}

/// The tracked head's pose (docs/events.md, *Head*).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Head {
    /// Host time, seconds since the Unix epoch.
    pub t: f64,
    /// The pose to use (fresh, or the last good one); absent before the first good one.
    #[serde(flatten)]
    pub point: Point,
    /// `tracked`, `held` (no fix: the last pose) or `refused` (behind the display: the last pose).
    pub status: String,
    /// How far ahead of `device_us` the pose is predicted, ms.
    pub prediction_ms: u8,
    /// Head reports refused since pend started.
    pub refused: u64,
    /// Why the pose is not fresh, for a person (`held` and `refused`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The head report's own sequence number and device time.
    #[serde(flatten)]
    pub report: Report,
}

/// Why a well-formed JSON line is not an event.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WireError {
    /// Some of `u_mm`, `v_mm`, `h_mm`, `u_px`, `v_px` but not all.
    #[error("a position needs all of u_mm, v_mm, h_mm, u_px and v_px")]
    PartialPoint,
    /// `seq` without `device_us` or the other way round.
    #[error("seq and device_us come together")]
    PartialReport,
    /// A button other than SW2 and SW3.
    #[error("button {0} is not 2 or 3")]
    Button(u8),
    /// A head status other than `tracked`, `held` and `refused`.
    #[error("head status {0:?} is not tracked, held or refused")]
    HeadStatus(String),
    /// `t` is negative, or not before 2^32 s (the year 2106).
    #[error("t {0} is not a time")]
    Time(f64),
}

fn seconds(t_us: u64) -> f64 {
    t_us as f64 * 1e-6
}

/// The latest time a line carries: 2^32 s after the epoch (the year 2106). Below it a time in
/// seconds as an `f64` holds every microsecond (its spacing is at most 2^-21 s), so the time pend
/// writes is the time a client reads; beyond it the spacing passes a microsecond and a time read
/// and written again drifts (found by fuzzing, docs/reliability.md).
const LATEST_S: f64 = 4_294_967_296.0;

fn micros(t: f64) -> Result<u64, WireError> {
    let us = (t * 1e6).round();
    if us.is_finite() && us >= 0.0 && t < LATEST_S {
        Ok(us as u64)
    } else {
        Err(WireError::Time(t))
    }
}

impl Hello {
    /// The greeting at `t_us` for `device`.
    pub fn new(t_us: u64, device: Option<String>) -> Hello {
        Hello {
            t: seconds(t_us),
            events: EVENTS_VERSION,
            connected: device.is_some(),
            device,
        }
    }
}

impl Refused {
    /// The refusal at `t_us`, saying `reason`.
    pub fn new(t_us: u64, reason: String) -> Refused {
        Refused {
            t: seconds(t_us),
            reason,
        }
    }
}

impl Point {
    fn of(p: Option<DisplayPoint>) -> Point {
        let Some(p) = p else { return Point::default() };
        let r = |v: f64| Some((v * 1000.0).round() / 1000.0);
        Point {
            u_mm: r(p.u_mm),
            v_mm: r(p.v_mm),
            h_mm: r(p.h_mm),
            u_px: r(p.u_px),
            v_px: r(p.v_px),
        }
    }

    fn read(self) -> Result<Option<DisplayPoint>, WireError> {
        match (self.u_mm, self.v_mm, self.h_mm, self.u_px, self.v_px) {
            (Some(u_mm), Some(v_mm), Some(h_mm), Some(u_px), Some(v_px)) => Ok(Some(DisplayPoint {
                u_mm,
                v_mm,
                h_mm,
                u_px,
                v_px,
            })),
            (None, None, None, None, None) => Ok(None),
            _ => Err(WireError::PartialPoint),
        }
    }
}

impl Report {
    fn of(seq: Option<(u16, u64)>) -> Report {
        Report {
            seq: seq.map(|s| s.0),
            device_us: seq.map(|s| s.1),
        }
    }

    fn read(self) -> Result<Option<(u16, u64)>, WireError> {
        match (self.seq, self.device_us) {
            (Some(s), Some(d)) => Ok(Some((s, d))),
            (None, None) => Ok(None),
            _ => Err(WireError::PartialReport),
        }
    }
}

/// An event as one line on pend's socket: JSON and a newline (docs/events.md).
pub fn line(event: &PenEvent) -> String {
    SocketLine::from(event).to_text()
}

impl From<&PenEvent> for SocketLine {
    fn from(e: &PenEvent) -> SocketLine {
        let t = seconds(e.t_us);
        let pen = || Pen {
            t,
            point: Point::of(e.point),
            sw: e.sw,
            report: Report::of(e.seq),
        };
        let button = |button| Button {
            t,
            point: Point::of(e.point),
            button,
            sw: e.sw,
            report: Report::of(e.seq),
        };
        match &e.kind {
            EventKind::ProximityIn => SocketLine::ProximityIn(pen()),
            EventKind::ProximityOut => SocketLine::ProximityOut(pen()),
            EventKind::TipDown => SocketLine::TipDown(pen()),
            EventKind::TipUp => SocketLine::TipUp(pen()),
            EventKind::ButtonDown { button: b } => SocketLine::ButtonDown(button(*b)),
            EventKind::ButtonUp { button: b } => SocketLine::ButtonUp(button(*b)),
            EventKind::Motion => SocketLine::Motion(pen()),
            EventKind::DeviceLost { reason } => SocketLine::DeviceLost(DeviceLost {
                t,
                reason: reason.clone(),
            }),
            EventKind::DeviceFound { device } => SocketLine::DeviceFound(DeviceFound {
                t,
                device: device.clone(),
            }),
            EventKind::Missed { count } => SocketLine::Missed(Missed { t, count: *count }),
            EventKind::Head(h) => SocketLine::Head(Head {
                t,
                point: Point::of(h.at),
                status: h.status.name().to_string(),
                prediction_ms: h.prediction_ms,
                refused: h.refused,
                reason: h.reason.clone(),
                report: Report::of(e.seq),
            }),
        }
    }
}

impl SocketLine {
    /// The event this line carries; `Ok(None)` for the greeting and a refusal.
    pub fn into_event(self) -> Result<Option<PenEvent>, WireError> {
        let bare = |kind, t| -> Result<PenEvent, WireError> {
            Ok(PenEvent {
                kind,
                t_us: micros(t)?,
                point: None,
                sw: None,
                seq: None,
            })
        };
        let pen = |kind, p: Pen| -> Result<PenEvent, WireError> {
            Ok(PenEvent {
                kind,
                t_us: micros(p.t)?,
                point: p.point.read()?,
                sw: p.sw,
                seq: p.report.read()?,
            })
        };
        let button = |down: bool, b: Button| -> Result<PenEvent, WireError> {
            if !(2..=3).contains(&b.button) {
                return Err(WireError::Button(b.button));
            }
            let kind = if down {
                EventKind::ButtonDown { button: b.button }
            } else {
                EventKind::ButtonUp { button: b.button }
            };
            Ok(PenEvent {
                kind,
                t_us: micros(b.t)?,
                point: b.point.read()?,
                sw: b.sw,
                seq: b.report.read()?,
            })
        };
        Ok(Some(match self {
            SocketLine::Hello(Hello { t, .. }) | SocketLine::Refused(Refused { t, .. }) => {
                micros(t)?;
                return Ok(None);
            }
            SocketLine::ProximityIn(p) => pen(EventKind::ProximityIn, p)?,
            SocketLine::ProximityOut(p) => pen(EventKind::ProximityOut, p)?,
            SocketLine::TipDown(p) => pen(EventKind::TipDown, p)?,
            SocketLine::TipUp(p) => pen(EventKind::TipUp, p)?,
            SocketLine::Motion(p) => pen(EventKind::Motion, p)?,
            SocketLine::ButtonDown(b) => button(true, b)?,
            SocketLine::ButtonUp(b) => button(false, b)?,
            SocketLine::DeviceLost(d) => bare(EventKind::DeviceLost { reason: d.reason }, d.t)?,
            SocketLine::DeviceFound(d) => bare(EventKind::DeviceFound { device: d.device }, d.t)?,
            SocketLine::Missed(m) => bare(EventKind::Missed { count: m.count }, m.t)?,
            SocketLine::Head(h) => PenEvent {
                t_us: micros(h.t)?,
                seq: h.report.read()?,
                kind: EventKind::Head(HeadPose {
                    at: h.point.read()?,
                    status: HeadStatus::from_name(&h.status).ok_or(WireError::HeadStatus(h.status))?,
                    prediction_ms: h.prediction_ms,
                    refused: h.refused,
                    reason: h.reason,
                }),
                point: None,
                sw: None,
            },
        }))
    }

    /// The line as sent: one JSON object and a newline.
    pub fn to_text(&self) -> String {
        // Every field is a number, a bool or a string: serializing cannot fail.
        let mut s = serde_json::to_string(self).unwrap_or_default();
        s.push('\n');
        s
    }
}
