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
    /// The base heightmap's (`terrain.base`): not found, not readable, not of the grid's size.
    #[error("{0}")]
    Base(String),
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
    base(doc)?;
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

/// Checks the base heightmap's entry: a path, a PNG range of finite numbers given whole (both
/// or neither, `min` ≤ `max`), and loaded heights, if any, of the grid's size, every one finite.
pub fn base(doc: &Document) -> Result<(), ValidationError> {
    let Some(b) = &doc.terrain.base else { return Ok(()) };
    let defect = |path: &str, m: String| Err(ValidationError::new(path, TerrainDefect::Base(m)));
    if b.path.trim().is_empty() {
        return defect("terrain.base.path", "the base heightmap's path is empty".into());
    }
    if let Some(min) = b.min {
        finite(min, || "terrain.base.min".into())?;
    }
    if let Some(max) = b.max {
        finite(max, || "terrain.base.max".into())?;
    }
    match (b.min, b.max) {
        (Some(min), Some(max)) if min > max => {
            return defect(
                "terrain.base.max",
                format!("max ({}) is below min ({})", Num(max), Num(min)),
            );
        }
        (Some(_), None) | (None, Some(_)) => {
            return defect("terrain.base", "give both min and max, or neither".into());
        }
        _ => {}
    }
    if let Some(h) = b.heights.get() {
        if h.len() != doc.grid.cells() {
            return defect(
                "terrain.base",
                format!("{} heights loaded for the grid's {} cells", h.len(), doc.grid.cells()),
            );
        }
        if let Some(i) = h.iter().position(|v| !v.is_finite()) {
            return defect(
                "terrain.base",
                format!("the base height of cell {i} is not a finite number"),
            );
        }
    }
    Ok(())
}

/// Checks that a document's base heightmap, if it has one, is loaded: the terrain needs its
/// heights, which only a document read from its file ([`crate::Document::load`]) or given them
/// ([`crate::import::load_base`]) has.
pub fn base_loaded(doc: &Document) -> Result<(), ValidationError> {
    match &doc.terrain.base {
        Some(b) if b.heights.get().is_none() => Err(ValidationError::new(
            "terrain.base",
            TerrainDefect::Base(format!(
                "the base heightmap {} is not loaded: read the document from its file",
                b.path
            )),
        )),
        _ => Ok(()),
    }
}
