//! Requests and their answers: the status feature report (ID 0x05, read-only), the command
//! feature report (ID 0x06, write-only) and the serial link's get-feature request (ID 0x80).

use core::fmt;

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::config::{ConfigError, ConfigField, Problem};
use crate::error::DecodeError;

/// The outcome of the last request (a set-feature or a command). JSON (feature `serde`): the
/// variant's name, e.g. `"OutOfRange"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum StatusCode {
    /// Applied.
    Ok = 0,
    /// The request names a report ID the device does not define.
    UnknownReport = 1,
    /// The request's bytes do not decode (wrong length, reserved bits, a non-finite number).
    Malformed = 2,
    /// A value is outside its range; the status names the field.
    OutOfRange = 3,
    /// A value is geometrically unusable; the status names the field.
    Degenerate = 4,
    /// A value needs another that is not set; the status names the field.
    Missing = 5,
    /// The report cannot be written (device information, status).
    ReadOnly = 6,
    /// The configuration could not be saved to flash; the running one is unchanged.
    StorageFailed = 7,
    /// The firmware does not implement this request.
    Unsupported = 8,
}

impl StatusCode {
    fn from_u8(v: u8) -> Option<StatusCode> {
        use StatusCode::*;
        [
            Ok,
            UnknownReport,
            Malformed,
            OutOfRange,
            Degenerate,
            Missing,
            ReadOnly,
            StorageFailed,
            Unsupported,
        ]
        .into_iter()
        .find(|c| *c as u8 == v)
    }
}

/// The answer to a request: which request, its outcome, and the field at fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub struct Status {
    /// The report ID of the request answered (0 before any request).
    pub request: u8,
    pub code: StatusCode,
    /// The configuration field at fault (a [`ConfigField`] code), or 0.
    pub field: u8,
}

impl Status {
    /// Success for request `request`.
    pub fn ok(request: u8) -> Status {
        Status {
            request,
            code: StatusCode::Ok,
            field: 0,
        }
    }

    /// A failure without a field.
    pub fn failed(request: u8, code: StatusCode) -> Status {
        Status {
            request,
            code,
            field: 0,
        }
    }

    /// The status of a configuration that failed [`Config::validate`](crate::Config::validate).
    pub fn from_config_error(request: u8, err: ConfigError) -> Status {
        let code = match err.problem {
            Problem::OutOfRange => StatusCode::OutOfRange,
            Problem::Degenerate => StatusCode::Degenerate,
            Problem::Missing => StatusCode::Missing,
        };
        Status {
            request,
            code,
            field: err.field.code(),
        }
    }

    /// The field at fault, when the status names one.
    pub fn config_field(&self) -> Option<ConfigField> {
        ConfigField::from_code(self.field)
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match ReportId::from_u8(self.request) {
            Some(id) => id.name(),
            None => "request",
        };
        let outcome = match self.code {
            StatusCode::Ok => "applied",
            StatusCode::UnknownReport => "rejected: unknown report",
            StatusCode::Malformed => "rejected: malformed",
            StatusCode::OutOfRange => "rejected: out of range",
            StatusCode::Degenerate => "rejected: degenerate",
            StatusCode::Missing => "rejected: needs a field that is not set",
            StatusCode::ReadOnly => "rejected: read-only",
            StatusCode::StorageFailed => "failed: flash storage",
            StatusCode::Unsupported => "rejected: not supported by this firmware",
        };
        write!(f, "{what} (0x{:02x}) {outcome}", self.request)?;
        match self.config_field() {
            Some(field) => write!(f, " ({field})"),
            None => Ok(()),
        }
    }
}

impl Report for Status {
    const ID: ReportId = ReportId::Status;
    const LEN: usize = 4;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(self.request);
        w.u8(self.code as u8);
        w.u8(self.field);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let request = r.u8()?;
        let code = StatusCode::from_u8(r.u8()?).ok_or(DecodeError::OutOfRange {
            report: ReportId::Status,
            field: "code",
        })?;
        let field = r.u8()?;
        if field != 0 && ConfigField::from_code(field).is_none() {
            return Err(DecodeError::OutOfRange {
                report: ReportId::Status,
                field: "field",
            });
        }
        Ok(Status { request, code, field })
    }
}

/// An action the device performs when this report is written. JSON (feature `serde`): the
/// variant's name, e.g. `"SaveConfig"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Command {
    /// Save the running configuration to flash, so it survives a power cycle.
    SaveConfig = 1,
    /// Replace the running configuration with the firmware's defaults (not saved).
    LoadDefaults = 2,
    /// Restart into the microcontroller's ROM USB DFU bootloader, for `dfu-util`.
    EnterBootloader = 3,
    /// Protocol 2.1: start tracking the head — fire the glasses' emitter in its own slots
    /// between the pen's and send head reports (not saved). A base station without the
    /// glasses' emitter answers *not supported*.
    HeadOn = 4,
    /// Protocol 2.1: stop tracking the head; the pen has every cycle again.
    HeadOff = 5,
}

impl Report for Command {
    const ID: ReportId = ReportId::Command;
    const LEN: usize = 2;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(*self as u8);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        match r.u8()? {
            1 => Ok(Command::SaveConfig),
            2 => Ok(Command::LoadDefaults),
            3 => Ok(Command::EnterBootloader),
            4 => Ok(Command::HeadOn),
            5 => Ok(Command::HeadOff),
            _ => Err(DecodeError::OutOfRange {
                report: ReportId::Command,
                field: "command",
            }),
        }
    }
}

/// Serial only: asks the device to send the feature report `report` (what a USB host does with a
/// HID GET_REPORT request).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GetFeature {
    /// The feature report wanted.
    pub report: ReportId,
}

impl Report for GetFeature {
    const ID: ReportId = ReportId::GetFeature;
    const LEN: usize = 2;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(self.report as u8);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let id = r.u8()?;
        match ReportId::from_u8(id) {
            Some(report @ (ReportId::DeviceInfo | ReportId::Config | ReportId::Status | ReportId::ResetRecord)) => {
                Ok(GetFeature { report })
            }
            _ => Err(DecodeError::OutOfRange {
                report: ReportId::GetFeature,
                field: "report (not a readable feature report)",
            }),
        }
    }
}
