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
//! Record layout 2 (little-endian, 208 bytes, a multiple of the flash's 4-byte write unit):
//! magic `PCFG` (u32), sequence (u32), the configuration report (protocol 2: 195 bytes), the
//! layout version (one byte, [`LAYOUT`]), CRC-32 of the preceding 204 bytes (u32). A record of
//! another layout is skipped, never misread: layout 1's 200-byte records (protocol 1's
//! configuration, no version byte) fail the CRC at this stride, and a record whose CRC holds
//! with another version byte is skipped by that byte.

use pen_protocol::{CRC, Config, Report};

/// Bytes of one record.
pub const RECORD_LEN: usize = 208;
const MAGIC: u32 = u32::from_le_bytes(*b"PCFG");
const BODY: usize = RECORD_LEN - 4;
/// The records' layout version, in the byte before the CRC.
pub const LAYOUT: u8 = 2;
const LAYOUT_AT: usize = BODY - 1;
const _: () = assert!(
    8 + Config::LEN <= LAYOUT_AT,
    "the configuration fits before the layout byte"
);

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
    /// The newest stored configuration that decodes and validates, if any.
    fn load(&mut self) -> Option<Config>;
    /// Stores `config`.
    fn save(&mut self, config: &Config) -> Result<(), StoreError>;
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
    Valid { seq: u32, config: Config },
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
        if word(0) != MAGIC || word(BODY) != CRC.checksum(&rec[..BODY]) || rec[LAYOUT_AT] != LAYOUT {
            return Ok(Slot::Invalid);
        }
        match Config::decode(&rec[8..8 + Config::LEN]) {
            Ok(config) if config.validate().is_ok() => Ok(Slot::Valid { seq: word(4), config }),
            _ => Ok(Slot::Invalid),
        }
    }

    /// A region's newest valid record and the index after its last used slot.
    fn scan(&mut self, region: usize) -> Result<(Option<(u32, Config)>, usize), StoreError> {
        let (mut newest, mut next_free) = (None::<(u32, Config)>, 0);
        for i in 0..self.slots(region) {
            match self.read_slot(region, i)? {
                Slot::Erased => {}
                Slot::Valid { seq, config } => {
                    if newest.is_none_or(|(s, _)| seq >= s) {
                        newest = Some((seq, config));
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
    fn scan_both(&mut self) -> Result<([(Option<(u32, Config)>, usize); 2], usize), StoreError> {
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
    fn load(&mut self) -> Option<Config> {
        let (scans, active) = self.scan_both().ok()?;
        scans[active].0.map(|(_, c)| c)
    }

    fn save(&mut self, config: &Config) -> Result<(), StoreError> {
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
        config
            .encode(&mut rec[8..8 + Config::LEN])
            .map_err(|_| StoreError::Flash)?;
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
