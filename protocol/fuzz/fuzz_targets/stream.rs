//! Any bytes as the serial link's stream, through the frame decoder.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| pen_protocol::fuzzing::stream(data));
