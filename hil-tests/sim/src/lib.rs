//! The simulated pen and base station.
//!
//! It models what makes ultrasonic tracking hard — receiver geometry ([`rig`]), the speed of
//! sound and its drift, timing jitter, timer quantisation, late echoes and dropouts
//! ([`acoustics`]), a human hand with tremor and bouncing switch contacts ([`hand`]), a seated
//! viewer wearing the tracked shutter glasses ([`viewer`]) — plays
//! scripted sessions of the seed's operations ([`script`], [`scenarios`], [`session`]), and
//! drives the real firmware core through its hardware traits ([`sim`]), so what comes out are
//! the exact report bytes the device sends, in process ([`sim::Simulation`]).
//!
//! This crate is the simulator only: a library the host driver's `sim` transport and the
//! modeler's built-in demo link. The hardware-in-the-loop harness around it — the
//! pseudo-terminal server, the QEMU runner, the accuracy tool, the `pen-sim` program — is the
//! `pen-hil` crate in `hil-tests/`, which nothing in production depends on.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod acoustics;
pub mod hand;
pub mod rig;
pub mod scenarios;
pub mod script;
pub mod session;
pub mod sim;
pub mod viewer;

pub use sim::{CycleRecord, Scenario, Sent, Simulation};
