//! The host side of the 3D pen.
//!
//! * [`transport`]: one interface over USB HID (hidapi), the serial link (serialport) and the
//!   simulated pen in process (cargo feature `sim`); [`source`] chooses one, from a
//!   `--source` string (`hid`, `serial:PATH`, `sim`, …) every tool takes; [`device`] keeps a session alive across
//!   unplugging.
//! * [`sample`]: reports as samples — millimetres, the device clock unwrapped, the host's
//!   receive time, lost reports counted from sequence numbers.
//! * [`calibration`]: the tracker → display transform fitted to touched targets, its file, the
//!   procedure that collects the touches, display coordinates (u, v, h in mm and pixels), and
//!   the residual plot.
//! * [`events`]: pen events from samples; [`head`]: the tracked head's samples and `head`
//!   events; [`pipeline`] turns a device into events.
//! * [`daemon`]: `pend`, serving events to any number of clients on a Unix socket; [`client`]
//!   reads them; [`wire`] is the socket's line format, shared by both; [`requests`] reads what
//!   a client asks for (`head` lines).
//!
//! * [`help`]: what every tool's `--help` promises (examples), checked by each tool's tests.
//!
//! Every byte layout comes from `pen-protocol`; nothing here re-implements it.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod calibration;
pub mod client;
pub mod daemon;
pub mod device;
pub mod events;
// The fuzz targets' properties, shared with the stable test that replays their corpora.
#[doc(hidden)]
pub mod fuzzing;
pub mod head;
pub mod help;
pub mod hex;
pub mod pipeline;
pub mod requests;
pub mod sample;
pub mod socket;
pub mod source;
pub mod transport;
pub mod virtual_tablet;
pub mod wire;
