//! Configuration storage: a log of checksummed records in two flash regions used in turn.
//!
//! Each save appends a record; loading takes the newest record that checks out. A region is
//! erased only when the other is full, so a save is a write of 200 bytes (under a millisecond on
//! the STM32F4) rather than a sector erase (seconds), and the flash wears out hundreds of times
//! more slowly. A save interrupted by power loss leaves a record whose CRC fails; it is skipped
//! and the previous configuration loads. The region holding the newest record is never erased:
//! when it is full the next record goes to the other region, erased first, so a power cut
//! during that erase (or during any write) still leaves the newest complete record readable.
//!
//! Record layout 3 (little-endian, 208 bytes, a multiple of the flash's 4-byte write unit):
//! magic `PCFG` (u32), sequence (u32), the configuration report without its report ID (always
//! `0x04`: protocol 2's 195 bytes less one), the head byte (bit 0: head tracking on; the other
//! bits zero), the layout version (one byte, [`LAYOUT`]), CRC-32 of the preceding 204 bytes
//! (u32). Layout 2, written before head tracking could be saved, had the whole report (ID
//! included) where layout 3 has the report and the head byte: it still loads, with the head off.
//! A record of another layout is skipped, never misread: layout 1's 200-byte records (protocol
//! 1's configuration, no version byte) fail the CRC at this stride, and a record whose CRC holds
//! with another version byte is skipped by that byte (firmware that knows only layout 2 skips
//! layout 3's records and loads the newest layout 2 one it finds).

use pen_protocol::{CRC, Config, Report, ReportId};

/// Bytes of one record.
pub const RECORD_LEN: usize = 208;
const MAGIC: u32 = u32::from_le_bytes(*b"PCFG");
const BODY: usize = RECORD_LEN - 4;
/// The records' layout version this build writes, in the byte before the CRC.
pub const LAYOUT: u8 = 3;
/// The layout before it (no head byte), still loaded.
pub const LAYOUT_2: u8 = 2;
const LAYOUT_AT: usize = BODY - 1;
/// Layout 3's head byte, after the configuration report's bytes less its ID.
const HEAD_AT: usize = 8 + Config::LEN - 1;
/// The head byte's bit: head tracking was on.
const HEAD_ON: u8 = 1;
const _: () = assert!(
    8 + Config::LEN <= LAYOUT_AT && HEAD_AT < LAYOUT_AT,
    "the configuration (and layout 3's head byte) fit before the layout byte"
);

/// What a save keeps across a power cycle: the running configuration and whether the head was
/// being tracked (HeadOn, protocol 2.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Saved {
    /// The configuration report.
    pub config: Config,
    /// Head tracking was on: a base station with the glasses' emitter starts with it on.
    pub head: bool,
}

impl Saved {
    /// A configuration saved with the head off (what layout 2 records hold).
    pub fn config(config: Config) -> Saved {
        Saved { config, head: false }
    }
}

/// A flash region the store owns (one sector): reads, writes of erased bytes, and erasing all
/// of it.
pub trait FlashRegion {
    /// The region's size in bytes.
    fn size(&self) -> usize;
    /// Reads `buf.len()` bytes at `offset`.
    fn read(&mut self, offset: usize, buf: &mut [u8]) -> Result<(), StoreError>;
    /// Programs bytes at `offset`, which must be erased; offset and length are multiples of 4.
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), StoreError>;
    /// Erases the whole region (every byte becomes 0xFF).
    fn erase(&mut self) -> Result<(), StoreError>;
}

/// Why storage failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// The flash driver reported an error.
    Flash,
    /// A record read back differs from what was written.
    Verify,
}

/// Where configurations are kept across power cycles.
pub trait ConfigStore {
    /// The newest stored configuration that decodes and validates, and its head mode, if any.
    fn load(&mut self) -> Option<Saved>;
    /// Stores `saved`.
    fn save(&mut self, saved: &Saved) -> Result<(), StoreError>;
}

/// The record log over two flash regions.
pub struct LogStore<F> {
    regions: [F; 2],
}

// A short-lived value on the stack during a scan; without an allocator there is nothing to gain
// from boxing the large variant.
#[allow(clippy::large_enum_variant)]
enum Slot {
    Erased,
    Valid { seq: u32, saved: Saved },
    Invalid,
}

impl<F: FlashRegion> LogStore<F> {
    /// A store over two regions, used in turn.
    pub fn new(regions: [F; 2]) -> Self {
        LogStore { regions }
    }

    /// The flash regions, back.
    pub fn into_inner(self) -> [F; 2] {
        self.regions
    }

