//! The integration tests of this crate, one binary: each module is one former test file.
mod outputs;
mod render;
