//! The configuration feature report (ID 0x04, read and write) and its validation.
//!
//! Decoding checks the form (length, flags, finite numbers, unused slots zero); [`Config::validate`]
//! checks the values. A device applies a configuration only when both pass and otherwise keeps the
//! old one, answering with a [`Status`](crate::Status) that names the field.

use core::fmt;

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;
use crate::pen::MAX_RECEIVERS;

/// Position smoothing.
///
/// JSON (feature `serde`): `{"kind": "off"}` or `{"kind": "one_euro", "min_cutoff_hz", "beta",
/// "d_cutoff_hz"}`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(tag = "kind", rename_all = "snake_case", try_from = "crate::config::FilterJson")
)]
pub enum Filter {
    /// Report raw fixes.
    Off,
    /// The 1€ filter (Casiez et al., CHI 2012): a low-pass whose cutoff rises with speed, so a
    /// still pen is steady and a moving one lags little.
    OneEuro {
        /// Cutoff at rest, Hz.
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::wide"))]
        min_cutoff_hz: f32,
        /// Cutoff increase per mm/s of speed, Hz·s/mm.
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::wide"))]
        beta: f32,
        /// Cutoff of the speed estimate, Hz.
        #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::wide"))]
        d_cutoff_hz: f32,
    },
}

impl Filter {
    const KIND_OFF: u8 = 0;
    const KIND_ONE_EURO: u8 = 1;
}

/// The similarity transform from the tracker frame to the display frame:
/// `p_display = scale · R(rotation) · p_tracker + translation`, where the display frame has u, v
/// in the display surface and h along its normal, towards the user.
///
/// With it, the display's size: the display frame's u runs 0…width to the right and v 0…height
/// up across the display's active area, from its bottom-left corner; the operating system's pen
/// report spans it (with Y = height − v, down from the top, as screens count).
///
/// JSON (feature `serde`): `{"rotation_wxyz", "translation_mm", "scale", "size_mm"}`;
/// `size_mm` may be left out (unknown).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct DisplayPose {
    /// Unit quaternion `[w, x, y, z]`.
    #[cfg_attr(
        feature = "serde",
        serde(rename = "rotation_wxyz", serialize_with = "crate::wide::wide_array")
    )]
    pub rotation: [f32; 4],
    /// Translation, mm.
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::wide_array"))]
    pub translation_mm: [f32; 3],
    /// Scale (1 for a rigid transform).
    #[cfg_attr(feature = "serde", serde(serialize_with = "crate::wide::wide"))]
    pub scale: f32,
    /// The display's active area, width × height, mm; `[0, 0]` when unknown (the operating
    /// system's pen is then never in range).
    #[cfg_attr(feature = "serde", serde(default, serialize_with = "crate::wide::wide_array"))]
    pub size_mm: [f32; 2],
}

/// The base station's configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Receivers in use, 3 to [`MAX_RECEIVERS`]; the first `receiver_count` slots below are used.
    pub receiver_count: u8,
    /// Receiver positions in the tracker frame, mm. Unused slots encode as zero.
    pub receivers_mm: [[f32; 3]; MAX_RECEIVERS],
    /// Per-receiver transducer and detector delay, µs, subtracted from each capture.
    pub transducer_delay_us: [f32; MAX_RECEIVERS],
    /// Air temperature, °C: the speed of sound is 331.3·√(1 + T/273.15) m/s.
    pub temperature_c: f32,
    /// A measured speed of sound, m/s, used instead of the temperature's when set.
    pub speed_of_sound_m_s: Option<f32>,
    /// Pen reports per second, or 0 for one report per measurement cycle at the fastest cycle
    /// rate. A rate below the fastest cycle rate slows the cycles to match; a rate above it
    /// repeats the latest fix between cycles.
    pub report_rate_hz: u16,
    /// Position smoothing.
    pub filter: Filter,
    /// Switch debounce time, ms.
    pub debounce_ms: u8,
    /// Where the display is, for the tip-contact constraint and display-frame reports.
    pub display: Option<DisplayPose>,
    /// Report positions in the display frame (needs `display`).
    pub report_display_frame: bool,
    /// Send a time-of-flight diagnostics report after every pen report.
    pub stream_tof: bool,
}

