//! The JSON forms of reports and of the configuration (feature `serde`), as `penctl decode`,
//! `penctl info --json` and `penctl config get --json` print them (docs/penctl.md).
//!
//! Every report serializes as an object of its fields in physical units: positions and lengths
//! in mm, times in µs. A [`Message`] adds `report_id` (number) and `report` (name) in front. A
//! [`Config`] on its own is the settings object `penctl config set --file` reads back; it reads
//! as a [`ConfigChanges`], which keeps the values of keys it lacks.
//!
//! Numbers the device holds as `f32` are written as the shortest decimal that reads back as the
//! same `f32` (`0.1f32` prints as `0.1`, not as the `0.10000000149011612` it widens to): reading
//! the JSON back gives the device's value exactly.
//! No allocation: the firmware may enable the feature too.

use core::fmt;

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};

use crate::config::{Config, ConfigField, DisplayPose, Filter};
use crate::info::DeviceInfo;
use crate::pen::{MAX_RECEIVERS, PenReport, Quality};
use crate::reset::{ResetKind, ResetRecord};
use crate::status::{Command, GetFeature, Status};
use crate::tof::{NO_ARRIVAL, TofReport};
use crate::wide::{tenths, wide, wide_list, wide_opt};
use crate::{Message, ReportId};

/// A value by its `Display` form.
fn display<S: Serializer, T: fmt::Display>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(v)
}

/// Bytes as lowercase hex.
struct Hex<'a>(&'a [u8]);

impl fmt::Display for Hex<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.iter().try_for_each(|b| write!(f, "{b:02x}"))
    }
}

/// `report_id` and `report`, present inside a [`Message`] only.
#[derive(Clone, Copy)]
struct Tag {
    report_id: Option<u8>,
    report: Option<&'static str>,
}

impl Tag {
    const NONE: Tag = Tag {
        report_id: None,
        report: None,
    };

    fn of(id: ReportId) -> Tag {
        Tag {
            report_id: Some(id as u8),
            report: Some(id.name()),
        }
    }
}

#[derive(Serialize)]
struct PenJson<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    sw1: bool,
    sw2: bool,
    sw3: bool,
    in_range: bool,
    display_frame: bool,
    #[serde(serialize_with = "tenths")]
    x_mm: i16,
    #[serde(serialize_with = "tenths")]
    y_mm: i16,
    #[serde(serialize_with = "tenths")]
    z_mm: i16,
    seq: u16,
    timestamp_us: u32,
    quality: &'a Quality,
}

impl PenReport {
    fn json(&self, tag: Tag) -> PenJson<'_> {
        PenJson {
            report_id: tag.report_id,
            report: tag.report,
            sw1: self.sw1,
            sw2: self.sw2,
            sw3: self.sw3,
            in_range: self.in_range,
            display_frame: self.display_frame,
            x_mm: self.position.x,
            y_mm: self.position.y,
            z_mm: self.position.z,
            seq: self.seq,
            timestamp_us: self.timestamp_us,
            quality: &self.quality,
        }
    }
}

/// Switches, position (`x_mm`, `y_mm`, `z_mm`), `seq`, `timestamp_us` and `quality`.
impl Serialize for PenReport {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

/// The configured receivers' times of flight in µs (`null` without an arrival).
struct TofList<'a>(&'a [u32]);

impl Serialize for TofList<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.0.iter().map(|&t| (t != NO_ARRIVAL).then(|| f64::from(t) / 1000.0)))
    }
}

/// One bool per configured receiver: its range was used.
struct UsedList {
    count: u8,
    mask: u8,
}

impl Serialize for UsedList {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq((0..self.count).map(|i| self.mask & (1 << i) != 0))
    }
}

#[derive(Serialize)]
struct TofJson<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    seq: u16,
    timestamp_us: u32,
    tof_us: TofList<'a>,
    used: UsedList,
    #[serde(serialize_with = "wide")]
    speed_of_sound_m_s: f32,
}

