//! A calibration's display and targets as command-line arguments: one definition for
//! `penctl calibrate` and `penmodel calibrate` (flattened into each with `#[command(flatten)]`).

use super::DisplaySize;

/// `--targets`, `--display-mm`, `--display-px`.
#[derive(Debug, Clone, clap::Args)]
pub struct DisplayArgs {
    /// Targets: 4 (corners), 5 (and the centre) or 9 (a 3 × 3 grid).
    #[arg(long, default_value_t = 5, value_parser = target_count)]
    pub targets: u8,
    /// The display's active area, mm.
    #[arg(long, value_name = "WxH", default_value = "600x340", value_parser = size::<f64>)]
    pub display_mm: (f64, f64),
    /// The display's resolution.
    #[arg(long, value_name = "WxH", default_value = "2560x1440", value_parser = size::<u32>)]
    pub display_px: (u32, u32),
}

impl DisplayArgs {
    /// The display the arguments give (not yet checked: [`DisplaySize::check`]).
    pub fn display(&self) -> DisplaySize {
        let ((width_mm, height_mm), (width_px, height_px)) = (self.display_mm, self.display_px);
        DisplaySize {
            width_mm,
            height_mm,
            width_px,
            height_px,
        }
    }
}

/// `WIDTHxHEIGHT`, for clap (a usage error otherwise).
fn size<T: std::str::FromStr>(s: &str) -> Result<(T, T), String> {
    s.split_once(['x', 'X', '×'])
        .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, such as 600x340, got {s:?}"))
}

/// The target counts, for clap: any other is refused, not rounded to one of these.
fn target_count(s: &str) -> Result<u8, String> {
    match s.trim().parse::<u8>() {
        Ok(n @ (4 | 5 | 9)) => Ok(n),
        _ => Err("a calibration has 4 targets (the corners), 5 (and the centre) or 9 (a 3 × 3 grid)".into()),
    }
}