const FIXED_SPEED: u8 = 1 << 0;
const HAS_DISPLAY: u8 = 1 << 1;
const DISPLAY_FRAME: u8 = 1 << 2;
const STREAM_TOF: u8 = 1 << 3;
const FLAG_BITS: u8 = FIXED_SPEED | HAS_DISPLAY | DISPLAY_FRAME | STREAM_TOF;

impl Report for Config {
    const ID: ReportId = ReportId::Config;
    const LEN: usize = 195;

    fn write_body(&self, w: &mut Writer<'_>) {
        let count = (self.receiver_count as usize).min(MAX_RECEIVERS);
        let flag = |on: bool, bit: u8| if on { bit } else { 0 };
        w.u8(self.receiver_count);
        w.u8(flag(self.speed_of_sound_m_s.is_some(), FIXED_SPEED)
            | flag(self.display.is_some(), HAS_DISPLAY)
            | flag(self.report_display_frame, DISPLAY_FRAME)
            | flag(self.stream_tof, STREAM_TOF));
        let (kind, params) = match self.filter {
            Filter::Off => (Filter::KIND_OFF, [0.0; 3]),
            Filter::OneEuro {
                min_cutoff_hz,
                beta,
                d_cutoff_hz,
            } => (Filter::KIND_ONE_EURO, [min_cutoff_hz, beta, d_cutoff_hz]),
        };
        w.u8(kind);
        w.u8(self.debounce_ms);
        w.u16(self.report_rate_hz);
        w.f32(self.temperature_c);
        w.f32(self.speed_of_sound_m_s.unwrap_or(0.0));
        params.iter().for_each(|&p| w.f32(p));
        // Unused slots are written as zero whatever the struct holds: one canonical encoding.
        for (i, r) in self.receivers_mm.iter().enumerate() {
            r.iter().for_each(|&v| w.f32(if i < count { v } else { 0.0 }));
        }
        for (i, &d) in self.transducer_delay_us.iter().enumerate() {
            w.f32(if i < count { d } else { 0.0 });
        }
        let pose = self.display.unwrap_or(DisplayPose {
            rotation: [0.0; 4],
            translation_mm: [0.0; 3],
            scale: 0.0,
            size_mm: [0.0; 2],
        });
        pose.rotation.iter().for_each(|&v| w.f32(v));
        pose.translation_mm.iter().for_each(|&v| w.f32(v));
        w.f32(pose.scale);
        pose.size_mm.iter().for_each(|&v| w.f32(v));
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let receiver_count = r.u8()?;
        if receiver_count as usize > MAX_RECEIVERS {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Config,
                field: "receiver_count",
            });
        }
        let count = receiver_count as usize;
        let flags = r.flags(FLAG_BITS)?;
        let kind_offset = r.offset();
        let kind = r.u8()?;
        let debounce_ms = r.u8()?;
        let report_rate_hz = r.u16()?;
        let temperature_c = r.f32("temperature_c")?;
        let speed_of_sound_m_s = if flags & FIXED_SPEED != 0 {
            Some(r.f32("speed_of_sound_m_s")?)
        } else {
            r.zero_f32("speed_of_sound_m_s")?;
            None
        };
        let filter = match kind {
            Filter::KIND_OFF => {
                for _ in 0..3 {
                    r.zero_f32("filter parameter")?;
                }
                Filter::Off
            }
            Filter::KIND_ONE_EURO => Filter::OneEuro {
                min_cutoff_hz: r.f32("filter.min_cutoff_hz")?,
                beta: r.f32("filter.beta")?,
                d_cutoff_hz: r.f32("filter.d_cutoff_hz")?,
            },
            other => {
                return Err(DecodeError::ReservedBits {
                    report: ReportId::Config,
                    offset: kind_offset,
                    value: other,
                });
            }
        };
        let mut receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
        for (i, rec) in receivers_mm.iter_mut().enumerate() {
            for v in rec.iter_mut() {
                if i < count {
                    *v = r.f32("receivers_mm")?;
                } else {
                    r.zero_f32("receivers_mm beyond receiver_count")?;
                }
            }
        }
        let mut transducer_delay_us = [0.0; MAX_RECEIVERS];
        for (i, d) in transducer_delay_us.iter_mut().enumerate() {
            if i < count {
                *d = r.f32("transducer_delay_us")?;
            } else {
                r.zero_f32("transducer_delay_us beyond receiver_count")?;
            }
        }
        let display = if flags & HAS_DISPLAY != 0 {
            let mut pose = DisplayPose {
                rotation: [0.0; 4],
                translation_mm: [0.0; 3],
                scale: 0.0,
                size_mm: [0.0; 2],
            };
            for v in pose.rotation.iter_mut() {
                *v = r.f32("display.rotation")?;
            }
            for v in pose.translation_mm.iter_mut() {
                *v = r.f32("display.translation_mm")?;
            }
            pose.scale = r.f32("display.scale")?;
            for v in pose.size_mm.iter_mut() {
                *v = r.f32("display.size_mm")?;
            }
            Some(pose)
        } else {
            for _ in 0..10 {
                r.zero_f32("display (absent)")?;
            }
            None
        };
        Ok(Config {
            receiver_count,
            receivers_mm,
            transducer_delay_us,
            temperature_c,
            speed_of_sound_m_s,
            report_rate_hz,
            filter,
            debounce_ms,
            display,
            report_display_frame: flags & DISPLAY_FRAME != 0,
            stream_tof: flags & STREAM_TOF != 0,
        })
    }
}

