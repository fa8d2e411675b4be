//! Rock fields (seed 001): an outline (a closed curve on the grid, relative to the field's
//! `at`), a cell size and image size, layers within the ranges of
//! [`crate::rocks::Recipe::check`], and a place in a region.

use thiserror::Error;

use super::{Defect, GridDefect, MAX_CELL_SIZE, MIN_CELL_SIZE, Num, ValidationError, curves::ring, finite};
use crate::document::Document;
use crate::geometry::{self, Side};

/// What is wrong with a rock field.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RockDefect {
    /// A rock field whose outline is in no top-level region.
    #[error("lies outside every region: draw the field inside a region")]
    OutsideEveryRegion,
    /// A rock field's image would be too large.
    #[error("the field would be {width} × {height} cells of its cell size, more than {max}: use a larger cell_size")]
    FieldTooLarge { width: f64, height: f64, max: u64 },
    /// A rock field without layers.
    #[error("a rock field needs at least one layer (a radius and a fraction or count)")]
    NoLayers,
    /// A radius that is not above 0.
    #[error("{} must be above 0", Num(*_0))]
    RadiusNotPositive(f64),
    /// A radius with no room for a rock in its field.
    #[error("{} cells leaves no room for one rock in the field's {width} × {height} cells", Num(*radius))]
    NoRoom { radius: f64, width: u32, height: u32 },
    /// A layer with both or neither of fraction and count.
    #[error("give either a fraction or a count")]
    FractionOrCount,
    /// A fraction outside [0, 1].
    #[error("{} must be from 0 to 1", Num(*_0))]
    FractionRange(f64),
    /// A field's fractions summing over 1.
    #[error("the fractions add up to {}, more than the whole field (1)", Num(*_0))]
    FractionsOverOne(f64),
}

/// Checks every rock field: its outline (a closed curve on the grid, relative to `at`), its cell
/// size and image size, its layers (the ranges of [`crate::rocks::Recipe::check`]), and that it
/// lies in a region (at least one of its vertices inside a top-level region).
pub fn rock_fields(doc: &Document) -> Result<(), ValidationError> {
    use crate::rocks::{self, RecipeError};
    for (i, f) in doc.rocks.iter().enumerate() {
        let path = format!("rocks[{i}]");
        finite(f.at[0], || format!("{path}.at"))?;
        finite(f.at[1], || format!("{path}.at"))?;
        if !(MIN_CELL_SIZE..=MAX_CELL_SIZE).contains(&f.cell_size) {
            return Err(ValidationError::new(
                format!("{path}.cell_size"),
                GridDefect::CellSize(f.cell_size),
            ));
        }
        let outline = f.outline_at();
        ring(
            &doc.grid,
            &outline,
            |k| format!("{path}.outline[{k}]"),
            &format!("{path}.outline"),
        )?;
        let (width, height, _) = rocks::field::extent(f);
        if width * height > rocks::MAX_PIXELS as f64 {
            let max = rocks::MAX_PIXELS;
            return Err(ValidationError::new(
                format!("{path}.cell_size"),
                RockDefect::FieldTooLarge { width, height, max },
            ));
        }
        if f.layers.is_empty() {
            return Err(ValidationError::new(format!("{path}.layers"), RockDefect::NoLayers));
        }
        for (k, l) in f.layers.iter().enumerate() {
            if l.fraction.is_some() == l.count.is_some() {
                return Err(ValidationError::new(
                    format!("{path}.layers[{k}]"),
                    RockDefect::FractionOrCount,
                ));
            }
        }
        let recipe = rocks::field::recipe(f, width as u32, height as u32);
        if let Err(e) = recipe.check() {
            let layer = |k: usize, what: &str| format!("{path}.layers[{k}].{what}");
            let (at, defect): (String, Defect) = match e {
                RecipeError::FieldSize { .. } | RecipeError::Fill(_) => (
                    format!("{path}.cell_size"),
                    RockDefect::FieldTooLarge {
                        width,
                        height,
                        max: rocks::MAX_PIXELS,
                    }
                    .into(),
                ),
                RecipeError::NoLayers => (format!("{path}.layers"), RockDefect::NoLayers.into()),
                RecipeError::RadiusNotPositive { layer: k, radius } => {
                    (layer(k, "radius"), RockDefect::RadiusNotPositive(radius).into())
                }
                RecipeError::RadiusTooLarge {
                    layer: k,
                    radius,
                    width,
                    height,
                } => (layer(k, "radius"), RockDefect::NoRoom { radius, width, height }.into()),
                RecipeError::FractionRange { layer: k, fraction } => {
                    (layer(k, "fraction"), RockDefect::FractionRange(fraction).into())
                }
                RecipeError::FractionsOverOne { sum } => {
                    (format!("{path}.layers"), RockDefect::FractionsOverOne(sum).into())
                }
                RecipeError::ShapeRange {
                    layer: k,
                    what,
                    value,
                    min,
                    max,
                } => {
                    let (list, n) = match what {
                        "c_w1" => ("widths", 0),
                        "c_w2" => ("widths", 1),
                        "c_w3" => ("widths", 2),
                        "c_h1" => ("heights", 0),
                        "c_h2" => ("heights", 1),
                        _ => ("heights", 2),
                    };
                    (
                        layer(k, &format!("{list}[{n}]")),
                        Defect::Coefficient { value, min, max },
                    )
                }
            };
            return Err(ValidationError::new(at, defect));
        }
        let in_a_region = doc.regions.iter().any(|r| {
            outline
                .iter()
                .any(|&p| geometry::locate(&r.boundary, p) == Side::Inside)
        });
        if !in_a_region {
            return Err(ValidationError::new(path, RockDefect::OutsideEveryRegion));
        }
    }
    Ok(())
}
