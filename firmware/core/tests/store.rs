//! The configuration log over a flash region in RAM that behaves like NOR flash: writes can
//! only clear bits, erasing sets them all.

use pen_core::default_config;
use pen_core::store::{ConfigStore, FlashRegion, LogStore, RECORD_LEN, StoreError};
use pen_protocol::Config;

struct RamFlash {
    bytes: Vec<u8>,
    erases: usize,
    /// Stop a write after this many bytes (a power cut).
    cut_after: Option<usize>,
}

impl RamFlash {
    fn new(records: usize) -> RamFlash {
        RamFlash {
            bytes: vec![0xFF; records * RECORD_LEN + 7],
            erases: 0,
            cut_after: None,
        }
    }
}

impl FlashRegion for RamFlash {
    fn size(&self) -> usize {
        self.bytes.len()
    }
    fn read(&mut self, offset: usize, buf: &mut [u8]) -> Result<(), StoreError> {
        buf.copy_from_slice(self.bytes.get(offset..offset + buf.len()).ok_or(StoreError::Flash)?);
        Ok(())
    }
    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), StoreError> {
        assert!(
            offset.is_multiple_of(4) && bytes.len().is_multiple_of(4),
            "4-byte writes"
        );
        let n = self.cut_after.take().unwrap_or(bytes.len()).min(bytes.len());
        for (dst, src) in self
            .bytes
            .get_mut(offset..offset + n)
            .ok_or(StoreError::Flash)?
            .iter_mut()
            .zip(bytes)
        {
            // NOR flash: programming only clears bits.
            *dst &= *src;
        }
        Ok(())
    }
    fn erase(&mut self) -> Result<(), StoreError> {
        self.bytes.iter_mut().for_each(|b| *b = 0xFF);
        self.erases += 1;
        Ok(())
    }
}

fn config(temperature_c: f32) -> Config {
    Config {
        temperature_c,
        ..default_config()
    }
}

#[test]
fn empty_flash_has_no_configuration() {
    assert_eq!(LogStore::new(RamFlash::new(4)).load(), None);
}

#[test]
fn the_newest_save_loads_and_the_region_is_reused_when_full() {
    let mut store = LogStore::new(RamFlash::new(3));
    for (i, t) in [10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0].into_iter().enumerate() {
        store.save(&config(t)).expect("save");
        assert_eq!(store.load(), Some(config(t)), "after save {i}");
    }
    // Three records fit: seven saves erased the region twice.
    assert_eq!(store.into_inner().erases, 2);
}

#[test]
fn a_save_cut_short_leaves_the_previous_configuration() {
    let mut store = LogStore::new(RamFlash::new(4));
    store.save(&config(20.0)).expect("save");
    let mut flash = store.into_inner();
    flash.cut_after = Some(100);
    let mut store = LogStore::new(flash);
    // The read-back after the write catches it.
    assert_eq!(store.save(&config(30.0)), Err(StoreError::Verify));
    assert_eq!(store.load(), Some(config(20.0)));
    // The next save goes after the torn record and wins.
    store.save(&config(40.0)).expect("save");
    assert_eq!(store.load(), Some(config(40.0)));
}

#[test]
fn a_corrupted_record_is_skipped() {
    let mut store = LogStore::new(RamFlash::new(4));
    store.save(&config(20.0)).expect("save");
    store.save(&config(21.0)).expect("save");
    let mut flash = store.into_inner();
    flash.bytes[RECORD_LEN + 50] ^= 0x10;
    assert_eq!(LogStore::new(flash).load(), Some(config(20.0)));
}
