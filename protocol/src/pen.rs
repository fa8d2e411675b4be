//! The pen input report (ID 0x01): switches, position, sequence number, timestamp, quality.

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;

/// Logical position units per millimetre: one unit is 0.1 mm.
pub const UNITS_PER_MM: f32 = 10.0;
/// The largest logical position value; the smallest is its negation. -32768 is never sent.
pub const POSITION_LOGICAL_MAX: i16 = i16::MAX;
/// The most receivers a base station has (TIM2 and TIM5 give eight capture channels).
pub const MAX_RECEIVERS: usize = 8;

/// A position in logical units of 0.1 mm, in the tracker frame or, when the report says so, the
/// display frame (u, v on the surface, h along its normal).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Position {
    /// X (or u), 0.1 mm.
    pub x: i16,
    /// Y (or v), 0.1 mm.
    pub y: i16,
    /// Z (or h), 0.1 mm.
    pub z: i16,
}

impl Position {
    /// Converts millimetres to logical units, rounding to the nearest 0.1 mm. `None` when a
    /// coordinate is not finite or lies beyond ±3276.7 mm.
    pub fn from_mm(mm: [f32; 3]) -> Option<Position> {
        let limit = POSITION_LOGICAL_MAX as f32 / UNITS_PER_MM;
        if mm.iter().any(|v| !v.is_finite() || v.abs() > limit) {
            return None;
        }
        let unit = |v: f32| {
            let u = v * UNITS_PER_MM;
            // `as` saturates; the range check above keeps the result within ±32767.
            if u >= 0.0 { (u + 0.5) as i16 } else { (u - 0.5) as i16 }
        };
        Some(Position {
            x: unit(mm[0]),
            y: unit(mm[1]),
            z: unit(mm[2]),
        })
    }

    /// The position in millimetres.
    pub fn to_mm(self) -> [f32; 3] {
        [
            self.x as f32 / UNITS_PER_MM,
            self.y as f32 / UNITS_PER_MM,
            self.z as f32 / UNITS_PER_MM,
        ]
    }
}

/// How much to trust a fix: the receivers it used, how well their ranges agree, and how the
/// geometry amplifies range errors.
///
/// JSON (feature `serde`): `receivers_used`, `residual_mm` and `dop` as decimal numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Quality {
    /// Receivers whose ranges the fix used (0 = no fix, at most [`MAX_RECEIVERS`]).
    pub receivers_used: u8,
    /// RMS range residual of the fix in 0.1 mm; 255 means 25.5 mm or more, or unknown.
    #[cfg_attr(
        feature = "serde",
        serde(rename = "residual_mm", serialize_with = "crate::wide::tenths")
    )]
    pub residual: u8,
    /// Position dilution of precision ×10; 255 means 25.5 or more, or unknown.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::tenths"))]
    pub dop: u8,
}

impl Quality {
    /// The figure of a cycle without a fix.
    pub const NONE: Quality = Quality {
        receivers_used: 0,
        residual: u8::MAX,
        dop: u8::MAX,
    };

    /// Builds the figure from the solver's numbers, saturating each at 255 steps.
    pub fn new(receivers_used: u8, residual_mm: f32, dop: f32) -> Quality {
        let step = |v: f32| {
            if v.is_finite() {
                (v * 10.0 + 0.5).clamp(0.0, 255.0) as u8
            } else {
                u8::MAX
            }
        };
        Quality {
            receivers_used: receivers_used.min(MAX_RECEIVERS as u8),
            residual: step(residual_mm),
            dop: step(dop),
        }
    }

    /// RMS range residual in millimetres (25.5 when saturated or unknown).
    pub fn residual_mm(self) -> f32 {
        self.residual as f32 / 10.0
    }

    /// Position dilution of precision (25.5 when saturated or unknown).
    pub fn dop(self) -> f32 {
        self.dop as f32 / 10.0
    }
}

