//! Stack measurement by painting: cortex-m-rt fills the whole stack with
//! [`STACK_PAINT_VALUE`] before `main` (its `paint-stack` feature), and the deepest the stack has
//! reached is where the paint first gives way. The stack sits at the bottom of RAM
//! (stm32f411ce.x), so an overflow faults instead of corrupting the statics; this says how much
//! of it the firmware uses.

use core::ptr::addr_of;

use cortex_m_rt::STACK_PAINT_VALUE;

unsafe extern "C" {
    /// The stack's lowest address (the bottom of RAM), from stm32f411ce.x.
    static _stack_end: u32;
    /// The stack's highest address, from stm32f411ce.x.
    static _stack_start: u32;
}

fn bounds() -> (usize, usize) {
    // Only the symbols' addresses are taken, never their values.
    (addr_of!(_stack_end) as usize, addr_of!(_stack_start) as usize)
}

/// The most stack used since reset, and the stack's size, bytes.
pub fn high_water() -> (usize, usize) {
    let (bottom, top) = bounds();
    let mut p = bottom;
    // SAFETY: reads of RAM within the stack's bounds, word-aligned (cortex-m-rt checks that
    // both symbols are aligned).
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == STACK_PAINT_VALUE {
        p += 4;
    }
    (top - p, top - bottom)
}
