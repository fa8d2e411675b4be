//! What the command-line test modules share: penmodel run in a folder, and the examples' paths.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs penmodel with `args` in `dir` (never on a display: the tests are headless) and returns
/// what it did.
pub fn penmodel(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penmodel"))
        .current_dir(dir)
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("penmodel runs")
}

/// The path of `modeler/examples/NAME`.
pub fn example(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
        .display()
        .to_string()
}
