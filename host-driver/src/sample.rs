//! Samples: pen reports as the host uses them — positions in millimetres, the device clock
//! unwrapped to 64 bits, the host's receive time, and lost reports counted from sequence numbers.

use std::time::{SystemTime, UNIX_EPOCH};

use glam::DVec3;
use pen_protocol::{PenReport, Quality};
use serde::Serialize;

/// One pen report, decoded and timed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The report's sequence number.
    pub seq: u16,
    /// Device time of the measurement, µs since the device started (unwrapped).
    pub device_us: u64,
    /// Host time the report arrived, µs since the Unix epoch.
    pub host_us: u64,
    /// SW1, SW2, SW3.
    pub sw: [bool; 3],
    /// The pen is in range (fixed within 100 ms, or its tip pressed); `position_mm` is
    /// meaningless otherwise. A fresh fix this cycle has `quality.receivers_used` > 0.
    pub in_range: bool,
    /// The position is in the display frame (the device applies a calibration).
    pub display_frame: bool,
    /// The position: tracker frame (x, y, z) or, with `display_frame`, display frame (u, v, h), mm.
    pub position_mm: DVec3,
    /// How far to trust the fix.
    pub quality: Quality,
}

impl Sample {
    /// The sample as `penctl monitor --json` prints it, with the reports lost just before it
    /// (docs/penctl.md): positions rounded to the reports' 0.1 mm.
    pub fn json(&self, lost: u64) -> impl Serialize + '_ {
        let r = |v: f64| (v * 10.0).round() / 10.0;
        SampleJson {
            seq: self.seq,
            device_us: self.device_us,
            host_us: self.host_us,
            in_range: self.in_range,
            display_frame: self.display_frame,
            x_mm: r(self.position_mm.x),
            y_mm: r(self.position_mm.y),
            z_mm: r(self.position_mm.z),
            sw1: self.sw[0],
            sw2: self.sw[1],
            sw3: self.sw[2],
            quality: &self.quality,
            lost,
        }
    }
}

#[derive(Serialize)]
struct SampleJson<'a> {
    seq: u16,
    device_us: u64,
    host_us: u64,
    in_range: bool,
    display_frame: bool,
    x_mm: f64,
    y_mm: f64,
    z_mm: f64,
    sw1: bool,
    sw2: bool,
    sw3: bool,
    quality: &'a Quality,
    lost: u64,
}

/// Microseconds since the Unix epoch, now.
pub fn now_us() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_micros() as u64)
}

/// The device clock, which wraps every 2³² µs, extended to 64 bits with the previous value's
/// high bits (`prev`, the last unwrapped time of the same stream).
pub fn unwrap_device_us(prev: Option<u64>, timestamp_us: u32) -> u64 {
    match prev {
        Some(prev) => {
            let candidate = (prev & !0xFFFF_FFFF) | timestamp_us as u64;
            if candidate + 0x8000_0000 < prev {
                candidate + 0x1_0000_0000
            } else {
                candidate
            }
        }
        None => timestamp_us as u64,
    }
}

/// Turns reports into samples: unwraps the device's 32-bit microsecond clock and counts the
/// reports lost between consecutive sequence numbers.
#[derive(Debug, Default, Clone)]
pub struct Sampler {
    last_seq: Option<u16>,
    last_device_us: Option<u64>,
    lost: u64,
    received: u64,
}

impl Sampler {
    /// A sampler with no history (after attaching or reattaching to a device).
    pub fn new() -> Sampler {
        Sampler::default()
    }

    /// Reports lost so far, from gaps in the sequence numbers.
    pub fn lost(&self) -> u64 {
        self.lost
    }

    /// Reports received so far.
    pub fn received(&self) -> u64 {
        self.received
    }

    /// The sample of `report`, received at `host_us`; also returns how many reports were lost
    /// just before it.
    pub fn sample(&mut self, report: &PenReport, host_us: u64) -> (Sample, u64) {
        let gap = match self.last_seq {
            Some(last) => report.seq.wrapping_sub(last).wrapping_sub(1) as u64,
            None => 0,
        };
        // A gap of more than half the counter's range is a repeated or reordered report, not
        // 32 000 lost ones: count nothing.
        let gap = if gap < 0x8000 { gap } else { 0 };
        self.lost += gap;
        self.received += 1;
        self.last_seq = Some(report.seq);
        let device_us = unwrap_device_us(self.last_device_us, report.timestamp_us);
        self.last_device_us = Some(device_us);
        // From the logical units in f64: 0.1 mm steps stay exact decimals.
        let units = pen_protocol::UNITS_PER_MM as f64;
        let p = report.position;
        let sample = Sample {
            seq: report.seq,
            device_us,
            host_us,
            sw: [report.sw1, report.sw2, report.sw3],
            in_range: report.in_range,
            display_frame: report.display_frame,
            position_mm: DVec3::new(p.x as f64 / units, p.y as f64 / units, p.z as f64 / units),
            quality: report.quality,
        };
        (sample, gap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pen_protocol::Position;

    fn report(seq: u16, timestamp_us: u32) -> PenReport {
        PenReport {
            sw1: false,
            sw2: true,
            sw3: false,
            in_range: true,
            display_frame: false,
            position: Position { x: 1234, y: -5, z: 70 },
            seq,
            timestamp_us,
            quality: Quality {
                receivers_used: 4,
                residual: 3,
                dop: 18,
            },
        }
    }

    #[test]
    fn gaps_are_counted_across_the_wrap() {
        let mut s = Sampler::new();
        assert_eq!(s.sample(&report(65_533, 0), 0).1, 0);
        assert_eq!(s.sample(&report(65_534, 0), 0).1, 0);
        // 65535 and 0 lost.
        assert_eq!(s.sample(&report(1, 0), 0).1, 2);
        assert_eq!((s.lost(), s.received()), (2, 3));
        // A repeated report is not 65 535 lost ones.
        assert_eq!(s.sample(&report(1, 0), 0).1, 0);
    }

    #[test]
    fn the_device_clock_unwraps() {
        let mut s = Sampler::new();
        let (a, _) = s.sample(&report(0, u32::MAX - 10), 5);
        let (b, _) = s.sample(&report(1, 20), 6);
        assert_eq!(a.device_us, u32::MAX as u64 - 10);
        assert_eq!(b.device_us, (1u64 << 32) + 20);
        assert_eq!(b.host_us, 6);
        assert_eq!(b.position_mm, DVec3::new(123.4, -0.5, 7.0));
        assert_eq!(b.sw, [false, true, false]);
    }
}