impl TofReport {
    fn json(&self, tag: Tag) -> TofJson<'_> {
        let n = (self.receiver_count as usize).min(MAX_RECEIVERS);
        TofJson {
            report_id: tag.report_id,
            report: tag.report,
            seq: self.seq,
            timestamp_us: self.timestamp_us,
            tof_us: TofList(&self.tof_ns[..n]),
            used: UsedList {
                count: n as u8,
                mask: self.used_mask,
            },
            speed_of_sound_m_s: self.speed_of_sound_m_s,
        }
    }
}

/// `seq`, `timestamp_us`, `tof_us`, `used`, `speed_of_sound_m_s`.
impl Serialize for TofReport {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

#[derive(Serialize)]
struct InfoJson<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    #[serde(serialize_with = "display")]
    protocol: crate::Version,
    #[serde(serialize_with = "display")]
    firmware: crate::FirmwareVersion,
    receiver_count: u8,
    max_receivers: u8,
    fix_rate_hz: u16,
    #[serde(serialize_with = "display")]
    unique_id: Hex<'a>,
}

impl DeviceInfo {
    fn json(&self, tag: Tag) -> InfoJson<'_> {
        InfoJson {
            report_id: tag.report_id,
            report: tag.report,
            protocol: self.protocol,
            firmware: self.firmware,
            receiver_count: self.receiver_count,
            max_receivers: self.max_receivers,
            fix_rate_hz: self.fix_rate_hz,
            unique_id: Hex(&self.unique_id),
        }
    }
}

/// Versions as strings (`"1.0"`, `"0.1.0"`), the receivers, `fix_rate_hz`, `unique_id` in hex.
impl Serialize for DeviceInfo {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

#[derive(Serialize)]
struct ConfigJson<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    receiver_count: u8,
    #[serde(serialize_with = "wide_list")]
    receivers_mm: &'a [[f32; 3]],
    #[serde(serialize_with = "wide_list")]
    transducer_delay_us: &'a [f32],
    #[serde(serialize_with = "wide")]
    temperature_c: f32,
    #[serde(serialize_with = "wide_opt")]
    speed_of_sound_m_s: Option<f32>,
    report_rate_hz: u16,
    filter: &'a Filter,
    debounce_ms: u8,
    display: &'a Option<DisplayPose>,
    report_display_frame: bool,
    stream_tof: bool,
}

impl Config {
    fn json(&self, tag: Tag) -> ConfigJson<'_> {
        let n = (self.receiver_count as usize).min(MAX_RECEIVERS);
        ConfigJson {
            report_id: tag.report_id,
            report: tag.report,
            receiver_count: self.receiver_count,
            receivers_mm: &self.receivers_mm[..n],
            transducer_delay_us: &self.transducer_delay_us[..n],
            temperature_c: self.temperature_c,
            speed_of_sound_m_s: self.speed_of_sound_m_s,
            report_rate_hz: self.report_rate_hz,
            filter: &self.filter,
            debounce_ms: self.debounce_ms,
            display: &self.display,
            report_display_frame: self.report_display_frame,
            stream_tof: self.stream_tof,
        }
    }
}

/// The settings object: the fields of [`Config`], its receiver lists only as long as
/// `receiver_count`, `filter` tagged by `kind`, `display` `null` or
/// `{"rotation_wxyz", "translation_mm", "scale"}`.
impl Serialize for Config {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

/// A field by its name, e.g. `"receivers_mm[2]"`.
impl Serialize for ConfigField {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

#[derive(Serialize)]
struct StatusJson<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    request: u8,
    code: crate::StatusCode,
    field: Option<ConfigField>,
    #[serde(serialize_with = "display")]
    message: &'a Status,
}

impl Status {
    fn json(&self, tag: Tag) -> StatusJson<'_> {
        StatusJson {
            report_id: tag.report_id,
            report: tag.report,
            request: self.request,
            code: self.code,
            field: self.config_field(),
            message: self,
        }
    }
}

