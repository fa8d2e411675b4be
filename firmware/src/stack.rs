//! Stack measurement by painting: the free stack is filled with a pattern at start-up, and the
//! deepest the stack has reached is where the pattern first gives way. The linker script holds
//! the statics and the stack to 16 KiB together; this says how much of the rest the stack uses.

use core::ptr::{addr_of, addr_of_mut};

/// The paint: unlikely as a return address, a saved register or data.
const PAINT: u32 = 0xCA5C_ADE5;
/// Left unpainted below the stack pointer at the time of painting, for `paint`'s own frame.
const MARGIN: usize = 64;

unsafe extern "C" {
    /// The stack's lowest address (the end of the statics), from cortex-m-rt's link.x.
    static mut _stack_end: u32;
    /// The stack's highest address (the top of RAM), from cortex-m-rt's link.x.
    static _stack_start: u32;
}

fn bounds() -> (usize, usize) {
    // Only the symbols' addresses are taken, never their values.
    (addr_of_mut!(_stack_end) as usize, addr_of!(_stack_start) as usize)
}

/// Paints the stack below the current stack pointer. Call once, first thing in `main`.
pub fn paint() {
    let (bottom, _) = bounds();
    let sp = cortex_m::register::msp::read() as usize;
    let mut p = bottom;
    while p + 4 <= sp.saturating_sub(MARGIN) {
        // SAFETY: between the end of the statics and below the live stack: memory that nothing
        // uses yet, word-aligned (cortex-m-rt aligns _stack_end to 4).
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// The most stack used since [`paint`], and the stack's size, bytes.
pub fn high_water() -> (usize, usize) {
    let (bottom, top) = bounds();
    let mut p = bottom;
    // SAFETY: reads of RAM within the stack's bounds, word-aligned.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    (top - p, top - bottom)
}
