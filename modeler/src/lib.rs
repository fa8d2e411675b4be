//! `penmodel`, the terrain modeler driven by the 3D pen: the seed's pen interaction over the
//! terrain model (`penmodel-terrain`) and the CPU renderer (`penmodel-render`).
//!
//! - [`interaction`]: the seed's pen operations (section 3.2) as a state machine over pen
//!   events — draw, end with SW3, highlight, grab, pull, slope, move, delete, undo, pan and zoom
//!   (`docs/modeler.md`).
//! - [`feed`] and [`session`]: pen events from the built-in demo, `pend` or a device, on a thread
//!   of their own, into an editor.
//! - [`keys`]: the live window's keys and the help it shows for them.
//! - [`picture`]: what a frame of the session shows — the document and the interaction turned
//!   into the renderer's plain-data scene.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod feed;
pub mod head_prediction;
pub mod interaction;
pub mod keys;
pub mod latency;
pub mod picture;
pub mod session;
