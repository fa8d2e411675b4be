//! Trees and groves (seed 004): on the grid, a height in range, a known preset or their own IFS
//! maps that contract, and wind within range; a grove's region a closed curve and its expected
//! trees and sampling image within their limits.

use thiserror::Error;

use super::{
    Defect, Num, ValidationError,
    curves::{points, ring},
    finite,
};
use crate::document::Document;

/// What is wrong with a tree or a grove.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TreeDefect {
    /// A tree preset no build knows.
    #[error("unknown preset {_0:?}; the presets are {names}", names = crate::trees::Preset::names())]
    UnknownPreset(String),
    /// A tree with both a preset and its own maps.
    #[error("give either a preset or maps, not both")]
    PresetAndMaps,
    /// A tree with no maps or more than [`crate::trees::species::MAX_MAPS`].
    #[error("a tree needs 1 to {max} maps, found {_0}", max = crate::trees::species::MAX_MAPS)]
    MapCount(usize),
    /// An IFS map that does not contract.
    #[error("|s| = {} is not below 1: the IFS does not contract", Num(*_0))]
    NotContracting(f64),
    /// A species with more branches down to 2 % of its height than a tree may have.
    #[error(
        "the tree would have more than {} branches down to 2 % of its height: use smaller scales or fewer maps",
        crate::trees::nodes::MAX_NODES
    )]
    TooManyBranches,
    /// A tree height out of range.
    #[error("a tree's height must be above 0 and at most {} m, got {}", Num(crate::trees::MAX_HEIGHT), Num(*_0))]
    TreeHeight(f64),
    /// Wind without a generation.
    #[error("wind needs at least one generation (amplitude, frequency)")]
    NoGenerations,
    /// A grove whose expected trees are too many.
    #[error("{} trees per hectare over {} m² is about {} trees, more than the {} a grove may have", Num(*density), Num(*area), Num(*trees), Num(*max))]
    GroveTooDense {
        density: f64,
        area: f64,
        trees: f64,
        max: f64,
    },
    /// A grove whose sampling image would be too large.
    #[error(
        "the grove's sampling image would be {width} × {height} pixels, more than {max}: use a smaller region or a lower density"
    )]
    GroveTooLarge { width: u32, height: u32, max: u64 },
}

/// Checks every tree: on the grid, a height in (0, [`crate::trees::MAX_HEIGHT`]] m, a known
/// preset or its own maps ([`species`]), and its wind (`wind`).
pub fn trees(doc: &Document) -> Result<(), ValidationError> {
    for (i, t) in doc.trees.iter().enumerate() {
        let path = format!("trees[{i}]");
        points(&doc.grid, &[t.at], &|_| format!("{path}.at"))?;
        tree_height(t.height, || format!("{path}.height"))?;
        match (&t.preset, &t.maps) {
            (Some(_), Some(_)) => return Err(ValidationError::new(path, TreeDefect::PresetAndMaps)),
            (Some(p), None) => preset(p, || format!("{path}.preset"))?,
            (None, Some(maps)) => species(maps, &format!("{path}.maps"))?,
            (None, None) => {}
        }
        if let Some(w) = &t.wind {
            wind(w, &format!("{path}.wind"))?;
        }
    }
    Ok(())
}

/// Checks every grove: its region (a closed curve on the grid), a density above 0 with at most
/// [`crate::trees::grove::MAX_TREES`] expected trees and a sampling image of at most
/// [`crate::trees::grove::MAX_PIXELS`] pixels, known presets with weights above 0, a height in
/// (0, [`crate::trees::MAX_HEIGHT`]] m, and its wind.
pub fn groves(doc: &Document) -> Result<(), ValidationError> {
    use crate::trees::grove;
    for (i, g) in doc.groves.iter().enumerate() {
        let path = format!("groves[{i}]");
        ring(
            &doc.grid,
            &g.region,
            |k| format!("{path}.region[{k}]"),
            &format!("{path}.region"),
        )?;
        finite(g.density, || format!("{path}.density"))?;
        if g.density <= 0.0 {
            return Err(ValidationError::new(
                format!("{path}.density"),
                Defect::NotPositive(g.density),
            ));
        }
        let area = grove::area(&g.region);
        let expected = g.density / 10_000.0 * area;
        if expected > grove::MAX_TREES {
            let defect = TreeDefect::GroveTooDense {
                density: g.density,
                area,
                trees: expected.round(),
                max: grove::MAX_TREES,
            };
            return Err(ValidationError::new(format!("{path}.density"), defect));
        }
        let (_, width, height) = grove::image(g);
        if u64::from(width) * u64::from(height) > grove::MAX_PIXELS {
            let defect = TreeDefect::GroveTooLarge {
                width,
                height,
                max: grove::MAX_PIXELS,
            };
            return Err(ValidationError::new(format!("{path}.density"), defect));
        }
        for (k, m) in g.mix.iter().enumerate() {
            preset(&m.preset, || format!("{path}.mix[{k}].preset"))?;
            finite(m.weight, || format!("{path}.mix[{k}].weight"))?;
            if m.weight <= 0.0 {
                return Err(ValidationError::new(
                    format!("{path}.mix[{k}].weight"),
                    Defect::NotPositive(m.weight),
                ));
            }
        }
        tree_height(g.height, || format!("{path}.height"))?;
        if let Some(w) = &g.wind {
            wind(w, &format!("{path}.wind"))?;
        }
    }
    Ok(())
}

