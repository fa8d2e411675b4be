//! Any bytes as a calibration file.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| pen_host::fuzzing::calibration(data));
