//! The host side of the 3D pen.
//!
//! * [`transport`]: one interface over USB HID (hidapi), the serial link (serialport) and the
//!   simulated pen in process; [`source`] chooses one; [`device`] keeps a session alive across
//!   unplugging.
//! * [`sample`]: reports as samples — millimetres, the device clock unwrapped, the host's
//!   receive time, lost reports counted from sequence numbers.
//! * [`calibration`]: the tracker → display transform from touched targets, its file, and
//!   display coordinates (u, v, h in mm and pixels); [`plot`] draws its residuals.
//! * [`events`]: pen events from samples; [`pipeline`] turns a device into events.
//! * [`daemon`]: `pend`, serving events to any number of clients on a Unix socket; [`client`]
//!   reads them.
//!
//! Every byte layout comes from `pen-protocol`; nothing here re-implements it.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod calibrate;
pub mod calibration;
pub mod client;
pub mod daemon;
pub mod device;
pub mod events;
pub mod hex;
pub mod pipeline;
pub mod plot;
pub mod sample;
pub mod socket;
pub mod source;
pub mod transport;
pub mod wire;
