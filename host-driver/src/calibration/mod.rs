//! Calibration: the transform from the tracker frame to the display frame.
//!
//! * [`fit`]: the transform from touched targets (Horn's closed form), display sizes and
//!   display coordinates.
//! * [`file`]: the calibration file, `~/.config/penscape/calibration.toml`.
//! * [`procedure`]: leading the user (or the simulated pen) through the targets.
//! * [`plot`]: the residuals as a PNG.

pub mod file;
pub mod fit;
pub mod plot;
pub mod procedure;

pub use file::{FILE_VERSION, default_path};
pub use fit::{Calibration, CalibrationError, DisplaySize, FitKind, MIN_TARGETS, TargetResidual, Transform, fit};
