//! The device information feature report (ID 0x03, read-only) and protocol versions.

use core::fmt;

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;
use crate::pen::MAX_RECEIVERS;

/// A protocol version. Minor versions only add (report IDs, commands, flag bits, enum values);
/// a major version changes an existing layout. See the crate documentation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Version {
    /// Incremented when an existing report's length or meaning changes.
    pub major: u8,
    /// Incremented when something is added that older hosts may ignore.
    pub minor: u8,
}

impl fmt::Display for Version {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.major, self.minor)
    }
}

/// The protocol version this crate implements. 2: the configuration report carries the display's
/// size (195 bytes, was 187) and the operating system's pen has its own report (0x07) in the
/// display frame; version 1's configuration would be misread, so a version 1 host refuses it.
/// 2.1 added the head report (0x08) and the HeadOn/HeadOff commands; 2.2 the reset record
/// (0x09), which a 2.1 device does not answer.
pub const PROTOCOL_VERSION: Version = Version { major: 2, minor: 2 };

/// The protocol major versions a host built from this crate understands.
pub const SUPPORTED_MAJOR_VERSIONS: &[u8] = &[2];

/// Why a host cannot talk to a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UnsupportedVersion {
    /// The device's protocol version.
    pub device: Version,
}

impl fmt::Display for UnsupportedVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the device speaks protocol {}, this host understands {}.x; update the host software or the firmware",
            self.device, PROTOCOL_VERSION.major
        )
    }
}

impl core::error::Error for UnsupportedVersion {}

/// Checks that a host built from this crate can talk to a device of protocol `device`.
/// A newer minor version is accepted: what it adds, an older host ignores.
pub fn check_version(device: Version) -> Result<(), UnsupportedVersion> {
    if SUPPORTED_MAJOR_VERSIONS.contains(&device.major) {
        Ok(())
    } else {
        Err(UnsupportedVersion { device })
    }
}

/// A firmware version (semantic versioning).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub struct FirmwareVersion {
    pub major: u8,
    pub minor: u8,
    pub patch: u8,
}

impl fmt::Display for FirmwareVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}.{}", self.major, self.minor, self.patch)
    }
}

/// What the device is: protocol and firmware versions, receivers, and its unique ID.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeviceInfo {
    /// The protocol version the firmware speaks.
    pub protocol: Version,
    /// The firmware version.
    pub firmware: FirmwareVersion,
    /// Receivers in the current configuration.
    pub receiver_count: u8,
    /// Receivers the hardware can capture.
    pub max_receivers: u8,
    /// Measurement cycles per second the firmware runs.
    pub fix_rate_hz: u16,
    /// The microcontroller's 96-bit unique ID, to tell several base stations apart.
    pub unique_id: [u8; 12],
}

impl Report for DeviceInfo {
    const ID: ReportId = ReportId::DeviceInfo;
    const LEN: usize = 22;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(self.protocol.major);
        w.u8(self.protocol.minor);
        w.u8(self.firmware.major);
        w.u8(self.firmware.minor);
        w.u8(self.firmware.patch);
        w.u8(self.receiver_count);
        w.u8(self.max_receivers);
        w.u16(self.fix_rate_hz);
        w.bytes(&self.unique_id);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let protocol = Version {
            major: r.u8()?,
            minor: r.u8()?,
        };
        let firmware = FirmwareVersion {
            major: r.u8()?,
            minor: r.u8()?,
            patch: r.u8()?,
        };
        let receiver_count = r.u8()?;
        let max_receivers = r.u8()?;
        if max_receivers as usize > MAX_RECEIVERS {
            return Err(DecodeError::OutOfRange {
                report: ReportId::DeviceInfo,
                field: "max_receivers",
            });
        }
        if receiver_count > max_receivers {
            return Err(DecodeError::OutOfRange {
                report: ReportId::DeviceInfo,
                field: "receiver_count",
            });
        }
        Ok(DeviceInfo {
            protocol,
            firmware,
            receiver_count,
            max_receivers,
            fix_rate_hz: r.u16()?,
            unique_id: r.bytes()?,
        })
    }
}
