//! Length-checked little-endian reading and writing of report bodies.
//!
//! Every report has a fixed length, checked once before its fields are read, so the reader's own
//! bounds checks can only fail on a layout bug, which the golden-byte tests would catch. They still
//! return an error rather than panic: decoding foreign bytes must never panic.

use crate::ReportId;
use crate::error::{DecodeError, EncodeError};

/// The common shape of every report and message: a report ID, a fixed length, and a codec.
pub trait Report: Sized {
    /// The report ID, the first byte of the encoded report.
    const ID: ReportId;
    /// The encoded length in bytes, report ID included.
    const LEN: usize;

    /// Writes the report body (everything after the report ID).
    fn write_body(&self, w: &mut Writer<'_>);

    /// Reads the report body (everything after the report ID); the length is already checked.
    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError>;

    /// Encodes the report, report ID first, into `out`; returns the number of bytes written.
    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let available = out.len();
        let out = out.get_mut(..Self::LEN).ok_or(EncodeError::BufferTooSmall {
            needed: Self::LEN,
            available,
        })?;
        let mut w = Writer::new(out);
        w.u8(Self::ID as u8);
        self.write_body(&mut w);
        debug_assert_eq!(w.pos, Self::LEN, "layout of report {:?}", Self::ID);
        Ok(Self::LEN)
    }

    /// Decodes a report from exactly [`Self::LEN`] bytes, report ID first.
    fn decode(bytes: &[u8]) -> Result<Self, DecodeError> {
        let Some(&id) = bytes.first() else {
            return Err(DecodeError::Empty);
        };
        if id != Self::ID as u8 {
            return Err(DecodeError::WrongReportId {
                expected: Self::ID,
                found: id,
            });
        }
        if bytes.len() != Self::LEN {
            return Err(DecodeError::Length {
                report: Self::ID,
                expected: Self::LEN,
                found: bytes.len(),
            });
        }
        let mut r = Reader {
            buf: bytes,
            pos: 1,
            report: Self::ID,
        };
        Self::read_body(&mut r)
    }
}

/// Writes little-endian fields into a buffer whose length the caller has checked.
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> Writer<'a> {
    fn new(buf: &'a mut [u8]) -> Self {
        Writer { buf, pos: 0 }
    }

    /// Writes raw bytes.
    pub fn bytes(&mut self, bytes: &[u8]) {
        // `Report::encode` sized the buffer to `LEN`; a write past it is a layout bug and the
        // debug assertion there names the report. Release builds drop the excess bytes.
        if let Some(dst) = self.buf.get_mut(self.pos..self.pos + bytes.len()) {
            dst.copy_from_slice(bytes);
        }
        self.pos += bytes.len();
    }

    /// Writes one byte.
    pub fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }

    /// Writes a little-endian `u16`.
    pub fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }

    /// Writes a little-endian `i16`.
    pub fn i16(&mut self, v: i16) {
        self.bytes(&v.to_le_bytes());
    }

    /// Writes a little-endian `u32`.
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    /// Writes a little-endian IEEE-754 `f32`.
    pub fn f32(&mut self, v: f32) {
        self.bytes(&v.to_le_bytes());
    }
}

/// Reads little-endian fields from a report of checked length.
pub struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    report: ReportId,
}

impl Reader<'_> {
    /// The report being read, for error messages.
    pub fn report(&self) -> ReportId {
        self.report
    }

    /// Byte offset of the next field within the report (report ID at offset 0).
    pub fn offset(&self) -> usize {
        self.pos
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], DecodeError> {
        let mut out = [0u8; N];
        let src = self.buf.get(self.pos..self.pos + N).ok_or(DecodeError::Length {
            report: self.report,
            expected: self.pos + N,
            found: self.buf.len(),
        })?;
        out.copy_from_slice(src);
        self.pos += N;
        Ok(out)
    }

    /// Reads one byte.
    pub fn u8(&mut self) -> Result<u8, DecodeError> {
        Ok(self.array::<1>()?[0])
    }

    /// Reads a little-endian `u16`.
    pub fn u16(&mut self) -> Result<u16, DecodeError> {
        Ok(u16::from_le_bytes(self.array()?))
    }

    /// Reads a little-endian `i16`.
    pub fn i16(&mut self) -> Result<i16, DecodeError> {
        Ok(i16::from_le_bytes(self.array()?))
    }

    /// Reads a little-endian `u32`.
    pub fn u32(&mut self) -> Result<u32, DecodeError> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    /// Reads a little-endian `f32`, which must be finite.
    pub fn f32(&mut self, field: &'static str) -> Result<f32, DecodeError> {
        let v = f32::from_le_bytes(self.array()?);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(DecodeError::NotFinite {
                report: self.report,
                field,
            })
        }
    }

    /// Reads `N` raw bytes.
    pub fn bytes<const N: usize>(&mut self) -> Result<[u8; N], DecodeError> {
        self.array()
    }

    /// Reads a byte of which only the bits in `allowed` may be set.
    pub fn flags(&mut self, allowed: u8) -> Result<u8, DecodeError> {
        let offset = self.pos;
        let v = self.u8()?;
        if v & !allowed != 0 {
            return Err(DecodeError::ReservedBits {
                report: self.report,
                offset,
                value: v & !allowed,
            });
        }
        Ok(v)
    }

    /// Reads an `f32` that must be exactly zero (all bits clear): an unused slot in canonical form.
    pub fn zero_f32(&mut self, field: &'static str) -> Result<(), DecodeError> {
        let offset = self.pos;
        if u32::from_le_bytes(self.array()?) != 0 {
            return Err(DecodeError::UnusedNotZero {
                report: self.report,
                offset,
                field,
            });
        }
        Ok(())
    }

    /// Reads a byte that must be zero.
    pub fn zero_u8(&mut self, field: &'static str) -> Result<(), DecodeError> {
        let offset = self.pos;
        if self.u8()? != 0 {
            return Err(DecodeError::UnusedNotZero {
                report: self.report,
                offset,
                field,
            });
        }
        Ok(())
    }
}
