//! Replays a fuzz target's corpus through the target's property on stable: one copy for every
//! crate with fuzz targets (pen-protocol, pen-host, penmodel-terrain), whose corpus tests include
//! this file by path (docs/reliability.md).

use std::fs;
use std::path::Path;

/// Runs every file of `crate_dir/fuzz/corpus/target` through `property`; returns how many there
/// were. A failing file is named, so it can be run alone with `cargo fuzz run <target> <file>`.
pub fn replay(crate_dir: &str, target: &str, property: fn(&[u8])) -> usize {
    let dir = Path::new(crate_dir).join("fuzz/corpus").join(target);
    let mut n = 0;
    for entry in fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("corpus entry").path();
        let bytes = fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if let Err(panic) = std::panic::catch_unwind(|| property(&bytes)) {
            panic!("{}: {panic:?}", path.display());
        }
        n += 1;
    }
    n
}
