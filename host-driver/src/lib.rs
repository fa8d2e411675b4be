//! The host side of the 3D pen.
//!
//! Today: reports as JSON ([`json`]) and hex input ([`hex`]), used by `penctl`. The host-driver
//! issue adds the transports (HID through hidapi, serial through serialport, the simulated pen),
//! calibration to the display frame, pen events and the `pend` daemon. Every byte layout comes
//! from `pen-protocol`; nothing here re-implements it.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod hex;
pub mod json;
