//! The HardFault vector, on a fresh stack.
//!
//! The stack sits at the bottom of RAM (stm32f411ce.x), so an overflow runs off the end of RAM:
//! the push faults, and the HardFault's own exception entry cannot stack either. Rust code
//! cannot run on that stack pointer, so the vector is these few instructions of assembly: the
//! stack pointer as the fault left it goes to r0 (the exception frame, where stacking worked),
//! the stack pointer is set to the top of the stack (`_stack_start`), and `fault_on_fresh_stack`
//! (the including crate's, `extern "C" fn(frame: u32) -> !`) runs there. cortex-m-rt calls the
//! vector `HardFault`; this definition replaces its default.
//!
//! The board's `fault.rs` and pen-qemu (which overflows its stack on purpose under QEMU, the
//! guard's test) both include this file.

core::arch::global_asm!(
    ".section .HardFault.user, \"ax\"",
    ".global HardFault",
    ".type HardFault, %function",
    ".thumb_func",
    "HardFault:",
    "mrs r0, msp",
    "ldr r1, =_stack_start",
    "msr msp, r1",
    "b fault_on_fresh_stack",
);
