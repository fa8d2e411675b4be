//! The integration tests of this crate, one binary: each module is one former test file.
mod demo_session;
mod hil;
mod pty;
mod qemu;
mod serial;
