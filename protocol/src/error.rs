//! Errors of the codecs and the framing. Each variant says exactly what was wrong and where, so a
//! host can print it and a firmware can turn it into a status code.

use core::fmt;

use crate::ReportId;

/// Why bytes are not a valid report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(missing_docs)]
pub enum DecodeError {
    /// No bytes at all.
    Empty,
    /// The first byte is not a report ID this protocol version defines.
    UnknownReportId(u8),
    /// The first byte is a different report's ID than the one being decoded.
    WrongReportId {
        /// The report the caller asked for.
        expected: ReportId,
        /// The ID byte found.
        found: u8,
    },
    /// Truncated or oversized: every report has one fixed length.
    Length {
        /// The report whose length is wrong.
        report: ReportId,
        /// Its length, report ID included.
        expected: usize,
        /// The length received.
        found: usize,
    },
    /// Bits that this version reserves (padding, unused flags) are set.
    ReservedBits {
        report: ReportId,
        /// Byte offset within the report (report ID at 0).
        offset: usize,
        /// The offending bits.
        value: u8,
    },
    /// A slot that must be zero in this configuration (an unused receiver, a disabled option) is not.
    UnusedNotZero {
        report: ReportId,
        /// Byte offset within the report (report ID at 0).
        offset: usize,
        field: &'static str,
    },
    /// A field holds a value outside its defined range (e.g. a position of -32768, the reserved
    /// logical value, or more receivers than exist).
    OutOfRange { report: ReportId, field: &'static str },
    /// A floating-point field is NaN or infinite.
    NotFinite { report: ReportId, field: &'static str },
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            DecodeError::Empty => write!(f, "empty report: no bytes"),
            DecodeError::UnknownReportId(id) => write!(f, "unknown report ID 0x{id:02x}"),
            DecodeError::WrongReportId { expected, found } => {
                write!(
                    f,
                    "report ID 0x{found:02x} where the {expected} report (0x{:02x}) was expected",
                    expected as u8
                )
            }
            DecodeError::Length {
                report,
                expected,
                found,
            } => {
                let what = if found < expected { "truncated" } else { "oversized" };
                write!(f, "{what} {report} report: {found} bytes, expected {expected}")
            }
            DecodeError::ReservedBits { report, offset, value } => {
                write!(f, "{report} report: reserved bits 0x{value:02x} set in byte {offset}")
            }
            DecodeError::UnusedNotZero { report, offset, field } => {
                write!(f, "{report} report: unused field {field} at byte {offset} is not zero")
            }
            DecodeError::OutOfRange { report, field } => write!(f, "{report} report: {field} is out of range"),
            DecodeError::NotFinite { report, field } => write!(f, "{report} report: {field} is not a finite number"),
        }
    }
}

impl core::error::Error for DecodeError {}

/// Why a report could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is smaller than the encoding.
    BufferTooSmall {
        /// Bytes the encoding needs.
        needed: usize,
        /// Bytes the buffer has.
        available: usize,
    },
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            EncodeError::BufferTooSmall { needed, available } => {
                write!(
                    f,
                    "output buffer too small: {needed} bytes needed, {available} available"
                )
            }
        }
    }
}

impl core::error::Error for EncodeError {}
