//! The simulated pen and base station.
//!
//! It models what makes ultrasonic tracking hard — receiver geometry ([`rig`]), the speed of
//! sound and its drift, timing jitter, timer quantisation, late echoes and dropouts
//! ([`acoustics`]), a human hand with tremor and bouncing switch contacts ([`hand`]) — plays
//! scripted sessions of the seed's operations ([`script`], [`scenarios`], [`session`]), and
//! drives the real firmware core through its hardware traits ([`sim`]), so what comes out are
//! the exact report bytes the device sends. Three ways out: in process ([`sim::Simulation`]),
//! over a pseudo-terminal like a real serial device ([`pty`]), and the core itself on an emulated
//! Cortex-M4F ([`qemu`]). [`accuracy`] measures it; [`trace`] records it.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod accuracy;
pub mod acoustics;
pub mod hand;
pub mod pty;
pub mod qemu;
pub mod rig;
pub mod scenarios;
pub mod script;
pub mod session;
pub mod sim;
pub mod trace;

pub use sim::{CycleRecord, Scenario, Sent, Simulation};
