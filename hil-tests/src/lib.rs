//! The hardware-in-the-loop harness around the simulated pen (`pen-sim`).
//!
//! Three ways to reach the real code with the simulated pen's bytes: over a pseudo-terminal like
//! a real serial device ([`pty`]), the firmware core itself on an emulated Cortex-M4F
//! ([`qemu`]), and the real board, its receiver inputs and switches driven by the bench rig
//! ([`rig`]); [`accuracy`] measures the tracker against the Cramér–Rao bound, [`head`] the
//! tracked head and what multiplexing it costs the pen, and [`trace`] records a run. The
//! `pen-sim` program exposes them; `tests/` holds the whole-chain tests.
//! Nothing depends on this crate.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod accuracy;
pub mod head;
pub mod pty;
pub mod qemu;
pub mod rig;
pub mod trace;
