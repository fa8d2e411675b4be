//! The integration tests of this crate, one binary: each module is one former test file.
mod common;
mod docs;
mod editing;
mod equations;
mod examples;
mod exports;
mod properties;
mod validation;
