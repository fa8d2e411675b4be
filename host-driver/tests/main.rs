//! The integration tests of this crate, one binary: each module is one former test file.
mod calibration;
mod daemon;
mod events;
mod penctl;
