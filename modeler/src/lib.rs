//! `penmodel`, the terrain modeler driven by the 3D pen: the seed's pen interaction over the
//! terrain model (`penmodel-terrain`) and the CPU renderer (`penmodel-render`).
//!
//! - [`interaction`]: the pen's gestures over pen events, through the tool that is on — seed
//!   000's figures (section 3.2: draw, end with SW3, highlight, grab, pull, slope, move, delete),
//!   rocks, rivers, ridgelines, trees — with undo, pan and zoom (`docs/modeler.md`).
//! - [`feed`] and [`session`]: pen events from the built-in demo, `pend` or a device, on a thread
//!   of their own, into an editor.
//! - [`keys`]: the live window's keys and the help it shows for them; [`mouse`]: the window's
//!   pointer as the pen, for users without a base station; [`config`]: the settings file
//!   (the mouse's mapping).
//! - [`picture`]: what a frame of the session shows — the document and the interaction turned
//!   into the renderer's plain-data scene.
//! - [`painter`]: frames of a session — the view, the overview and map, the trees held to the
//!   view's budget; [`latch`] and [`latency`]: a tracked head's newest pose taken late, and how
//!   old the pose a frame shows is.
#![cfg_attr(not(test), warn(clippy::unwrap_used))]

pub mod config;
pub mod feed;
pub mod head_prediction;
pub mod interaction;
pub mod keys;
pub mod latch;
pub mod latency;
pub mod mouse;
pub mod painter;
pub mod picture;
pub mod session;
