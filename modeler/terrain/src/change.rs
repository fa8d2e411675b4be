//! What part of a document a change touched: the scope the terrain engine regenerates.
//!
//! The editor applies an edit to the document and describes the result as a [`Scope`]; the
//! engine ([`crate::engine::TerrainEngine::update`]) reads the changed part from the document.
//! Neither needs the other's vocabulary: the engine never sees an edit.

use crate::address::FigurePath;

/// A list of figures: a top-level region's, or the nested figures of a closed figure.
#[derive(Debug, Clone, PartialEq)]
pub enum FigureList {
    /// The figures of top-level region N.
    Region(usize),
    /// The figures nested in this closed figure.
    Nested(FigurePath),
}

impl FigureList {
    /// The list that holds the figure at `path`.
    pub fn of(path: &FigurePath) -> FigureList {
        match path.parent() {
            None => FigureList::Region(path.region()),
            Some(p) => FigureList::Nested(p),
        }
    }
}

/// What changed in one figure list; the index is the figure's in the list after the change
/// (before it, for a removal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ListChange {
    /// A figure was inserted at this index.
    Added(usize),
    /// The figure at this index was removed.
    Removed(usize),
    /// The figure and its nested figures were replaced.
    Replaced(usize),
    /// Only the figure's own points changed; its nested figures are as they were.
    Outline(usize),
}

/// The part of a document that one change touched.
#[derive(Debug, Clone, PartialEq)]
pub enum Scope {
    /// Only this figure's height.
    Height(FigurePath),
    /// Only this figure's slope.
    Slope(FigurePath),
    /// A change in one figure list.
    Figures(FigureList, ListChange),
    /// Top-level region N was inserted.
    RegionAdded(usize),
    /// Top-level region N was removed.
    RegionRemoved(usize),
    /// Top-level region N and its figures were replaced.
    RegionReplaced(usize),
    /// Only top-level region N's boundary changed.
    RegionOutline(usize),
    /// Rock field N was added, removed, moved or replaced: the terrain is unchanged (rocks stand
    /// on it; [`crate::rocks::cache::Rocks`] follows the document).
    Rocks(usize),
    /// River N was added, removed or changed: the engine reprocesses it and recarves only its
    /// window ([`crate::river::layer::Layer`]).
    Rivers(usize),
    /// The `ridges` entry changed: the ridge layer ([`crate::ridge::layer::Layer`]) compares
    /// each ridgeline and tree with the last it saw and re-rasterises only those that differ.
    Ridges,
    /// A tree or grove was added, removed, moved or replaced: the terrain is unchanged (trees
    /// stand on it; [`crate::trees::Forest`] follows the document).
    Trees,
}