/// `request`, `code` (e.g. `"OutOfRange"`), `field` (a name or `null`) and `message`, one
/// readable sentence.
impl Serialize for Status {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

/// The OS pen report: its fields, positions in mm.
#[derive(Serialize)]
struct OsPenJson {
    report_id: u8,
    report: &'static str,
    tip: bool,
    barrel: bool,
    secondary_barrel: bool,
    in_range: bool,
    #[serde(serialize_with = "tenths")]
    x_mm: u16,
    #[serde(serialize_with = "tenths")]
    y_mm: u16,
}

/// The head report: its fields, positions in mm.
#[derive(Serialize)]
struct HeadJson<'a> {
    report_id: u8,
    report: &'static str,
    no_fix: bool,
    display_frame: bool,
    #[serde(serialize_with = "tenths")]
    x_mm: i16,
    #[serde(serialize_with = "tenths")]
    y_mm: i16,
    #[serde(serialize_with = "tenths")]
    z_mm: i16,
    prediction_ms: u8,
    seq: u16,
    timestamp_us: u32,
    quality: &'a Quality,
}

#[derive(Serialize)]
struct CommandJson {
    report_id: u8,
    report: &'static str,
    command: Command,
}

#[derive(Serialize)]
struct GetFeatureJson {
    #[serde(skip_serializing_if = "Option::is_none")]
    report_id: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    report: Option<&'static str>,
    feature_report_id: u8,
    feature_report: &'static str,
}

impl GetFeature {
    fn json(&self, tag: Tag) -> GetFeatureJson {
        GetFeatureJson {
            report_id: tag.report_id,
            report: tag.report,
            feature_report_id: self.report as u8,
            feature_report: self.report.name(),
        }
    }
}

/// `feature_report_id` and `feature_report` (its name).
impl Serialize for GetFeature {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json(Tag::NONE).serialize(s)
    }
}

/// The reset record: its fields, the text as a string, and the record in words.
#[derive(Serialize)]
struct ResetJson<'a> {
    report_id: u8,
    report: &'static str,
    kind: ResetKind,
    line: u32,
    column: u32,
    uptime_ms: u32,
    text: &'a str,
    #[serde(serialize_with = "display")]
    message: &'a ResetRecord,
}

/// The report's fields after `report_id` and `report`.
impl Serialize for Message {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let tag = Tag::of(self.id());
        match self {
            Message::Pen(r) => r.json(tag).serialize(s),
            Message::Tof(r) => r.json(tag).serialize(s),
            Message::DeviceInfo(r) => r.json(tag).serialize(s),
            Message::Config(r) => r.json(tag).serialize(s),
            Message::Status(r) => r.json(tag).serialize(s),
            Message::Command(c) => CommandJson {
                report_id: ReportId::Command as u8,
                report: ReportId::Command.name(),
                command: *c,
            }
            .serialize(s),
            Message::OsPen(r) => OsPenJson {
                report_id: ReportId::OsPen as u8,
                report: ReportId::OsPen.name(),
                tip: r.tip,
                barrel: r.barrel,
                secondary_barrel: r.secondary_barrel,
                in_range: r.in_range,
                x_mm: r.x,
                y_mm: r.y,
            }
            .serialize(s),
            Message::Head(r) => HeadJson {
                report_id: ReportId::Head as u8,
                report: ReportId::Head.name(),
                no_fix: r.no_fix,
                display_frame: r.display_frame,
                x_mm: r.position.x,
                y_mm: r.position.y,
                z_mm: r.position.z,
                prediction_ms: r.prediction_ms,
                seq: r.seq,
                timestamp_us: r.timestamp_us,
                quality: &r.quality,
            }
            .serialize(s),
            Message::ResetRecord(r) => ResetJson {
                report_id: ReportId::ResetRecord as u8,
                report: ReportId::ResetRecord.name(),
                kind: r.kind,
                line: r.line,
                column: r.column,
                uptime_ms: r.uptime_ms,
                text: r.text(),
                message: r,
            }
            .serialize(s),
            Message::GetFeature(r) => r.json(tag).serialize(s),
        }
    }
}

