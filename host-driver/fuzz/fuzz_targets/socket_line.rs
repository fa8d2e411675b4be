//! Any bytes as a line from pend's socket, as a client reads it.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| pen_host::fuzzing::socket_line(data));
