//! The integration tests of penmodel-terrain, in one binary: a module per area.
mod baseline;
mod common;
mod docs;
mod editing;
mod equations;
mod examples;
mod exports;
mod faults;
mod fuzz_corpus;
mod limits;
mod properties;
mod ridges;
mod rivers;
mod rock_fields;
mod rocks;
mod validation;
