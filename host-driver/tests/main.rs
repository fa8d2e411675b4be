//! The integration tests of pen-host, in one binary: a module per area.
mod calibration;
mod common;
mod daemon;
mod delays;
mod events;
mod fuzz_corpus;
mod head;
mod install;
mod penctl;
mod pend_faults;
mod reliability_doc;
mod socket;
// The docs' generated sections, one helper with pen-protocol's docs test.
#[path = "../../protocol/tests/common/splice.rs"]
mod splice;
mod vocabulary;
mod waiting;
