//! Writing a subcommand's output file, `-` meaning standard output.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

/// The heights `lo` to `hi` in whole metres, as "0 to 1105 m" (a carve 0.3 m deep is 0, not −0).
pub fn metres_range(lo: f32, hi: f32) -> String {
    format!("{:.0} to {:.0} m", lo.round() + 0.0, hi.round() + 0.0)
}

/// Writes `bytes` to `path`, or to standard output when `path` is `-`.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    if path == Path::new("-") {
        let mut out = std::io::stdout().lock();
        out.write_all(bytes)?;
        return out.flush().context("cannot write to stdout");
    }
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}