/// The pen input report, sent once per measurement cycle.
///
/// `in_range` is HID In Range: the pen was fixed within the last 100 ms, or its tip is pressed
/// (after a first fix). A cycle without a fix repeats the last position with
/// `quality.receivers_used` 0; when `in_range` is false the position is stale (zero before the
/// first fix) and hosts must not use it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PenReport {
    /// SW1, the tip switch (HID Tip Switch).
    pub sw1: bool,
    /// SW2, the barrel button nearer the tip (HID Barrel Switch).
    pub sw2: bool,
    /// SW3, the second barrel button (HID Secondary Barrel Switch).
    pub sw3: bool,
    /// HID In Range: a fix within the last 100 ms, or the tip pressed (see above).
    pub in_range: bool,
    /// The position is in the display frame (the device applies a calibration), not the tracker frame.
    pub display_frame: bool,
    /// The tip position.
    pub position: Position,
    /// Increments by one per report, wrapping; a gap tells the host how many reports it lost.
    pub seq: u16,
    /// Device time of the measurement in microseconds, wrapping every 2³² µs (about 71.6 minutes).
    pub timestamp_us: u32,
    /// Confidence in the fix.
    pub quality: Quality,
}

// Bits of byte 1.
const SW1: u8 = 1 << 0;
const SW2: u8 = 1 << 1;
const SW3: u8 = 1 << 2;
const IN_RANGE: u8 = 1 << 3;
const DISPLAY_FRAME: u8 = 1 << 4;
const SWITCH_BITS: u8 = SW1 | SW2 | SW3 | IN_RANGE | DISPLAY_FRAME;

impl Position {
    /// Writes the three axes, as every report with a position carries them.
    pub(crate) fn write(&self, w: &mut Writer<'_>) {
        w.i16(self.x);
        w.i16(self.y);
        w.i16(self.z);
    }

    /// Reads three axes of `report`, refusing the one value no axis holds (below
    /// −[`POSITION_LOGICAL_MAX`]), named by its field.
    pub(crate) fn read(r: &mut Reader<'_>, report: ReportId) -> Result<Position, DecodeError> {
        let mut axis = |field| {
            let v = r.i16()?;
            if v < -POSITION_LOGICAL_MAX {
                return Err(DecodeError::OutOfRange { report, field });
            }
            Ok(v)
        };
        Ok(Position {
            x: axis("x")?,
            y: axis("y")?,
            z: axis("z")?,
        })
    }
}

impl Quality {
    /// Writes receivers used, residual and dilution of precision, in that order.
    pub(crate) fn write(&self, w: &mut Writer<'_>) {
        w.u8(self.receivers_used);
        w.u8(self.residual);
        w.u8(self.dop);
    }
}

impl Report for PenReport {
    const ID: ReportId = ReportId::Pen;
    const LEN: usize = 17;

    fn write_body(&self, w: &mut Writer<'_>) {
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        w.u8(bit(self.sw1, SW1)
            | bit(self.sw2, SW2)
            | bit(self.sw3, SW3)
            | bit(self.in_range, IN_RANGE)
            | bit(self.display_frame, DISPLAY_FRAME));
        self.position.write(w);
        w.u16(self.seq);
        w.u32(self.timestamp_us);
        self.quality.write(w);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let switches = r.flags(SWITCH_BITS)?;
        let position = Position::read(r, ReportId::Pen)?;
        let seq = r.u16()?;
        let timestamp_us = r.u32()?;
        let receivers_used = r.u8()?;
        if receivers_used as usize > MAX_RECEIVERS {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Pen,
                field: "receivers_used",
            });
        }
        let quality = Quality {
            receivers_used,
            residual: r.u8()?,
            dop: r.u8()?,
        };
        Ok(PenReport {
            sw1: switches & SW1 != 0,
            sw2: switches & SW2 != 0,
            sw3: switches & SW3 != 0,
            in_range: switches & IN_RANGE != 0,
            display_frame: switches & DISPLAY_FRAME != 0,
            position,
            seq,
            timestamp_us,
            quality,
        })
    }
}

impl PenReport {
    /// The encoded report.
    pub fn to_bytes(&self) -> [u8; Self::LEN] {
        let mut out = [0u8; Self::LEN];
        // The array has exactly `LEN` bytes, so encoding cannot fail.
        let _ = self.encode(&mut out);
        out
    }
}
