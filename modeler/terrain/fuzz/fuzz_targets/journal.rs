//! Any bytes as a document's journal, after its `open` line.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| penmodel_terrain::fuzzing::journal(data));