/// A configuration field, as named in errors and in the status report's field byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigField {
    /// `receiver_count`.
    ReceiverCount,
    /// The receiver set as a whole (e.g. all on one line).
    Receivers,
    /// `receivers_mm[i]`.
    Receiver(u8),
    /// `transducer_delay_us[i]`.
    TransducerDelay(u8),
    /// `temperature_c`.
    Temperature,
    /// `speed_of_sound_m_s`.
    SpeedOfSound,
    /// `report_rate_hz`.
    ReportRate,
    /// `filter` (its kind or a parameter).
    Filter,
    /// `debounce_ms`.
    Debounce,
    /// `display`.
    Display,
    /// `report_display_frame`.
    ReportDisplayFrame,
}

impl ConfigField {
    /// The field's code in the status report.
    pub fn code(self) -> u8 {
        match self {
            ConfigField::ReceiverCount => 0x01,
            ConfigField::Receivers => 0x02,
            ConfigField::Temperature => 0x03,
            ConfigField::SpeedOfSound => 0x04,
            ConfigField::ReportRate => 0x05,
            ConfigField::Filter => 0x06,
            ConfigField::Debounce => 0x07,
            ConfigField::Display => 0x08,
            ConfigField::ReportDisplayFrame => 0x09,
            ConfigField::Receiver(i) => 0x10 + (i & 0x07),
            ConfigField::TransducerDelay(i) => 0x18 + (i & 0x07),
        }
    }

    /// The field with status code `code`, if any.
    pub fn from_code(code: u8) -> Option<ConfigField> {
        Some(match code {
            0x01 => ConfigField::ReceiverCount,
            0x02 => ConfigField::Receivers,
            0x03 => ConfigField::Temperature,
            0x04 => ConfigField::SpeedOfSound,
            0x05 => ConfigField::ReportRate,
            0x06 => ConfigField::Filter,
            0x07 => ConfigField::Debounce,
            0x08 => ConfigField::Display,
            0x09 => ConfigField::ReportDisplayFrame,
            0x10..=0x17 => ConfigField::Receiver(code - 0x10),
            0x18..=0x1f => ConfigField::TransducerDelay(code - 0x18),
            _ => return None,
        })
    }
}

impl fmt::Display for ConfigField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConfigField::ReceiverCount => write!(f, "receiver_count"),
            ConfigField::Receivers => write!(f, "receivers_mm"),
            ConfigField::Receiver(i) => write!(f, "receivers_mm[{i}]"),
            ConfigField::TransducerDelay(i) => write!(f, "transducer_delay_us[{i}]"),
            ConfigField::Temperature => write!(f, "temperature_c"),
            ConfigField::SpeedOfSound => write!(f, "speed_of_sound_m_s"),
            ConfigField::ReportRate => write!(f, "report_rate_hz"),
            ConfigField::Filter => write!(f, "filter"),
            ConfigField::Debounce => write!(f, "debounce_ms"),
            ConfigField::Display => write!(f, "display"),
            ConfigField::ReportDisplayFrame => write!(f, "report_display_frame"),
        }
    }
}

