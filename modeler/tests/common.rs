//! What the command-line test modules share: penmodel run in a folder, the examples' paths, and
//! the outside checkers in `scripts/` run against penmodel.

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

/// Runs `scripts/SCRIPT` with python3 and `args` (an outside checker: GDAL, the Khronos glTF
/// validator), asserting it passed. Exit 77 means its tools could not be installed: the test
/// `name` is then skipped, saying so, as when python3 itself cannot run.
pub fn outside_check(name: &str, script: &str, args: &[&std::ffi::OsStr]) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts").join(script);
    let out = match Command::new("python3").arg(&script).args(args).output() {
        Ok(out) => out,
        Err(e) => {
            eprintln!("SKIPPED {name}: python3 cannot run ({e})");
            return;
        }
    };
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    if out.status.code() == Some(77) {
        eprintln!("SKIPPED {name}: {text}");
        return;
    }
    assert!(out.status.success(), "{text}");
    assert!(text.contains("all checks passed"), "{text}");
}
