//! Any bytes as a HID input or feature report (or a serial frame's payload).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| pen_protocol::fuzzing::message(data));