/// What is wrong with a configuration value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Problem {
    /// Outside the field's documented range.
    OutOfRange,
    /// Geometrically unusable: receivers too close together or all on one line, a rotation that
    /// is not a unit quaternion.
    Degenerate,
    /// Needs another field that is not set (display-frame reports without a display pose).
    Missing,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Problem::OutOfRange => "out of range",
            Problem::Degenerate => "degenerate",
            Problem::Missing => "needs a field that is not set",
        })
    }
}

/// A configuration that decodes but cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub struct ConfigError {
    pub field: ConfigField,
    /// What is wrong with it.
    pub problem: Problem,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "configuration field {} is {}", self.field, self.problem)
    }
}

impl core::error::Error for ConfigError {}

/// Valid ranges, inclusive. Wide enough for any sane build, narrow enough to catch unit mistakes
/// (metres for millimetres, Kelvin for Celsius).
pub mod limits {
    /// Fewest receivers: three ranges fix a point up to a mirror image the display plane resolves.
    pub const MIN_RECEIVERS: u8 = 3;
    /// Largest receiver coordinate magnitude, mm.
    pub const MAX_COORDINATE_MM: f32 = 5000.0;
    /// Smallest distance between two receivers, and of any receiver from the line through the
    /// two farthest apart, mm.
    pub const MIN_SEPARATION_MM: f32 = 10.0;
    /// Transducer delay range, µs.
    pub const DELAY_US: (f32, f32) = (0.0, 1000.0);
    /// Air temperature range, °C.
    pub const TEMPERATURE_C: (f32, f32) = (-40.0, 85.0);
    /// Speed of sound range, m/s.
    pub const SPEED_OF_SOUND_M_S: (f32, f32) = (300.0, 400.0);
    /// Report rate range, Hz (a full-speed USB interrupt endpoint polls at most every 1 ms);
    /// 0 means one report per measurement cycle.
    pub const REPORT_RATE_HZ: (u16, u16) = (0, 1000);
    /// Debounce range, ms.
    pub const DEBOUNCE_MS: (u8, u8) = (0, 50);
    /// 1€ cutoff range (both cutoffs), Hz.
    pub const CUTOFF_HZ: (f32, f32) = (0.001, 100.0);
    /// 1€ beta range.
    pub const BETA: (f32, f32) = (0.0, 10.0);
    /// Allowed deviation of the rotation quaternion's norm from 1.
    pub const QUATERNION_NORM_TOLERANCE: f32 = 1e-3;
    /// A display's width and height, mm, when known: 50 mm to 3.2768 m (the OS pen report's 0.1 mm
    /// units in 15 bits).
    pub const DISPLAY_SIZE_MM: (f32, f32) = (50.0, 3276.7);
    /// Largest display translation magnitude per axis, mm.
    pub const MAX_TRANSLATION_MM: f32 = 10_000.0;
    /// Similarity scale range.
    pub const SCALE: (f32, f32) = (0.5, 2.0);
}

