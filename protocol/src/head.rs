//! The head input report (ID 0x08, protocol 2.1): where the viewer's shutter glasses are, from
//! the second emitter the base station fires between the pen's bursts.
//!
//! The position is the head filter's estimate *predicted* `prediction_ms` ahead of the
//! measurement (the seed's anchor, the InterSense IS-900, predicts up to 50 ms), so a host that
//! renders about that long after the burst draws the eyes where they are when the frame is seen.
//! A slot without a fix repeats the last position with `no_fix` set and 0 receivers used: the
//! host keeps its last pose and says so.

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;
use crate::pen::{MAX_RECEIVERS, Position, Quality};

/// The longest prediction the report carries, ms: beyond it a constant-velocity guess of a head
/// is worse than the stale pose (the IS-900 stops at 50 ms too).
pub const MAX_PREDICTION_MS: u8 = 50;

/// The head report, sent once per head slot of the multiplexing schedule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadReport {
    /// This slot had no fix: the position is the last one (or zero before the first fix) and
    /// must be kept, not trusted as new.
    pub no_fix: bool,
    /// The position is in the display frame (the device applies a calibration), not the
    /// tracker frame.
    pub display_frame: bool,
    /// The glasses' emitter, predicted `prediction_ms` ahead of `timestamp_us`.
    pub position: Position,
    /// How far ahead of the measurement the position is predicted, ms, 0…[`MAX_PREDICTION_MS`].
    pub prediction_ms: u8,
    /// Increments by one per head report, wrapping (its own count, not the pen's).
    pub seq: u16,
    /// Device time of the head burst the position comes from, µs, wrapping as the pen's.
    pub timestamp_us: u32,
    /// Confidence in the fix (receivers used 0 with `no_fix`).
    pub quality: Quality,
}

const NO_FIX: u8 = 1 << 0;
const DISPLAY_FRAME: u8 = 1 << 1;

impl Report for HeadReport {
    const ID: ReportId = ReportId::Head;
    const LEN: usize = 18;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(if self.no_fix { NO_FIX } else { 0 } | if self.display_frame { DISPLAY_FRAME } else { 0 });
        self.position.write(w);
        w.u8(self.prediction_ms);
        w.u16(self.seq);
        w.u32(self.timestamp_us);
        self.quality.write(w);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let flags = r.flags(NO_FIX | DISPLAY_FRAME)?;
        let position = Position::read(r, ReportId::Head)?;
        let prediction_ms = r.u8()?;
        if prediction_ms > MAX_PREDICTION_MS {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Head,
                field: "prediction_ms",
            });
        }
        let seq = r.u16()?;
        let timestamp_us = r.u32()?;
        let receivers_used = r.u8()?;
        let no_fix = flags & NO_FIX != 0;
        // A fix uses at least three receivers; no fix uses none. Anything else has two readings.
        if receivers_used as usize > MAX_RECEIVERS || no_fix != (receivers_used == 0) {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Head,
                field: "receivers_used",
            });
        }
        let quality = Quality {
            receivers_used,
            residual: r.u8()?,
            dop: r.u8()?,
        };
        Ok(HeadReport {
            no_fix,
            display_frame: flags & DISPLAY_FRAME != 0,
            position,
            prediction_ms,
            seq,
            timestamp_us,
            quality,
        })
    }
}

impl HeadReport {
    /// The encoded report.
    pub fn to_bytes(&self) -> [u8; Self::LEN] {
        let mut out = [0u8; Self::LEN];
        // The array has exactly `LEN` bytes, so encoding cannot fail.
        let _ = self.encode(&mut out);
        out
    }
}
