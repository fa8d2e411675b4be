//! Calibration: the transform from the tracker frame to the display frame.
//!
//! * [`fit`]: the transform from touched targets (Horn's closed form), display sizes and
//!   display coordinates.
//! * [`file`]: the calibration file, `~/.config/penscape/calibration.toml`.
//! * [`device`]: which base station a calibration belongs to (it is refused for any other), and
//!   where each one's file is kept (the simulated pen's apart from the real one's).
//! * [`procedure`]: leading the user (or the simulated pen) through the targets and the pivot.
//! * [`pivot`]: where the pen's tip is from its emitter, from the pen tilted about its tip; the
//!   tracked glasses' positions have it taken out.
//! * [`run`]: the whole calibration on an attached device, as `penctl calibrate` and `penmodel
//!   calibrate` run it.
//! * [`plot`]: the residuals as a PNG.
//! * [`delays`]: each receiver's transducer delay from a pen held at surveyed points
//!   (`penctl delays`).

pub mod args;
pub mod delays;
pub mod device;
pub mod file;
pub mod fit;
pub mod pivot;
pub mod plot;
pub mod procedure;
pub mod run;

pub use device::{DeviceId, SIMULATED_ID, default_path, default_path_for, default_path_for_source, default_sim_path};
pub use file::{FILE_VERSION, FILE_VERSION_BOUND, FILE_VERSION_UNBOUND};
pub use fit::{Calibration, CalibrationError, DisplaySize, FitKind, MIN_TARGETS, TargetResidual, Transform, fit};