fn within<T: PartialOrd>(v: T, (lo, hi): (T, T)) -> bool {
    v >= lo && v <= hi
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl Config {
    /// Checks every value against [`limits`]; the first problem found is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        use limits::*;
        let fail = |field, problem| Err(ConfigError { field, problem });
        let finite = |v: f32| v.is_finite();

        if !within(self.receiver_count, (MIN_RECEIVERS, MAX_RECEIVERS as u8)) {
            return fail(ConfigField::ReceiverCount, Problem::OutOfRange);
        }
        let receivers = &self.receivers_mm[..self.receiver_count as usize];
        for (i, r) in receivers.iter().enumerate() {
            if !r.iter().all(|&v| finite(v) && v.abs() <= MAX_COORDINATE_MM) {
                return fail(ConfigField::Receiver(i as u8), Problem::OutOfRange);
            }
            let d = self.transducer_delay_us[i];
            if !(finite(d) && within(d, DELAY_US)) {
                return fail(ConfigField::TransducerDelay(i as u8), Problem::OutOfRange);
            }
        }
        // Geometry, in squared distances so no square root is needed.
        let min_sq = MIN_SEPARATION_MM * MIN_SEPARATION_MM;
        let (mut far, mut far_sq) = ((0, 0), 0.0);
        for (i, &a) in receivers.iter().enumerate() {
            for (j, &b) in receivers.iter().enumerate().skip(i + 1) {
                let d = sub(b, a);
                let d_sq = dot(d, d);
                if d_sq < min_sq {
                    return fail(ConfigField::Receiver(j as u8), Problem::Degenerate);
                }
                if d_sq > far_sq {
                    (far, far_sq) = ((i, j), d_sq);
                }
            }
        }
        let (a, b) = (receivers[far.0], receivers[far.1]);
        let ab = sub(b, a);
        let off_line = receivers.iter().any(|&c| {
            let n = cross(ab, sub(c, a));
            // |ab × ac| / |ab| is c's distance from the line through a and b.
            dot(n, n) >= min_sq * far_sq
        });
        if !off_line {
            return fail(ConfigField::Receivers, Problem::Degenerate);
        }

        if !within(self.temperature_c, TEMPERATURE_C) {
            return fail(ConfigField::Temperature, Problem::OutOfRange);
        }
        if let Some(c) = self.speed_of_sound_m_s
            && !within(c, SPEED_OF_SOUND_M_S)
        {
            return fail(ConfigField::SpeedOfSound, Problem::OutOfRange);
        }
        if !within(self.report_rate_hz, REPORT_RATE_HZ) {
            return fail(ConfigField::ReportRate, Problem::OutOfRange);
        }
        if let Filter::OneEuro {
            min_cutoff_hz,
            beta,
            d_cutoff_hz,
        } = self.filter
            && !(within(min_cutoff_hz, CUTOFF_HZ) && within(beta, BETA) && within(d_cutoff_hz, CUTOFF_HZ))
        {
            return fail(ConfigField::Filter, Problem::OutOfRange);
        }
        if !within(self.debounce_ms, DEBOUNCE_MS) {
            return fail(ConfigField::Debounce, Problem::OutOfRange);
        }
        if let Some(pose) = &self.display {
            let q = pose.rotation;
            let norm_sq = q.iter().map(|v| v * v).sum::<f32>();
            let tol = QUATERNION_NORM_TOLERANCE;
            if !within(norm_sq, ((1.0 - tol) * (1.0 - tol), (1.0 + tol) * (1.0 + tol))) {
                return fail(ConfigField::Display, Problem::Degenerate);
            }
            let t_ok = pose.translation_mm.iter().all(|v| v.abs() <= MAX_TRANSLATION_MM);
            // Unknown (both 0) or a real display: the OS report's 0.1 mm units must fit u16.
            let size_ok = pose.size_mm == [0.0; 2] || pose.size_mm.iter().all(|&v| within(v, DISPLAY_SIZE_MM));
            if !t_ok || !within(pose.scale, SCALE) || !size_ok {
                return fail(ConfigField::Display, Problem::OutOfRange);
            }
        } else if self.report_display_frame {
            return fail(ConfigField::ReportDisplayFrame, Problem::Missing);
        }
        Ok(())
    }
}

/// `filter` as read: a `kind` and, for the 1€ filter, its three parameters.
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterJson {
    kind: FilterKind,
    min_cutoff_hz: Option<f32>,
    beta: Option<f32>,
    d_cutoff_hz: Option<f32>,
}

#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
#[serde(rename_all = "snake_case")]
enum FilterKind {
    Off,
    OneEuro,
}

/// Why a `filter` object is not one.
#[cfg(feature = "serde")]
#[derive(Debug)]
pub struct FilterJsonError(&'static str);

#[cfg(feature = "serde")]
impl core::fmt::Display for FilterJsonError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.0)
    }
}

#[cfg(feature = "serde")]
impl TryFrom<FilterJson> for Filter {
    type Error = FilterJsonError;

    fn try_from(j: FilterJson) -> Result<Filter, FilterJsonError> {
        match j.kind {
            FilterKind::Off => match (j.min_cutoff_hz, j.beta, j.d_cutoff_hz) {
                (None, None, None) => Ok(Filter::Off),
                _ => Err(FilterJsonError("the filter \"off\" takes no parameters")),
            },
            FilterKind::OneEuro => match (j.min_cutoff_hz, j.beta, j.d_cutoff_hz) {
                (Some(min_cutoff_hz), Some(beta), Some(d_cutoff_hz)) => Ok(Filter::OneEuro {
                    min_cutoff_hz,
                    beta,
                    d_cutoff_hz,
                }),
                _ => Err(FilterJsonError(
                    "the filter \"one_euro\" needs min_cutoff_hz, beta and d_cutoff_hz",
                )),
            },
        }
    }
}
