//! Any bytes as a replay file, its cycles through the engine.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| pen_core::fuzzing::replay(data));