    fn slots(&self, region: usize) -> usize {
        self.regions[region].size() / RECORD_LEN
    }

    fn read_slot(&mut self, region: usize, index: usize) -> Result<Slot, StoreError> {
        let mut rec = [0u8; RECORD_LEN];
        self.regions[region].read(index * RECORD_LEN, &mut rec)?;
        if rec.iter().all(|&b| b == 0xFF) {
            return Ok(Slot::Erased);
        }
        let word = |at: usize| u32::from_le_bytes([rec[at], rec[at + 1], rec[at + 2], rec[at + 3]]);
        if word(0) != MAGIC || word(BODY) != CRC.checksum(&rec[..BODY]) {
            return Ok(Slot::Invalid);
        }
        let mut report = [0u8; Config::LEN];
        let head = match rec[LAYOUT_AT] {
            LAYOUT_2 => {
                report.copy_from_slice(&rec[8..8 + Config::LEN]);
                false
            }
            LAYOUT if rec[HEAD_AT] & !HEAD_ON == 0 => {
                report[0] = ReportId::Config as u8;
                report[1..].copy_from_slice(&rec[8..HEAD_AT]);
                rec[HEAD_AT] == HEAD_ON
            }
            _ => return Ok(Slot::Invalid),
        };
        match Config::decode(&report) {
            Ok(config) if config.validate().is_ok() => Ok(Slot::Valid {
                seq: word(4),
                saved: Saved { config, head },
            }),
            _ => Ok(Slot::Invalid),
        }
    }

    /// A region's newest valid record and the index after its last used slot.
    fn scan(&mut self, region: usize) -> Result<(Option<(u32, Saved)>, usize), StoreError> {
        let (mut newest, mut next_free) = (None::<(u32, Saved)>, 0);
        for i in 0..self.slots(region) {
            match self.read_slot(region, i)? {
                Slot::Erased => {}
                Slot::Valid { seq, saved } => {
                    if newest.is_none_or(|(s, _)| seq >= s) {
                        newest = Some((seq, saved));
                    }
                    next_free = i + 1;
                }
                Slot::Invalid => next_free = i + 1,
            }
        }
        Ok((newest, next_free))
    }

    /// Both regions' scans, and the region holding the newest record (0 when neither has one).
    #[allow(clippy::type_complexity)]
    fn scan_both(&mut self) -> Result<([(Option<(u32, Saved)>, usize); 2], usize), StoreError> {
        let scans = [self.scan(0)?, self.scan(1)?];
        let active = match (scans[0].0, scans[1].0) {
            (Some((a, _)), Some((b, _))) if b > a => 1,
            (None, Some(_)) => 1,
            _ => 0,
        };
        Ok((scans, active))
    }
}

impl<F: FlashRegion> ConfigStore for LogStore<F> {
    fn load(&mut self) -> Option<Saved> {
        let (scans, active) = self.scan_both().ok()?;
        scans[active].0.map(|(_, c)| c)
    }

    fn save(&mut self, saved: &Saved) -> Result<(), StoreError> {
        let (scans, active) = self.scan_both()?;
        let seq = scans[active].0.map_or(0, |(s, _)| s.wrapping_add(1));
        let (region, slot) = if scans[active].1 < self.slots(active) {
            (active, scans[active].1)
        } else {
            // The active region is full: the other one holds only older records. Erase it and
            // start there; the newest record stays where it is until the next turn.
            let other = 1 - active;
            self.regions[other].erase()?;
            (other, 0)
        };
        let mut rec = [0u8; RECORD_LEN];
        rec[..4].copy_from_slice(&MAGIC.to_le_bytes());
        rec[4..8].copy_from_slice(&seq.to_le_bytes());
        let mut report = [0u8; Config::LEN];
        saved.config.encode(&mut report).map_err(|_| StoreError::Flash)?;
        // The report's ID byte is always the configuration's: not stored.
        rec[8..HEAD_AT].copy_from_slice(&report[1..]);
        rec[HEAD_AT] = if saved.head { HEAD_ON } else { 0 };
        rec[LAYOUT_AT] = LAYOUT;
        let crc = CRC.checksum(&rec[..BODY]);
        rec[BODY..].copy_from_slice(&crc.to_le_bytes());
        self.regions[region].write(slot * RECORD_LEN, &rec)?;
        let mut back = [0u8; RECORD_LEN];
        self.regions[region].read(slot * RECORD_LEN, &mut back)?;
        if back != rec {
            return Err(StoreError::Verify);
        }
        Ok(())
    }
}
