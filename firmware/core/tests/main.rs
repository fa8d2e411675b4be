//! The integration tests of this crate, one binary: each module is one former test file.
mod common;
mod debounce;
mod engine;
mod filter;
mod solver;
mod station;
mod store;
