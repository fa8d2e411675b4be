//! The integration tests of this crate, one binary: each module is one former test file.
mod common;
mod descriptor;
mod docs;
mod errors;
mod frames;
mod golden;
mod roundtrip;
