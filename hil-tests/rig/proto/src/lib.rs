//! The bench rig's shared definitions: what the host and the rig's firmware say to each other
//! ([`message`]) and how a time of flight becomes an edge on a receiver input ([`schedule`]).
//!
//! The rig (a Raspberry Pi Pico, `hil-tests/rig/`) watches the base station's burst pin and,
//! after each burst, raises each receiver input at the time the host asked for, from PIO at the
//! system clock: 125 MHz, so 8 ns per step. One definition here keeps the firmware and the host
//! side from drifting apart; both build this crate (the firmware for thumbv6m-none-eabi, the
//! host tests for the development machine, where its tests run). See docs/hil-rig.md.
#![no_std]
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod message;
pub mod schedule;

pub use message::{DecodeError, ErrorCode, HostMessage, Info, MAX_MESSAGE, RigMessage, RigStatus};
pub use schedule::{Edge, Edges, MAX_EDGES, ScheduleError, words};
// The frames are the base station's serial framing; re-exported so both ends use the same.
pub use pen_protocol::{FrameDecoder, FrameError, MAX_FRAME, encode_frame};

/// USB vendor ID of the rig: pid.codes, as the base station's.
pub const RIG_VID: u16 = pen_protocol::USB_VID;
/// USB product ID of the rig, in pid.codes' range for testing (0x0001–0x0010), next to the base
/// station's 0x0007: a bench instrument that never leaves the lab.
pub const RIG_PID: u16 = 0x0008;
/// The rig's USB product string; the host matches it too, since other test devices may share
/// the testing PID.
pub const RIG_PRODUCT: &str = "penscape bench rig";

/// Receiver inputs the rig drives: as many as the base station can capture (four required,
/// four optional), one PIO state machine each.
pub const RECEIVERS: usize = pen_protocol::MAX_RECEIVERS;

/// Version of the messages below; [`Info`] carries it and the host refuses another.
/// 2: a cycle carries up to [`MAX_EDGES`] pulses per receiver.
pub const RIG_PROTOCOL_VERSION: u8 = 2;
