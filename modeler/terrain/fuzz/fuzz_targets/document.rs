//! Any bytes as a document file.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| penmodel_terrain::fuzzing::document(data));
