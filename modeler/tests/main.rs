//! The integration tests of this crate, one binary: each module is one former test file.
mod cli;
mod demo_cli;
mod interaction;
