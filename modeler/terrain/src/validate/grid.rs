//! The grid: at least one cell, a cell size within [[`MIN_CELL_SIZE`], [`MAX_CELL_SIZE`]] m, at
//! most [`MAX_CELLS`] cells.

use thiserror::Error;

use super::{MAX_CELL_SIZE, MAX_CELLS, MIN_CELL_SIZE, Num, ValidationError};
use crate::document::Grid;

/// What is wrong with the grid.
#[allow(missing_docs)] // fields named for what they hold; the message shows them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GridDefect {
    /// The grid has no cells.
    #[error("the grid needs at least one column and one row")]
    EmptyGrid,
    /// A cell size (the grid's, a rock field's) not within [[`MIN_CELL_SIZE`],
    /// [`MAX_CELL_SIZE`]] metres (or not finite).
    #[error("the cell size must be between {} and {} m, got {}", Num(MIN_CELL_SIZE), Num(MAX_CELL_SIZE), Num(*.0))]
    CellSize(f64),
    /// The grid has more cells than [`MAX_CELLS`].
    #[error("{cells} cells is more than the {max} this build can hold in memory")]
    GridTooLarge { cells: u64, max: u64 },
}

/// Checks the grid.
pub fn grid(g: &Grid) -> Result<(), ValidationError> {
    if g.cols == 0 || g.rows == 0 {
        return Err(ValidationError::new("grid", GridDefect::EmptyGrid));
    }
    if !(MIN_CELL_SIZE..=MAX_CELL_SIZE).contains(&g.cell_size) {
        return Err(ValidationError::new(
            "grid.cell_size",
            GridDefect::CellSize(g.cell_size),
        ));
    }
    let cells = u64::from(g.cols) * u64::from(g.rows);
    if cells > MAX_CELLS {
        return Err(ValidationError::new(
            "grid",
            GridDefect::GridTooLarge { cells, max: MAX_CELLS },
        ));
    }
    Ok(())
}