fn tree_height(h: f64, path: impl Fn() -> String) -> Result<(), ValidationError> {
    finite(h, &path)?;
    if h <= 0.0 || h > crate::trees::MAX_HEIGHT {
        return Err(ValidationError::new(path(), TreeDefect::TreeHeight(h)));
    }
    Ok(())
}

fn preset(name: &str, path: impl Fn() -> String) -> Result<(), ValidationError> {
    match crate::trees::Preset::named(name) {
        Some(_) => Ok(()),
        None => Err(ValidationError::new(path(), TreeDefect::UnknownPreset(name.to_owned()))),
    }
}

/// Checks a tree's own IFS maps (`path` names the list): 1 to
/// [`crate::trees::species::MAX_MAPS`] maps, finite numbers, `0 ≤ y ≤ 1`, `0 < s < 1` (a
/// contraction), and at most [`crate::trees::nodes::MAX_NODES`] branches down to 2 % of the
/// tree's height.
pub fn species(maps: &[crate::document::IfsMap], path: &str) -> Result<(), ValidationError> {
    use crate::trees::{Species, nodes, species::MAX_MAPS};
    if maps.is_empty() || maps.len() > MAX_MAPS {
        return Err(ValidationError::new(path, TreeDefect::MapCount(maps.len())));
    }
    for (k, m) in maps.iter().enumerate() {
        for (name, v) in [("y", m.y), ("s", m.s), ("theta_z", m.theta_z), ("theta_y", m.theta_y)] {
            finite(v, || format!("{path}[{k}].{name}"))?;
        }
        if !(0.0..=1.0).contains(&m.y) {
            let defect = Defect::Coefficient {
                value: m.y,
                min: 0.0,
                max: 1.0,
            };
            return Err(ValidationError::new(format!("{path}[{k}].y"), defect));
        }
        if m.s.abs() >= 1.0 {
            return Err(ValidationError::new(
                format!("{path}[{k}].s"),
                TreeDefect::NotContracting(m.s.abs()),
            ));
        }
        if m.s <= 0.0 {
            return Err(ValidationError::new(format!("{path}[{k}].s"), Defect::NotPositive(m.s)));
        }
    }
    let sp = Species { maps: maps.to_vec() };
    if nodes::count_nodes(&sp, nodes::STOP, nodes::MAX_NODES).is_none() {
        return Err(ValidationError::new(path, TreeDefect::TooManyBranches));
    }
    Ok(())
}

/// Checks wind: a finite direction, at least one generation, amplitudes and rest leans within
/// ±[`crate::trees::wind::MAX_LEAN`]°, frequencies from 0 to [`crate::trees::wind::MAX_FREQUENCY`] Hz.
fn wind(w: &crate::document::Wind, path: &str) -> Result<(), ValidationError> {
    use crate::trees::wind::{MAX_FREQUENCY, MAX_LEAN};
    finite(w.direction, || format!("{path}.direction"))?;
    if w.generations.is_empty() {
        return Err(ValidationError::new(
            format!("{path}.generations"),
            TreeDefect::NoGenerations,
        ));
    }
    for (g, s) in w.generations.iter().enumerate() {
        for (name, v, min, max) in [
            ("amplitude", s.amplitude, -MAX_LEAN, MAX_LEAN),
            ("rest", s.rest, -MAX_LEAN, MAX_LEAN),
            ("frequency", s.frequency, 0.0, MAX_FREQUENCY),
        ] {
            let at = || format!("{path}.generations[{g}].{name}");
            finite(v, at)?;
            if !(min..=max).contains(&v) {
                return Err(ValidationError::new(at(), Defect::Coefficient { value: v, min, max }));
            }
        }
    }
    Ok(())
}
