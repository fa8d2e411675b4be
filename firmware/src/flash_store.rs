//! The configuration's flash region: sector 7, the last 128 KiB of the STM32F411CE's 512 KiB.
//! `memory.x` gives the program sectors 0–6 only, so the two can never overlap.

use embassy_stm32::flash::{Blocking, Flash};
use pen_core::{FlashRegion, StoreError};

/// Offset of sector 7 from the start of flash.
const SECTOR_7: u32 = 0x6_0000;
/// Its size.
const SECTOR_7_SIZE: u32 = 0x2_0000;

/// Sector 7 through embassy's blocking flash driver. Programming stalls the CPU for a few
/// microseconds per word; erasing, which the store does once per 655 saves, for about a second.
pub struct ConfigSector<'d> {
    pub flash: Flash<'d, Blocking>,
}

impl FlashRegion for ConfigSector<'_> {
    fn size(&self) -> usize {
        SECTOR_7_SIZE as usize
    }

    fn read(&mut self, offset: usize, buf: &mut [u8]) -> Result<(), StoreError> {
        self.flash
            .blocking_read(SECTOR_7 + offset as u32, buf)
            .map_err(|_| StoreError::Flash)
    }

    fn write(&mut self, offset: usize, bytes: &[u8]) -> Result<(), StoreError> {
        self.flash
            .blocking_write(SECTOR_7 + offset as u32, bytes)
            .map_err(|_| StoreError::Flash)
    }

    fn erase(&mut self) -> Result<(), StoreError> {
        let result = self
            .flash
            .blocking_erase(SECTOR_7, SECTOR_7 + SECTOR_7_SIZE)
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
