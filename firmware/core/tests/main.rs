//! The integration tests of pen-core, in one binary: a module per area.
mod board;
mod common;
mod debounce;
mod filter;
mod fuzz_corpus;
mod head;
mod replay;
mod report;
mod reset;
mod solve;
mod station;
mod store;
