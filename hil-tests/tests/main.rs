//! The integration tests of pen-hil, in one binary: a module per area.
mod architecture;
mod demo_session;
mod faults;
mod flashing;
mod head;
mod hil;
mod pty;
mod qemu;
mod rig;
mod serial;
