#![doc = include_str!("../../docs/protocol.md")]
#![no_std]
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

mod codec;
mod config;
mod descriptor;
mod error;
mod frame;
mod head;
// The fuzz targets' properties, shared with the stable test that replays their corpora.
#[doc(hidden)]
pub mod fuzzing;
mod info;
#[cfg(feature = "serde")]
mod json;
mod os_pen;
mod pen;
mod reset;
mod status;
mod tof;
#[cfg(feature = "serde")]
mod wide;

use core::fmt;

pub use codec::{Reader, Report, Writer};
pub use config::{Config, ConfigError, ConfigField, DisplayPose, Filter, Problem, limits};
pub use descriptor::{Descriptor, REPORT_DESCRIPTOR, REPORT_DESCRIPTOR_LEN, os_extent, report_descriptor, usage};
pub use error::{DecodeError, EncodeError};
pub use frame::{CRC, CRC_LEN, FrameDecoder, FrameError, MAX_FRAME, MAX_PAYLOAD, encode_frame, encode_report_frame};
pub use head::{HeadReport, MAX_PREDICTION_MS};
pub use info::SUPPORTED_MAJOR_VERSIONS;
pub use info::{DeviceInfo, FirmwareVersion, PROTOCOL_VERSION, UnsupportedVersion, Version, check_version};
#[cfg(feature = "serde")]
pub use json::{ConfigChanges, PerReceiver};
pub use os_pen::OsPenReport;
pub use pen::{MAX_RECEIVERS, POSITION_LOGICAL_MAX, PenReport, Position, Quality, UNITS_PER_MM};
pub use reset::{CFSR_STACKING, RESET_TEXT_LEN, ResetKind, ResetRecord};
pub use status::{Command, GetFeature, Status, StatusCode};
pub use tof::{NO_ARRIVAL, TofReport};

/// USB vendor ID of the pen's base station: pid.codes, the open-source hardware vendor ID.
pub const USB_VID: u16 = 0x1209;
/// USB product ID of the pen's base station, in pid.codes' range for testing (0x0001–0x0010);
/// a production build registers its own.
pub const USB_PID: u16 = 0x0007;

/// Every report and message the protocol defines, by its first byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum ReportId {
    /// Input: [`PenReport`].
    Pen = 0x01,
    /// Input: [`TofReport`].
    Tof = 0x02,
    /// Feature, read-only: [`DeviceInfo`].
    DeviceInfo = 0x03,
    /// Feature, read and write: [`Config`].
    Config = 0x04,
    /// Feature, read-only: [`Status`] of the last request.
    Status = 0x05,
    /// Feature, write-only: [`Command`].
    Command = 0x06,
    /// Input, USB HID only: [`OsPenReport`], the operating system's pen.
    OsPen = 0x07,
    /// Input (protocol 2.1): [`HeadReport`], the tracked head.
    Head = 0x08,
    /// Feature, read-only (protocol 2.2): [`ResetRecord`], the last panic or fault.
    ResetRecord = 0x09,
    /// Serial only, host to device: [`GetFeature`].
    GetFeature = 0x80,
}

impl ReportId {
    /// All IDs, in order.
    pub const ALL: [ReportId; 10] = [
        ReportId::Pen,
        ReportId::Tof,
        ReportId::DeviceInfo,
        ReportId::Config,
        ReportId::Status,
        ReportId::Command,
        ReportId::OsPen,
        ReportId::Head,
        ReportId::ResetRecord,
        ReportId::GetFeature,
    ];

    /// The ID whose byte is `v`.
    pub fn from_u8(v: u8) -> Option<ReportId> {
        ReportId::ALL.into_iter().find(|id| *id as u8 == v)
    }

    /// Whether this is a feature report (read or written with HID GET/SET_REPORT).
    pub fn is_feature(self) -> bool {
        matches!(
            self,
            ReportId::DeviceInfo | ReportId::Config | ReportId::Status | ReportId::Command | ReportId::ResetRecord
        )
    }

    /// The report's name, as the documentation uses it.
    pub fn name(self) -> &'static str {
        match self {
            ReportId::Pen => "pen",
            ReportId::Tof => "time-of-flight",
            ReportId::DeviceInfo => "device information",
            ReportId::Config => "configuration",
            ReportId::Status => "status",
            ReportId::Command => "command",
            ReportId::OsPen => "OS pen",
            ReportId::Head => "head",
            ReportId::ResetRecord => "reset record",
            ReportId::GetFeature => "get-feature request",
        }
    }
}

impl fmt::Display for ReportId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Any report or message, decoded by its report ID.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub enum Message {
    Pen(PenReport),
    Tof(TofReport),
    DeviceInfo(DeviceInfo),
    Config(Config),
    Status(Status),
    Command(Command),
    OsPen(OsPenReport),
    Head(HeadReport),
    ResetRecord(ResetRecord),
    GetFeature(GetFeature),
}

impl Message {
    /// Decodes whichever report `bytes` holds.
    pub fn decode(bytes: &[u8]) -> Result<Message, DecodeError> {
        let &first = bytes.first().ok_or(DecodeError::Empty)?;
        let id = ReportId::from_u8(first).ok_or(DecodeError::UnknownReportId(first))?;
        Ok(match id {
            ReportId::Pen => Message::Pen(PenReport::decode(bytes)?),
            ReportId::Tof => Message::Tof(TofReport::decode(bytes)?),
            ReportId::DeviceInfo => Message::DeviceInfo(DeviceInfo::decode(bytes)?),
            ReportId::Config => Message::Config(Config::decode(bytes)?),
            ReportId::Status => Message::Status(Status::decode(bytes)?),
            ReportId::Command => Message::Command(Command::decode(bytes)?),
            ReportId::OsPen => Message::OsPen(OsPenReport::decode(bytes)?),
            ReportId::Head => Message::Head(HeadReport::decode(bytes)?),
            ReportId::ResetRecord => Message::ResetRecord(ResetRecord::decode(bytes)?),
            ReportId::GetFeature => Message::GetFeature(GetFeature::decode(bytes)?),
        })
    }

    /// Encodes the message into `out`; returns the number of bytes written.
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        match self {
            Message::Pen(r) => r.encode(out),
            Message::Tof(r) => r.encode(out),
            Message::DeviceInfo(r) => r.encode(out),
            Message::Config(r) => r.encode(out),
            Message::Status(r) => r.encode(out),
            Message::Command(r) => r.encode(out),
            Message::OsPen(r) => r.encode(out),
            Message::Head(r) => r.encode(out),
            Message::ResetRecord(r) => r.encode(out),
            Message::GetFeature(r) => r.encode(out),
        }
    }

    /// The message's report ID.
    pub fn id(&self) -> ReportId {
        match self {
            Message::Pen(_) => ReportId::Pen,
            Message::Tof(_) => ReportId::Tof,
            Message::DeviceInfo(_) => ReportId::DeviceInfo,
            Message::Config(_) => ReportId::Config,
            Message::Status(_) => ReportId::Status,
            Message::Command(_) => ReportId::Command,
            Message::OsPen(_) => ReportId::OsPen,
            Message::Head(_) => ReportId::Head,
            Message::ResetRecord(_) => ReportId::ResetRecord,
            Message::GetFeature(_) => ReportId::GetFeature,
        }
    }
}
