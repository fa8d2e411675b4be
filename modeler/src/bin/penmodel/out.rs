//! Writing a subcommand's output file, `-` meaning standard output.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};

/// The heights `lo` to `hi` in whole metres, as "0 to 1105 m" (a carve 0.3 m deep is 0, not −0).
pub fn metres_range(lo: f32, hi: f32) -> String {
    format!("{:.0} to {:.0} m", lo.round() + 0.0, hi.round() + 0.0)
}

/// Writes what `f` writes to `path` (standard output for `-`) through a buffer, so that a large
/// result streams rather than being held whole.
pub fn write_with(path: &Path, f: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    if path == Path::new("-") {
        let mut out = std::io::BufWriter::new(std::io::stdout().lock());
        f(&mut out).and_then(|()| out.flush()).context("cannot write to stdout")
    } else {
        let file = std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?;
        let mut out = std::io::BufWriter::new(file);
        f(&mut out)
            .and_then(|()| out.flush())
            .with_context(|| format!("cannot write {}", path.display()))
    }
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
