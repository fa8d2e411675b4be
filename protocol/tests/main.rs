//! The integration tests of pen-protocol, in one binary: a module per area.
mod common;
mod descriptor;
mod docs;
mod errors;
mod frames;
mod fuzz_corpus;
mod golden;
mod head;
#[cfg(feature = "serde")]
mod json;
mod reset;
mod roundtrip;
