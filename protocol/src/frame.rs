//! Serial framing: `0x00 ‖ COBS(payload ‖ CRC-32(payload) little-endian) ‖ 0x00`.
//!
//! The payload is a report exactly as on USB HID (report ID first). COBS removes every zero byte
//! from the encoded frame, so 0x00 only ever delimits; sending it before *and* after a frame
//! means garbage on the line can spoil only itself, never the next intact frame. The CRC catches
//! what COBS cannot: a frame whose bytes were altered in transit.
//!
//! Decoding is push-bytes, pull-frames: [`FrameDecoder::push`] takes one byte at a time and
//! returns a frame, an error, or nothing (need more bytes).

use core::fmt;

use crate::codec::Report;
use crate::error::EncodeError;

/// The largest payload a frame carries. Version 2's largest report has 195 bytes; the margin
/// leaves room for minor versions.
pub const MAX_PAYLOAD: usize = 256;
/// Bytes of the CRC that follows the payload.
pub const CRC_LEN: usize = 4;
/// The largest encoded frame, both delimiters included.
pub const MAX_FRAME: usize = 2 + cobs::max_encoding_length(MAX_PAYLOAD + CRC_LEN);

/// CRC-32/ISO-HDLC (reflected, polynomial 0x04C11DB7, init and xorout 0xFFFFFFFF): the CRC of
/// zlib and Ethernet, so `zlib.crc32(payload)` checks a frame.
pub const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// Frames `payload` into `out`; returns the number of bytes written.
pub fn encode_frame(payload: &[u8], out: &mut [u8]) -> Result<usize, EncodeError> {
    if payload.len() > MAX_PAYLOAD {
        return Err(EncodeError::BufferTooSmall {
            needed: payload.len(),
            available: MAX_PAYLOAD,
        });
    }
    let needed = 2 + cobs::max_encoding_length(payload.len() + CRC_LEN);
    let too_small = EncodeError::BufferTooSmall {
        needed,
        available: out.len(),
    };
    let (first, rest) = out.split_first_mut().ok_or(too_small)?;
    *first = 0;
    let mut enc = cobs::CobsEncoder::new(rest);
    enc.push(payload).map_err(|_| too_small)?;
    enc.push(&CRC.checksum(payload).to_le_bytes()).map_err(|_| too_small)?;
    let n = enc.finalize();
    *rest.get_mut(n).ok_or(too_small)? = 0;
    Ok(n + 2)
}

/// Encodes `report` and frames it into `out`; returns the number of bytes written.
pub fn encode_report_frame<R: Report>(report: &R, out: &mut [u8]) -> Result<usize, EncodeError> {
    let mut payload = [0u8; MAX_PAYLOAD];
    let n = report.encode(&mut payload)?;
    encode_frame(&payload[..n], out)
}

/// Why bytes between two delimiters are not a frame. Each is one dropped frame for the counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// More bytes than the largest frame arrived without a delimiter; they were discarded up to
    /// the next delimiter.
    Overflow,
    /// The bytes are not valid COBS.
    Cobs,
    /// Too short to hold a report ID and a CRC.
    TooShort {
        /// Decoded bytes.
        len: usize,
    },
    /// The CRC does not match: the frame was altered in transit.
    Crc {
        /// CRC computed over the payload.
        computed: u32,
        /// CRC carried by the frame.
        carried: u32,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FrameError::Overflow => write!(f, "frame longer than {MAX_FRAME} bytes, discarded"),
            FrameError::Cobs => write!(f, "frame is not valid COBS"),
            FrameError::TooShort { len } => write!(f, "frame of {len} bytes is too short for a report and its CRC"),
            FrameError::Crc { computed, carried } => {
                write!(
                    f,
                    "frame CRC mismatch: computed 0x{computed:08x}, carried 0x{carried:08x}"
                )
            }
        }
    }
}

impl core::error::Error for FrameError {}

/// Reassembles frames from a byte stream, resynchronising at every 0x00.
pub struct FrameDecoder {
    buf: [u8; MAX_FRAME],
    len: usize,
    overflowed: bool,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    /// A decoder waiting for the start of a frame.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; MAX_FRAME],
            len: 0,
            overflowed: false,
        }
    }

    /// Takes one byte. At a delimiter that ends a non-empty frame, returns its payload (report ID
    /// first, CRC removed) or why it was dropped; otherwise `None`.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                Some(slot) => {
                    *slot = byte;
                    self.len += 1;
                }
                None => self.overflowed = true,
            }
            return None;
        }
        let len = core::mem::take(&mut self.len);
        if core::mem::take(&mut self.overflowed) {
            return Some(Err(FrameError::Overflow));
        }
        if len == 0 {
            // Back-to-back delimiters: the idle line between frames.
            return None;
        }
        let frame = &mut self.buf[..len];
        let decoded = match cobs::decode_in_place_report(frame) {
            Ok(report) if report.parsed_size() == len => report.frame_size(),
            _ => return Some(Err(FrameError::Cobs)),
        };
        if decoded <= CRC_LEN {
            return Some(Err(FrameError::TooShort { len: decoded }));
        }
        let (payload, crc) = frame[..decoded].split_at(decoded - CRC_LEN);
        let carried = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
        let computed = CRC.checksum(payload);
        if computed != carried {
            return Some(Err(FrameError::Crc { computed, carried }));
        }
        Some(Ok(payload))
    }
}
