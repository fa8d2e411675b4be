//! The tracked head on the host: head reports as samples, into the display frame through the
//! calibration, and the `head` events pend publishes (docs/events.md).
//!
//! Bad input is kept from the viewer: a report without a fix keeps the last pose and says so
//! (`held`), and a pose behind the display surface (h < 0: the glasses cannot be there; a wrong
//! calibration or a mirrored solution) is refused with the reason and a running count, the last
//! good pose kept. Either way a client that draws from the head always has a pose it can use.

use glam::DVec3;
use pen_protocol::{HeadReport, Quality};
use serde::Serialize;

use crate::events::{DisplayPoint, EventKind, PenEvent};
pub use crate::events::{HeadPose, HeadStatus};
use crate::sample::unwrap_device_us;

/// One head report, decoded and timed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadSample {
    /// The report's sequence number (the head's own count).
    pub seq: u16,
    /// Device time of the head's burst, µs since the device started (unwrapped).
    pub device_us: u64,
    /// Host time the report arrived, µs since the Unix epoch.
    pub host_us: u64,
    /// The slot had no fix: the position is the last one.
    pub no_fix: bool,
    /// The position is in the display frame (the device applies a calibration).
    pub display_frame: bool,
    /// The glasses' emitter, predicted `prediction_ms` ahead: tracker or display frame, mm.
    pub position_mm: DVec3,
    /// How far ahead of `device_us` the position is predicted, ms.
    pub prediction_ms: u8,
    /// How far to trust the fix.
    pub quality: Quality,
}

impl HeadSample {
    /// The sample as `penctl monitor --json` prints it (docs/penctl.md).
    pub fn json(&self) -> impl Serialize + '_ {
        let r = |v: f64| (v * 10.0).round() / 10.0;
        HeadJson {
            head: true,
            seq: self.seq,
            device_us: self.device_us,
            host_us: self.host_us,
            no_fix: self.no_fix,
            display_frame: self.display_frame,
            x_mm: r(self.position_mm.x),
            y_mm: r(self.position_mm.y),
            z_mm: r(self.position_mm.z),
            prediction_ms: self.prediction_ms,
            quality: &self.quality,
        }
    }
}

#[derive(Serialize)]
struct HeadJson<'a> {
    head: bool,
    seq: u16,
    device_us: u64,
    host_us: u64,
    no_fix: bool,
    display_frame: bool,
    x_mm: f64,
    y_mm: f64,
    z_mm: f64,
    prediction_ms: u8,
    quality: &'a Quality,
}

/// Turns head reports into samples: unwraps the device clock as the pen's samples do.
#[derive(Debug, Default, Clone)]
pub struct HeadSampler {
    last_device_us: Option<u64>,
}

impl HeadSampler {
    /// A sampler with no history.
    pub fn new() -> HeadSampler {
        HeadSampler::default()
    }

    /// The sample of `report`, received at `host_us`.
    pub fn sample(&mut self, report: &HeadReport, host_us: u64) -> HeadSample {
        let device_us = unwrap_device_us(self.last_device_us, report.timestamp_us);
        self.last_device_us = Some(device_us);
        let units = pen_protocol::UNITS_PER_MM as f64;
        let p = report.position;
        HeadSample {
            seq: report.seq,
            device_us,
            host_us,
            no_fix: report.no_fix,
            display_frame: report.display_frame,
            position_mm: DVec3::new(p.x as f64 / units, p.y as f64 / units, p.z as f64 / units),
            prediction_ms: report.prediction_ms,
            quality: report.quality,
        }
    }
}

/// Keeps the last good head pose; turns head samples into `head` events.
#[derive(Debug, Default, Clone)]
pub struct HeadTracker {
    last: Option<DisplayPoint>,
    refused: u64,
}

impl HeadTracker {
    /// No pose yet.
    pub fn new() -> HeadTracker {
        HeadTracker::default()
    }

    /// Head reports refused so far (behind the display).
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The last good pose.
    pub fn last(&self) -> Option<DisplayPoint> {
        self.last
    }

    /// The event of `sample`, whose position is `point` in the display frame, at host time
    /// `t_us`.
    pub fn on_sample(&mut self, sample: &HeadSample, point: DisplayPoint, t_us: u64) -> PenEvent {
        let (status, reason) = if sample.no_fix {
            (
                HeadStatus::Held,
                Some("no head fix in this report (glasses turned away or shadowed): keeping the last pose".to_string()),
            )
        } else if point.h_mm < 0.0 {
            self.refused += 1;
            (
                HeadStatus::Refused,
                Some(format!(
                    "head {:.1} mm behind the display surface refused ({} so far): keeping the last pose; \
                     check the calibration (`penctl calibrate`)",
                    -point.h_mm, self.refused
                )),
            )
        } else {
            self.last = Some(point);
            (HeadStatus::Tracked, None)
        };
        PenEvent {
            kind: EventKind::Head(HeadPose {
                at: self.last,
                status,
                prediction_ms: sample.prediction_ms,
                refused: self.refused,
                reason,
            }),
            t_us,
            point: None,
            sw: None,
            seq: Some((sample.seq, sample.device_us)),
        }
    }
}
