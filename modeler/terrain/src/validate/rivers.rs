//! Rivers (seed 003): a course of control points on the grid, a width, depth, water amount and
//! hardness above 0, within the limits of the river's shaping.

use thiserror::Error;

use super::{Defect, Num, ValidationError, curves::points, finite};
use crate::document::Document;

/// What is wrong with a river.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RiverDefect {
    /// A river course with fewer than two control points.
    #[error("a river's course needs at least two control points, found {0}")]
    CourseTooShort(usize),
    /// A river wider than [`crate::river::MAX_WIDTH_CELLS`] cells.
    #[error("{} m is more than the {} m ({} cells) a river may be wide", Num(*width), Num(*max), crate::river::MAX_WIDTH_CELLS)]
    RiverTooWide { width: f64, max: f64 },
    /// More river iterations than [`crate::river::MAX_ITERATIONS`].
    #[error("{0} iterations is more than the {max} a river may have", max = crate::river::MAX_ITERATIONS)]
    TooManyIterations(u32),
}

/// Checks every river: at least two control points, all on the grid (a Bézier course stays
/// within its control points' hull, so the course cannot leave the grid), a width, depth, water
/// amount and hardness above 0, a width of at most [`crate::river::MAX_WIDTH_CELLS`] cells (the
/// work per course sample grows with its square), and at most [`crate::river::MAX_ITERATIONS`]
/// iterations.
pub fn rivers(doc: &Document) -> Result<(), ValidationError> {
    for (i, r) in doc.rivers.iter().enumerate() {
        let path = format!("rivers[{i}]");
        if r.points.len() < 2 {
            return Err(ValidationError::new(
                format!("{path}.points"),
                RiverDefect::CourseTooShort(r.points.len()),
            ));
        }
        points(&doc.grid, &r.points, &|k| format!("{path}.points[{k}]"))?;
        for (name, v) in [
            ("width", r.width),
            ("depth", r.depth),
            ("water", r.water),
            ("hardness", r.hardness),
        ] {
            finite(v, || format!("{path}.{name}"))?;
            if v <= 0.0 {
                return Err(ValidationError::new(format!("{path}.{name}"), Defect::NotPositive(v)));
            }
        }
        let max = crate::river::MAX_WIDTH_CELLS * doc.grid.cell_size;
        if r.width > max {
            return Err(ValidationError::new(
                format!("{path}.width"),
                RiverDefect::RiverTooWide { width: r.width, max },
            ));
        }
        if r.iterations > crate::river::MAX_ITERATIONS {
            return Err(ValidationError::new(
                format!("{path}.iterations"),
                RiverDefect::TooManyIterations(r.iterations),
            ));
        }
    }
    Ok(())
}
