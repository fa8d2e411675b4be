//! The configuration's flash regions: sectors 6 and 7, the last 256 KiB of the STM32F411CE's
//! 512 KiB, used in turn by the store (pen-core's `store.rs`). The linker script gives the
//! program sectors 0–5 (256 KiB) only, so the two can never overlap.

use core::cell::RefCell;

use embassy_stm32::flash::{Blocking, Flash};
use pen_core::{FlashRegion, StoreError};

/// Offsets of sectors 6 and 7 from the start of flash.
pub const SECTORS: [u32; 2] = [0x4_0000, 0x6_0000];
/// Their size.
const SECTOR_SIZE: u32 = 0x2_0000;

/// One configuration sector through embassy's blocking flash driver, which both sectors share.
/// Programming stalls the CPU for a few microseconds per word; erasing, which the store does
/// once per 630 saves, for 2 s (4 s at most: embassy erases at 8-bit parallelism).
pub struct ConfigSector<'d> {
    pub flash: &'d RefCell<Flash<'d, Blocking>>,
    pub offset: u32,
}

impl FlashRegion for ConfigSector<'_> {
    fn size(&self) -> usize {
        SECTOR_SIZE as usize
    }

    fn read(&mut self, offset: usize, buf: &mut [u8]) -> Result<(), StoreError> {
        self.flash
            .borrow_mut()
            .blocking_read(self.offset + offset as u32, buf)
            .map_err(|_| StoreError::Flash)
    }

    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), StoreError> {
        self.flash
            .borrow_mut()
            .blocking_write(self.offset + offset as u32, bytes)
            .map_err(|_| StoreError::Flash)
    }

    fn erase(&mut self) -> Result<(), StoreError> {
        let result = self
            .flash
            .borrow_mut()
            .blocking_erase(self.offset, self.offset + SECTOR_SIZE)
            .map_err(|_| StoreError::Flash);
        // The caches may hold lines of the erased sector (the data cache, the store's reads);
        // RM0383 §3.4.2: reset them, disabled, after an erase.
        reset_caches();
        result
    }
}

/// Turns on the flash accelerator: prefetch, instruction cache, data cache (RM0383 §3.4).
pub fn enable_accelerator() {
    embassy_stm32::pac::FLASH.acr().modify(|w| {
        w.set_prften(true);
        w.set_icen(true);
        w.set_dcen(true);
    });
}

/// Empties the instruction and data caches: each is disabled, reset, and enabled again (a cache
/// may be reset only while disabled).
fn reset_caches() {
    let acr = embassy_stm32::pac::FLASH.acr();
    acr.modify(|w| {
        w.set_icen(false);
        w.set_dcen(false);
    });
    acr.modify(|w| {
        w.set_icrst(true);
        w.set_dcrst(true);
    });
    acr.modify(|w| {
        w.set_icrst(false);
        w.set_dcrst(false);
    });
    enable_accelerator();
}
