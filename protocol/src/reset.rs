//! The reset-cause feature report (ID 0x09, read-only, protocol 2.2): why the firmware last
//! restarted when it was not asked to. A panic or a fault writes a record to RAM that the
//! start-up code leaves alone and resets the chip at once; the next boot reads the record,
//! logs it and answers it here until the next reset.

use core::fmt;

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;

/// What ended the previous run. JSON (feature `serde`): the variant's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum ResetKind {
    /// Nothing recorded: a power-up, a requested restart, a probe's reset.
    None = 0,
    /// A Rust panic: `line`, `column` and the text say where and why.
    Panic = 1,
    /// A processor fault (HardFault): a stack overflow into the guard below RAM, a bad access.
    /// `line` holds the faulting PC (0 where the stacking itself failed), `column` the CFSR.
    Fault = 2,
    /// The independent watchdog reset the chip: the station stopped for its 12 s and no panic or
    /// fault said why (a lockup, a deadlock).
    Watchdog = 3,
}

/// Bytes of text the record carries: the panic's file, line and message, cut to fit.
pub const RESET_TEXT_LEN: usize = 49;

/// The last unrequested reset: what, where, after how long, and the panic's text.
#[derive(Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetRecord {
    /// What it was.
    pub kind: ResetKind,
    /// A panic's source line; a fault's program counter.
    pub line: u32,
    /// A panic's source column; a fault's CFSR (configurable fault status register).
    pub column: u32,
    /// Milliseconds since start-up when it happened.
    pub uptime_ms: u32,
    /// UTF-8, zero-padded: `file:line:column: message` for a panic, cut at a character boundary.
    pub text: [u8; RESET_TEXT_LEN],
}

impl ResetRecord {
    /// Nothing recorded.
    pub const NONE: ResetRecord = ResetRecord {
        kind: ResetKind::None,
        line: 0,
        column: 0,
        uptime_ms: 0,
        text: [0; RESET_TEXT_LEN],
    };

    /// The text up to its padding; what is not valid UTF-8 (a record cut mid-character by an
    /// older writer) is left out.
    pub fn text(&self) -> &str {
        let end = self.text.iter().position(|&b| b == 0).unwrap_or(RESET_TEXT_LEN);
        match core::str::from_utf8(&self.text[..end]) {
            Ok(s) => s,
            Err(e) => core::str::from_utf8(&self.text[..e.valid_up_to()]).unwrap_or_default(),
        }
    }

    /// `s` as the record's text, cut at a character boundary to fit.
    pub fn set_text(&mut self, s: &str) {
        let mut end = s.len().min(RESET_TEXT_LEN);
        while !s.is_char_boundary(end) {
            end -= 1;
        }
        self.text = [0; RESET_TEXT_LEN];
        self.text[..end].copy_from_slice(&s.as_bytes()[..end]);
    }
}

impl fmt::Debug for ResetRecord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ResetRecord")
            .field("kind", &self.kind)
            .field("line", &self.line)
            .field("column", &self.column)
            .field("uptime_ms", &self.uptime_ms)
            .field("text", &self.text())
            .finish()
    }
}

impl fmt::Display for ResetRecord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self.uptime_ms as f64 / 1000.0;
        match self.kind {
            ResetKind::None => f.write_str("no panic or fault recorded"),
            ResetKind::Watchdog => f.write_str("watchdog reset: the firmware stopped without a panic"),
            ResetKind::Panic => write!(f, "panic after {t:.1} s: {}", self.text()),
            ResetKind::Fault => write!(
                f,
                "fault after {t:.1} s at PC 0x{:08x} (CFSR 0x{:08x}){}",
                self.line,
                self.column,
                if self.column & CFSR_STACKING != 0 {
                    ": stack overflow"
                } else {
                    ""
                }
            ),
        }
    }
}

/// CFSR's stacking-error bits (MSTKERR, BSTKERR): the fault came while pushing onto the stack,
/// which past the guard below RAM means the stack overflowed.
pub const CFSR_STACKING: u32 = (1 << 4) | (1 << 12);

impl Report for ResetRecord {
    const ID: ReportId = ReportId::ResetRecord;
    const LEN: usize = 15 + RESET_TEXT_LEN;

    fn write_body(&self, w: &mut Writer<'_>) {
        w.u8(self.kind as u8);
        w.u8(0);
        w.u32(self.line);
        w.u32(self.column);
        w.u32(self.uptime_ms);
        w.bytes(&self.text);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let kind = match r.u8()? {
            0 => ResetKind::None,
            1 => ResetKind::Panic,
            2 => ResetKind::Fault,
            3 => ResetKind::Watchdog,
            _ => {
                return Err(DecodeError::OutOfRange {
                    report: ReportId::ResetRecord,
                    field: "kind",
                });
            }
        };
        r.zero_u8("reserved")?;
        Ok(ResetRecord {
            kind,
            line: r.u32()?,
            column: r.u32()?,
            uptime_ms: r.u32()?,
            text: r.bytes()?,
        })
    }
}
