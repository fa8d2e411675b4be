//! The reset record's life across a reset: what a panic or a fault leaves in RAM the start-up
//! code does not clear (the board's `.uninit`), and how the next boot takes it back.
//!
//! The RAM holds anything after a power-up, so the record carries a magic word and a CRC-32 of
//! its bytes: a power-up's noise, or a record half written when the fault came, is not taken for
//! one. [`RamRecord::take`] clears it, so the record is reported by the boot after the panic and
//! not again after a later, ordinary reset.

use core::fmt;

use pen_protocol::{CRC, RESET_TEXT_LEN, Report, ResetRecord};

/// Marks a sealed record.
const MAGIC: u32 = 0x5245_5354;

/// A [`ResetRecord`] as it waits in RAM for the next boot: magic, the report's bytes, CRC-32.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct RamRecord {
    magic: u32,
    bytes: [u8; ResetRecord::LEN],
    crc: u32,
}

impl RamRecord {
    /// An empty slot (what [`take`](Self::take) leaves).
    pub const EMPTY: RamRecord = RamRecord {
        magic: 0,
        bytes: [0; ResetRecord::LEN],
        crc: 0,
    };

    /// `record`, sealed for the next boot.
    pub fn seal(record: &ResetRecord) -> RamRecord {
        let mut bytes = [0; ResetRecord::LEN];
        // The buffer is exactly the report's length: encoding cannot fail.
        let _ = record.encode(&mut bytes);
        RamRecord {
            magic: MAGIC,
            crc: CRC.checksum(&bytes),
            bytes,
        }
    }

    /// A slot from its parts: magic word, the report's bytes, CRC-32 — whatever the RAM holds.
    pub const fn from_parts(magic: u32, bytes: [u8; ResetRecord::LEN], crc: u32) -> RamRecord {
        RamRecord { magic, bytes, crc }
    }

    /// The slot's parts, as [`from_parts`](Self::from_parts) takes them.
    pub const fn parts(&self) -> (u32, [u8; ResetRecord::LEN], u32) {
        (self.magic, self.bytes, self.crc)
    }

    /// The record a previous run sealed, if there is an intact one; the slot is emptied.
    pub fn take(&mut self) -> Option<ResetRecord> {
        let sealed = self.magic == MAGIC && self.crc == CRC.checksum(&self.bytes);
        let record = sealed.then(|| ResetRecord::decode(&self.bytes).ok()).flatten();
        *self = RamRecord::EMPTY;
        record
    }
}

/// Writes formatted text into a record's text field, cutting it at a character boundary when it
/// is full (a panic's message may be longer than the record holds).
pub struct TextWriter<'a> {
    record: &'a mut ResetRecord,
    len: usize,
}

impl<'a> TextWriter<'a> {
    /// Starts the record's text afresh.
    pub fn new(record: &'a mut ResetRecord) -> TextWriter<'a> {
        record.text = [0; RESET_TEXT_LEN];
        TextWriter { record, len: 0 }
    }
}

impl fmt::Write for TextWriter<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let room = RESET_TEXT_LEN - self.len;
        let mut n = s.len().min(room);
        while !s.is_char_boundary(n) {
            n -= 1;
        }
        self.record.text[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        // Never an error: a formatter that fails would stop the panic handler's record.
        Ok(())
    }
}
