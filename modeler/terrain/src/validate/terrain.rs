//! The terrain settings: fractal detail and thermal erosion (`docs/document.md`).

use thiserror::Error;

use super::{Num, ValidationError, finite};
use crate::document::{Document, Fluvial};

/// What is wrong with a terrain setting.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TerrainDefect {
    /// A terrain setting (`terrain.detail`, `terrain.erosion`) out of its range.
    #[error("{what} must be {range}, got {}", Num(*value))]
    DetailRange {
        what: &'static str,
        range: String,
        value: f64,
    },
}

/// The most octaves of fractal detail: the twelfth's wavelength is 1/2048 of the first's.
pub const MAX_DETAIL_OCTAVES: u32 = 12;

/// The most steps of thermal erosion: each moves material one cell, and a local change
/// recomputes a window grown by twice the steps.
pub const MAX_EROSION_ITERATIONS: u32 = 200;

/// Checks the terrain settings' fractal detail (`docs/document.md`): an amount from 0 to 1, a
/// scale (the longest wavelength) of at least two cells — a shorter one would alias on the grid
/// — and at most 10 000 km, and 1 to [`MAX_DETAIL_OCTAVES`] octaves; and the thermal erosion
/// ([`erosion`]). (The metric's names are checked when the text is read.)
pub fn terrain(doc: &Document) -> Result<(), ValidationError> {
    erosion(doc)?;
    let Some(d) = &doc.terrain.detail else { return Ok(()) };
    let range = |what: &'static str, range: String, value: f64| {
        Err(ValidationError::new(
            format!("terrain.detail.{}", what.rsplit(' ').next().unwrap_or(what)),
            TerrainDefect::DetailRange { what, range, value },
        ))
    };
    finite(d.amount, || "terrain.detail.amount".into())?;
    finite(d.scale, || "terrain.detail.scale".into())?;
    if !(0.0..=1.0).contains(&d.amount) {
        return range("the detail's amount", "from 0 to 1".into(), d.amount);
    }
    let min_scale = 2.0 * doc.grid.cell_size;
    if !(min_scale..=1e7).contains(&d.scale) {
        return range(
            "the detail's scale",
            format!("from {} m (two cells) to 10 000 km", Num(min_scale)),
            d.scale,
        );
    }
    if !(1..=MAX_DETAIL_OCTAVES).contains(&d.octaves) {
        return range(
            "the detail's octaves",
            format!("from 1 to {MAX_DETAIL_OCTAVES}"),
            f64::from(d.octaves),
        );
    }
    Ok(())
}

/// Checks the terrain settings' thermal erosion: a talus angle from 1° to 89°, 0 (no thermal
/// pass) to [`MAX_EROSION_ITERATIONS`] steps, an amount from 0 to 1.
pub fn erosion(doc: &Document) -> Result<(), ValidationError> {
    let Some(e) = &doc.terrain.erosion else { return Ok(()) };
    let range = |what: &'static str, range: String, value: f64| {
        Err(ValidationError::new(
            format!("terrain.erosion.{}", what.rsplit(' ').next().unwrap_or(what)),
            TerrainDefect::DetailRange { what, range, value },
        ))
    };
    finite(e.talus, || "terrain.erosion.talus".into())?;
    finite(e.amount, || "terrain.erosion.amount".into())?;
    if !(1.0..=89.0).contains(&e.talus) {
        return range("the erosion's talus", "from 1 to 89 degrees".into(), e.talus);
    }
    if e.iterations > MAX_EROSION_ITERATIONS {
        return range(
            "the erosion's iterations",
            format!("from 0 to {MAX_EROSION_ITERATIONS}"),
            f64::from(e.iterations),
        );
    }
    if !(0.0..=1.0).contains(&e.amount) {
        return range("the erosion's amount", "from 0 to 1".into(), e.amount);
    }
    match &e.fluvial {
        Some(f) => fluvial(f),
        None => Ok(()),
    }
}

/// The most steps of fluvial erosion: each re-routes the whole grid.
pub const MAX_FLUVIAL_STEPS: u32 = 5000;

/// Checks the fluvial erosion's settings against the ranges `docs/erosion.md` gives.
fn fluvial(f: &Fluvial) -> Result<(), ValidationError> {
    let checks: [(&'static str, f64, f64, f64); 8] = [
        ("dt", f.dt, 1.0, 1e6),
        ("k", f.k, 0.0, 1.0),
        ("m", f.m, 0.0, 2.0),
        ("n", f.n, 0.5, 4.0),
        ("diffusion", f.diffusion.unwrap_or(0.0), 0.0, 100.0),
        ("response", f.response, f.dt.max(1.0), 1e9),
        ("noise", f.noise, 0.0, 100.0),
        ("steps", f64::from(f.steps), 1.0, f64::from(MAX_FLUVIAL_STEPS)),
    ];
    for (name, value, lo, hi) in checks {
        let path = || format!("terrain.erosion.fluvial.{name}");
        finite(value, path)?;
        if !(lo..=hi).contains(&value) {
            return Err(ValidationError::new(
                path(),
                TerrainDefect::DetailRange {
                    what: name,
                    range: format!("from {} to {}", Num(lo), Num(hi)),
                    value,
                },
            ));
        }
    }
    Ok(())
}
