//! Panics and faults: recorded, then the chip resets at once; the next boot reports the record.
//!
//! The record ([`pen_protocol::ResetRecord`]) is sealed into RAM the start-up code leaves alone
//! (`.uninit`, pen-core's [`RamRecord`]: magic and CRC, so a power-up's noise is no record).
//! [`take_last`] reads it back first thing at start-up; `main` logs it over defmt and the engine
//! answers it as feature report 0x09 (`penctl info` prints it). A watchdog reset with no record
//! is reported as one.
//!
//! A stack overflow runs off the end of RAM (the stack is at its bottom, stm32f411ce.x) and
//! faults; the HardFault vector (`hard_fault.rs`) moves the stack pointer back to the top of the
//! stack before [`fault_on_fresh_stack`] runs, and the record says *stack overflow* (CFSR's
//! stacking-error bits).
//!
//! With a debugger attached, a panic also stops at a breakpoint after logging, so that
//! `probe-rs run` prints the backtrace; without one, nothing waits.

use core::fmt::Write;
use core::mem::MaybeUninit;
use core::panic::PanicInfo;
use core::ptr::addr_of_mut;

use cortex_m::peripheral::{DCB, SCB};
use pen_core::reset::{RamRecord, TextWriter};
use pen_protocol::{CFSR_STACKING, ResetKind, ResetRecord};

#[unsafe(link_section = ".uninit.RESET_RECORD")]
static mut RESET_RECORD: MaybeUninit<RamRecord> = MaybeUninit::uninit();

/// The configurable fault status register (ARMv7-M ARM, B3.2.15).
const CFSR: *const u32 = 0xE000_ED28 as *const u32;
/// The bottom of RAM: a fault whose frame would lie below it had nowhere to stack.
const RAM_START: u32 = 0x2000_0000;

fn uptime_ms() -> u32 {
    embassy_time::Instant::now().as_millis() as u32
}

/// Seals `record` for the next boot and resets.
fn record_and_reset(record: &ResetRecord) -> ! {
    // SAFETY: interrupts are off and nothing else writes the slot; a volatile store of plain
    // bytes, which the reset handler does not clear.
    unsafe {
        addr_of_mut!(RESET_RECORD)
            .cast::<RamRecord>()
            .write_volatile(RamRecord::seal(record))
    };
    log(record);
    defmt::error!("resetting");
    if DCB::is_debugger_attached() {
        cortex_m::asm::bkpt();
    }
    SCB::sys_reset()
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    let (line, column) = info.location().map_or((0, 0), |l| (l.line(), l.column()));
    let mut record = ResetRecord {
        kind: ResetKind::Panic,
        line,
        column,
        uptime_ms: uptime_ms(),
        ..ResetRecord::NONE
    };
    let mut text = TextWriter::new(&mut record);
    if let Some(l) = info.location() {
        let _ = write!(text, "{}:{}:{}: ", l.file(), l.line(), l.column());
    }
    let _ = write!(text, "{}", info.message());
    record_and_reset(&record)
}

/// The HardFault's Rust half, run on a fresh stack by `hard_fault.rs`'s vector: `frame` is the
/// stack pointer at the fault.
#[unsafe(no_mangle)]
extern "C" fn fault_on_fresh_stack(frame: u32) -> ! {
    // SAFETY: a read of a system control register.
    let cfsr = unsafe { CFSR.read_volatile() };
    let stacked = cfsr & CFSR_STACKING == 0 && frame >= RAM_START;
    // The exception frame: r0–r3, r12, lr, pc, xpsr; the PC is its seventh word.
    // SAFETY: `stacked` says the frame is in RAM and was written by the exception entry.
    let pc = if stacked {
        unsafe { ((frame + 24) as *const u32).read_volatile() }
    } else {
        0
    };
    record_and_reset(&ResetRecord {
        kind: ResetKind::Fault,
        line: pc,
        column: cfsr,
        uptime_ms: uptime_ms(),
        ..ResetRecord::NONE
    })
}

/// Logs a record over defmt.
pub fn log(record: &ResetRecord) {
    defmt::error!(
        "{} after {} ms (line or PC {=u32:#x}, column or CFSR {=u32:#x}): {=str}",
        record.kind,
        record.uptime_ms,
        record.line,
        record.column,
        record.text()
    );
}

/// The record the previous run left, or a watchdog reset's; `None` for a power-up or a requested
/// restart. Clears both for the next boot. Call once, first thing in `main`.
pub fn take_last() -> Option<ResetRecord> {
    // SAFETY: read and emptied once, before anything could panic and write it; the slot is plain
    // bytes, any content of which `take` checks.
    let record = unsafe { (*addr_of_mut!(RESET_RECORD).cast::<RamRecord>()).take() };
    let rcc = embassy_stm32::pac::RCC;
    let watchdog = rcc.csr().read().wdgrstf();
    // Clear the reset flags, so the next reset's are its own.
    rcc.csr().modify(|w| w.set_rmvf(true));
    record.or(watchdog.then_some(ResetRecord {
        kind: ResetKind::Watchdog,
        ..ResetRecord::NONE
    }))
}
