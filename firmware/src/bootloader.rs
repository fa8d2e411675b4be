//! Restarting into the STM32F4's ROM USB DFU bootloader, so `dfu-util` can flash a new image
//! without a probe or the BOOT0 button.
//!
//! The request survives a reset in RAM the start-up code does not clear (`.uninit`); `main`
//! checks it before it touches any clock or peripheral and jumps to system memory in the state
//! the bootloader expects, straight after reset.

use core::mem::MaybeUninit;
use core::ptr::addr_of_mut;

use embassy_stm32::pac;

/// Where the STM32F4's system memory (the ROM bootloader) starts.
const SYSTEM_MEMORY: u32 = 0x1FFF_0000;
const MAGIC: u32 = 0xB007_10AD;

#[unsafe(link_section = ".uninit.BOOT_REQUEST")]
static mut BOOT_REQUEST: MaybeUninit<u32> = MaybeUninit::uninit();

/// Marks the request and resets the chip.
pub fn restart_into_bootloader() -> ! {
    // SAFETY: a plain volatile store to a word this module owns.
    unsafe { addr_of_mut!(BOOT_REQUEST).cast::<u32>().write_volatile(MAGIC) };
    cortex_m::peripheral::SCB::sys_reset()
}

/// Maps the main flash at address 0 again. After `dfu-util … :leave` the ROM bootloader jumps to
/// the image with system memory still mapped there (AN2606, STM32F411); VTOR is set by the reset
/// handler (cortex-m-rt's `set-vtor`), but anything that reads address 0 would read the ROM.
pub fn map_flash_at_zero() {
    pac::RCC.apb2enr().modify(|w| w.set_syscfgen(true));
    pac::SYSCFG.memrm().modify(|w| w.set_mem_mode(0));
}

/// At the very start of `main`: jumps to the bootloader if it was requested before the reset.
pub fn enter_if_requested() {
    // SAFETY: the word may hold anything after a power-up; reading it as a u32 is fine.
    let requested = unsafe { addr_of_mut!(BOOT_REQUEST).cast::<u32>().read_volatile() } == MAGIC;
    if !requested {
        return;
    }
    // SAFETY: as above.
    unsafe { addr_of_mut!(BOOT_REQUEST).cast::<u32>().write_volatile(0) };
    // Map system memory at address 0, as a boot with BOOT0 high would, then jump to its reset
    // vector with its stack pointer.
    pac::RCC.apb2enr().modify(|w| w.set_syscfgen(true));
    pac::SYSCFG.memrm().modify(|w| w.set_mem_mode(1));
    // SAFETY: system memory holds the ROM bootloader's vector table; nothing of ours runs after.
    unsafe { cortex_m::asm::bootload(SYSTEM_MEMORY as *const u32) }
}