/// Up to [`MAX_RECEIVERS`] values, one per receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerReceiver<T> {
    values: [T; MAX_RECEIVERS],
    len: usize,
}

impl<T: Copy> PerReceiver<T> {
    /// The values given.
    pub fn as_slice(&self) -> &[T] {
        &self.values[..self.len]
    }

    /// Slots from the first `len` given, the rest `unused`.
    fn fill(&self, unused: T) -> [T; MAX_RECEIVERS] {
        let mut out = [unused; MAX_RECEIVERS];
        out[..self.len].copy_from_slice(self.as_slice());
        out
    }
}

impl<'de, T: Deserialize<'de> + Copy + Default> Deserialize<'de> for PerReceiver<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct List<T>(core::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy + Default> Visitor<'de> for List<T> {
            type Value = PerReceiver<T>;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "a list of at most {MAX_RECEIVERS} values, one per receiver")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = PerReceiver {
                    values: [T::default(); MAX_RECEIVERS],
                    len: 0,
                };
                while let Some(v) = seq.next_element()? {
                    if out.len == MAX_RECEIVERS {
                        return Err(de::Error::invalid_length(out.len + 1, &self));
                    }
                    out.values[out.len] = v;
                    out.len += 1;
                }
                Ok(out)
            }
        }
        d.deserialize_seq(List(core::marker::PhantomData))
    }
}

/// `Some` of a value that is present, `null` included: with `#[serde(default)]`, an absent key
/// stays `None` and `null` becomes `Some(None)`.
fn present<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// Changes to a configuration, read from the settings object [`Config`] serializes to: keys that
/// are absent keep their values ([`ConfigChanges::apply`]), unknown keys are refused. The values
/// are checked for their form only; [`Config::validate`] checks them.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct ConfigChanges {
    pub receiver_count: Option<u8>,
    /// Given: these receivers, the other slots zero.
    pub receivers_mm: Option<PerReceiver<[f32; 3]>>,
    /// Given: these delays, the other slots zero.
    pub transducer_delay_us: Option<PerReceiver<f32>>,
    pub temperature_c: Option<f32>,
    /// `Some(None)`: derive the speed of sound from the temperature.
    #[serde(default, deserialize_with = "present")]
    pub speed_of_sound_m_s: Option<Option<f32>>,
    pub report_rate_hz: Option<u16>,
    pub filter: Option<Filter>,
    pub debounce_ms: Option<u8>,
    /// `Some(None)`: no display pose.
    #[serde(default, deserialize_with = "present")]
    pub display: Option<Option<DisplayPose>>,
    pub report_display_frame: Option<bool>,
    pub stream_tof: Option<bool>,
}

impl ConfigChanges {
    /// `base` with these changes.
    pub fn apply(&self, base: &Config) -> Config {
        let mut c = *base;
        if let Some(v) = self.receiver_count {
            c.receiver_count = v;
        }
        if let Some(v) = &self.receivers_mm {
            c.receivers_mm = v.fill([0.0; 3]);
        }
        if let Some(v) = &self.transducer_delay_us {
            c.transducer_delay_us = v.fill(0.0);
        }
        if let Some(v) = self.temperature_c {
            c.temperature_c = v;
        }
        if let Some(v) = self.speed_of_sound_m_s {
            c.speed_of_sound_m_s = v;
        }
        if let Some(v) = self.report_rate_hz {
            c.report_rate_hz = v;
        }
        if let Some(v) = self.filter {
            c.filter = v;
        }
        if let Some(v) = self.debounce_ms {
            c.debounce_ms = v;
        }
        if let Some(v) = self.display {
            c.display = v;
        }
        if let Some(v) = self.report_display_frame {
            c.report_display_frame = v;
        }
        if let Some(v) = self.stream_tof {
            c.stream_tof = v;
        }
        c
    }
}
