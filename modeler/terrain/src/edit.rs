//! Edits of a document: what the pen does to it (add, delete and move figures and single points,
//! set a figure's height or slope) and their inverses, for undo.
//!
//! Applying an edit checks the result and leaves the document unchanged when it would not be
//! valid. Every edit has an inverse that restores the exact previous document (moves are undone
//! by restoring the old points, not by moving back, which could round differently).

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::address::{CurvePath, FigurePath};
use crate::cells::{self, Mask};
use crate::change::{FigureList, ListChange, Scope};
use crate::document::{Document, Figure, FigureKind, Grove, Point, Region, Ridges, River, RockField, Tree};
use crate::validate::{self, ValidationError};

/// One change to a document. Serialised (in the journal) as an object tagged by `"op"`.
#[allow(missing_docs)] // fields named for what they hold; each variant says what it does with them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Edit {
    /// Inserts a top-level region at `index`.
    AddRegion { index: usize, region: Region },
    /// Removes top-level region `index` and its figures.
    DeleteRegion { index: usize },
    /// Moves a region and its figures by `by` metres.
    MoveRegion {
        index: usize,
        /// Displacement `[dx, dy]`.
        by: Point,
    },
    /// Replaces a region and its figures.
    ReplaceRegion { index: usize, region: Region },
    /// Inserts a figure so that it ends up at `at`.
    AddFigure { at: FigurePath, figure: Figure },
    /// Removes a figure and everything nested in it.
    DeleteFigure { at: FigurePath },
    /// Moves a figure and everything nested in it by `by` metres.
    MoveFigure {
        at: FigurePath,
        /// Displacement `[dx, dy]`.
        by: Point,
    },
    /// Replaces a figure and everything nested in it.
    ReplaceFigure { at: FigurePath, figure: Figure },
    /// Moves one vertex of a curve. For a closed curve vertex 0 is both its first and last point.
    MovePoint { curve: CurvePath, index: usize, to: Point },
    /// Inserts a vertex before vertex `index` (`index` = vertex count appends).
    InsertPoint {
        curve: CurvePath,
        index: usize,
        point: Point,
    },
    /// Removes one vertex.
    DeletePoint { curve: CurvePath, index: usize },
    /// Sets a figure's absolute height (a pull).
    SetHeight {
        at: FigurePath,
        /// Height in metres.
        height: f64,
    },
    /// Sets a figure's slope coefficient.
    SetSlope { at: FigurePath, slope: f64 },
    /// Several edits made by one gesture (a pull and the slope set while pulling): applied in
    /// order, undone together, one step of the history.
    Group { edits: Vec<Edit> },
    /// Inserts a rock field at `index`.
    AddRocks { index: usize, field: RockField },
    /// Removes rock field `index`.
    DeleteRocks { index: usize },
    /// Moves rock field `index` by `by` metres (its `at`): the same rocks, elsewhere.
    MoveRocks {
        index: usize,
        /// Displacement `[dx, dy]`.
        by: Point,
    },
    /// Replaces rock field `index` (its density, sizes, shapes, outline or seed).
    ReplaceRocks { index: usize, field: RockField },
    /// Inserts a river at `index`.
    AddRiver { index: usize, river: River },
    /// Removes river `index`.
    DeleteRiver { index: usize },
    /// Replaces river `index` (its course, width, depth, water, hardness or iterations).
    ReplaceRiver { index: usize, river: River },
    /// Replaces the `ridges` entry (`null` removes it): a ridgeline drawn, a node dragged, a
    /// tree grown. Only the ridgelines and trees that differ are re-rasterised.
    SetRidges { ridges: Option<Ridges> },
    /// Inserts a tree at `index`.
    AddTree { index: usize, tree: Tree },
    /// Removes tree `index`.
    DeleteTree { index: usize },
    /// Moves tree `index` by `by` metres (its `at`; it stands on the ground there).
    MoveTree {
        index: usize,
        /// Displacement `[dx, dy]`.
        by: Point,
    },
    /// Replaces tree `index` (its height, species, seed or wind).
    ReplaceTree { index: usize, tree: Tree },
    /// Inserts a grove at `index`.
    AddGrove { index: usize, grove: Grove },
    /// Removes grove `index`.
    DeleteGrove { index: usize },
    /// Moves grove `index`'s region by `by` metres.
    MoveGrove {
        index: usize,
        /// Displacement `[dx, dy]`.
        by: Point,
    },
    /// Replaces grove `index` (its region, density, mix, height, seed or wind).
    ReplaceGrove { index: usize, grove: Grove },
}

/// Why an edit was refused. The document is unchanged.
#[allow(missing_docs)] // the fields name the missing vertex.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EditError {
    /// No top-level region at that index.
    #[error("there is no regions[{0}]")]
    NoRegion(usize),
    /// No figure at that path.
    #[error("there is no {0}")]
    NoFigure(FigurePath),
    /// No vertex at that index.
    #[error("{curve} has no vertex {index}")]
    NoPoint { curve: CurvePath, index: usize },
    /// The edit would make the document invalid.
    #[error("the edit would make the document invalid: {0}")]
    Invalid(#[from] ValidationError),
    /// No rock field at that index.
    #[error("there is no rocks[{0}]")]
    NoRocks(usize),
    /// No river at that index.
    #[error("there is no rivers[{0}]")]
    NoRiver(usize),
    /// No tree at that index.
    #[error("there is no trees[{0}]")]
    NoTree(usize),
    /// No grove at that index.
    #[error("there is no groves[{0}]")]
    NoGrove(usize),
    /// [`Edit::apply_to`] was given a group, whose edits are applied one at a time.
    #[error("a group of edits is applied edit by edit")]
    Group,
}

/// An edit that was applied: how to undo it and what it touched.
#[derive(Debug, Clone, PartialEq)]
pub struct Applied {
    /// The edit that restores the document exactly.
    pub inverse: Edit,
    /// The part of the document that changed, for [`crate::engine::TerrainEngine::update`].
    pub scope: Scope,
}

/// The vertices of a curve: its points without the closing repeat.
fn vertices(points: &[Point], closed: bool) -> Vec<Point> {
    let n = if closed {
        points.len().saturating_sub(1)
    } else {
        points.len()
    };
    points[..n].to_vec()
}

fn close(mut v: Vec<Point>, closed: bool) -> Vec<Point> {
    if closed && let Some(&first) = v.first() {
        v.push(first);
    }
    v
}

impl Edit {
    /// Applies the edit to `doc`, checking the touched top-level region, and returns its inverse
    /// and scope. A refused edit leaves `doc` unchanged. A [`Edit::Group`] is refused
    /// ([`EditError::Group`]): its edits are applied one by one, each followed by its terrain
    /// update, which the [`Editor`](crate::Editor) does.
    pub fn apply_to(&self, doc: &mut Document) -> Result<Applied, EditError> {
        let applied = apply(doc, self)?;
        // A region edit must not leave a rock field outside every region (it would not load).
        if !doc.rocks.is_empty()
            && !matches!(
                self,
                Edit::AddRocks { .. } | Edit::ReplaceRocks { .. } | Edit::MoveRocks { .. }
            )
            && let Err(e) = validate::rock_fields(doc)
        {
            // The inverse restores the document exactly.
            let _ = apply(doc, &applied.inverse);
            return Err(e.into());
        }
        Ok(applied)
    }
}

/// The cells of every top-level region, for the overlap check of region edits.
fn region_masks(doc: &Document) -> Vec<Mask> {
    doc.regions
        .iter()
        .map(|r| cells::closed_mask(&doc.grid, &r.boundary))
        .collect()
}

fn apply(doc: &mut Document, edit: &Edit) -> Result<Applied, EditError> {
    let figure = |doc: &Document, at: &FigurePath| at.get(doc).cloned().ok_or_else(|| EditError::NoFigure(at.clone()));
    match edit {
        Edit::SetHeight { at, height } => {
            let f = at.get_mut(doc).ok_or_else(|| EditError::NoFigure(at.clone()))?;
            validate::height(*height, || format!("{at}.height"))?;
            let old = std::mem::replace(&mut f.height, *height);
            let inverse = Edit::SetHeight {
                at: at.clone(),
                height: old,
            };
            Ok(Applied {
                inverse,
                scope: Scope::Height(at.clone()),
            })
        }
        Edit::SetSlope { at, slope } => {
            let f = at.get_mut(doc).ok_or_else(|| EditError::NoFigure(at.clone()))?;
            validate::slope(*slope, || format!("{at}.slope"))?;
            let old = std::mem::replace(&mut f.slope, *slope);
            let inverse = Edit::SetSlope {
                at: at.clone(),
                slope: old,
            };
            Ok(Applied {
                inverse,
                scope: Scope::Slope(at.clone()),
            })
        }
        Edit::AddFigure { at, figure } => {
            let list_len = at.list_mut(doc).ok_or_else(|| EditError::NoFigure(at.clone()))?.len();
            if at.index() > list_len {
                return Err(EditError::NoFigure(at.clone()));
            }
            let new = figure.clone();
            change_region(doc, at.region(), |d| {
                if let Some(list) = at.list_mut(d) {
                    list.insert(at.index(), new);
                }
            })?;
            Ok(Applied {
                inverse: Edit::DeleteFigure { at: at.clone() },
                scope: Scope::Figures(FigureList::of(at), ListChange::Added(at.index())),
            })
        }
        Edit::DeleteFigure { at } => {
            let old = figure(doc, at)?;
            change_region(doc, at.region(), |d| {
                if let Some(list) = at.list_mut(d) {
                    list.remove(at.index());
                }
            })?;
            Ok(Applied {
                inverse: Edit::AddFigure {
                    at: at.clone(),
                    figure: old,
                },
                scope: Scope::Figures(FigureList::of(at), ListChange::Removed(at.index())),
            })
        }
        Edit::MoveFigure { at, by } => {
            let old = figure(doc, at)?;
            let mut new = old.clone();
            new.translate(*by);
            replace_figure(doc, at, new, old)
        }
        Edit::ReplaceFigure { at, figure: new } => {
            let old = figure(doc, at)?;
            replace_figure(doc, at, new.clone(), old)
        }
        Edit::MovePoint { curve, index, to } => {
            let (pts, closed) = curve_points(doc, curve)?;
            let mut v = vertices(&pts, closed);
            let old = *v.get(*index).ok_or_else(|| no_point(curve, *index))?;
            v[*index] = *to;
            let scope = set_curve(doc, curve, close(v, closed))?;
            Ok(Applied {
                inverse: Edit::MovePoint {
                    curve: curve.clone(),
                    index: *index,
                    to: old,
                },
                scope,
            })
        }
        Edit::InsertPoint { curve, index, point } => {
            let (pts, closed) = curve_points(doc, curve)?;
            let mut v = vertices(&pts, closed);
            if *index > v.len() {
                return Err(no_point(curve, *index));
            }
            v.insert(*index, *point);
            let scope = set_curve(doc, curve, close(v, closed))?;
            Ok(Applied {
                inverse: Edit::DeletePoint {
                    curve: curve.clone(),
                    index: *index,
                },
                scope,
            })
        }
        Edit::DeletePoint { curve, index } => {
            let (pts, closed) = curve_points(doc, curve)?;
            let mut v = vertices(&pts, closed);
            if *index >= v.len() {
                return Err(no_point(curve, *index));
            }
            let old = v.remove(*index);
            let scope = set_curve(doc, curve, close(v, closed))?;
            Ok(Applied {
                inverse: Edit::InsertPoint {
                    curve: curve.clone(),
                    index: *index,
                    point: old,
                },
                scope,
            })
        }
        Edit::AddRegion { index, region } => {
            if *index > doc.regions.len() {
                return Err(EditError::NoRegion(*index));
            }
            validate::region(&doc.grid, region, *index)?;
            let mask = cells::closed_mask(&doc.grid, &region.boundary);
            let masks = region_masks(doc);
            let shifted = masks
                .iter()
                .enumerate()
                .map(|(j, m)| (if j >= *index { j + 1 } else { j }, m));
            validate::region_overlap(*index, &mask, shifted)?;
            doc.regions.insert(*index, region.clone());
            if let Err(e) = validate::memory(doc) {
                doc.regions.remove(*index);
                return Err(e.into());
            }
            Ok(Applied {
                inverse: Edit::DeleteRegion { index: *index },
                scope: Scope::RegionAdded(*index),
            })
        }
        Edit::DeleteRegion { index } => {
            if *index >= doc.regions.len() {
                return Err(EditError::NoRegion(*index));
            }
            let old = doc.regions.remove(*index);
            Ok(Applied {
                inverse: Edit::AddRegion {
                    index: *index,
                    region: old,
                },
                scope: Scope::RegionRemoved(*index),
            })
        }
        Edit::MoveRegion { index, by } => {
            let mut new = doc.regions.get(*index).ok_or(EditError::NoRegion(*index))?.clone();
            new.translate(*by);
            replace_region(doc, *index, new, Scope::RegionReplaced(*index))
        }
        Edit::ReplaceRegion { index, region } => {
            doc.regions.get(*index).ok_or(EditError::NoRegion(*index))?;
            replace_region(doc, *index, region.clone(), Scope::RegionReplaced(*index))
        }
        Edit::Group { .. } => Err(EditError::Group),
        Edit::AddRocks { index, field } => {
            if *index > doc.rocks.len() {
                return Err(EditError::NoRocks(*index));
            }
            doc.rocks.insert(*index, field.clone());
            if let Err(e) = validate::rock_fields(doc) {
                doc.rocks.remove(*index);
                return Err(e.into());
            }
            Ok(Applied {
                inverse: Edit::DeleteRocks { index: *index },
                scope: Scope::Rocks(*index),
            })
        }
        Edit::DeleteRocks { index } => {
            if *index >= doc.rocks.len() {
                return Err(EditError::NoRocks(*index));
            }
            let field = doc.rocks.remove(*index);
            Ok(Applied {
                inverse: Edit::AddRocks { index: *index, field },
                scope: Scope::Rocks(*index),
            })
        }
        Edit::MoveRocks { index, by } => {
            let mut field = doc.rocks.get(*index).ok_or(EditError::NoRocks(*index))?.clone();
            field.at = [field.at[0] + by[0], field.at[1] + by[1]];
            replace_rocks(doc, *index, field)
        }
        Edit::ReplaceRocks { index, field } => {
            doc.rocks.get(*index).ok_or(EditError::NoRocks(*index))?;
            replace_rocks(doc, *index, field.clone())
        }
        Edit::AddRiver { index, river } => add_river(doc, *index, river.clone()),
        Edit::DeleteRiver { index } => {
            if *index >= doc.rivers.len() {
                return Err(EditError::NoRiver(*index));
            }
            let river = doc.rivers.remove(*index);
            Ok(Applied {
                inverse: Edit::AddRiver { index: *index, river },
                scope: Scope::Rivers(*index),
            })
        }
        Edit::ReplaceRiver { index, river } => replace_river(doc, *index, river.clone()),
        Edit::SetRidges { ridges } => {
            let old = std::mem::replace(&mut doc.ridges, ridges.clone());
            if let Err(e) = validate::ridges(doc) {
                doc.ridges = old;
                return Err(e.into());
            }
            Ok(Applied {
                inverse: Edit::SetRidges { ridges: old },
                scope: Scope::Ridges,
            })
        }
        Edit::AddTree { index, tree } => {
            if *index > doc.trees.len() {
                return Err(EditError::NoTree(*index));
            }
            doc.trees.insert(*index, tree.clone());
            if let Err(e) = validate::trees(doc) {
                doc.trees.remove(*index);
                return Err(e.into());
            }
            Ok(Applied {
                inverse: Edit::DeleteTree { index: *index },
                scope: Scope::Trees,
            })
        }
        Edit::DeleteTree { index } => {
            if *index >= doc.trees.len() {
                return Err(EditError::NoTree(*index));
            }
            let tree = doc.trees.remove(*index);
            Ok(Applied {
                inverse: Edit::AddTree { index: *index, tree },
                scope: Scope::Trees,
            })
        }
        Edit::MoveTree { index, by } => {
            let mut tree = doc.trees.get(*index).ok_or(EditError::NoTree(*index))?.clone();
            tree.at = [tree.at[0] + by[0], tree.at[1] + by[1]];
            replace_tree(doc, *index, tree)
        }
        Edit::ReplaceTree { index, tree } => {
            doc.trees.get(*index).ok_or(EditError::NoTree(*index))?;
            replace_tree(doc, *index, tree.clone())
        }
        Edit::AddGrove { index, grove } => {
            if *index > doc.groves.len() {
                return Err(EditError::NoGrove(*index));
            }
            doc.groves.insert(*index, grove.clone());
            if let Err(e) = validate::groves(doc) {
                doc.groves.remove(*index);
                return Err(e.into());
            }
            Ok(Applied {
                inverse: Edit::DeleteGrove { index: *index },
                scope: Scope::Trees,
            })
        }
        Edit::DeleteGrove { index } => {
            if *index >= doc.groves.len() {
                return Err(EditError::NoGrove(*index));
            }
            let grove = doc.groves.remove(*index);
            Ok(Applied {
                inverse: Edit::AddGrove { index: *index, grove },
                scope: Scope::Trees,
            })
        }
        Edit::MoveGrove { index, by } => {
            let mut grove = doc.groves.get(*index).ok_or(EditError::NoGrove(*index))?.clone();
            for p in &mut grove.region {
                *p = [p[0] + by[0], p[1] + by[1]];
            }
            replace_grove(doc, *index, grove)
        }
        Edit::ReplaceGrove { index, grove } => {
            doc.groves.get(*index).ok_or(EditError::NoGrove(*index))?;
            replace_grove(doc, *index, grove.clone())
        }
    }
}

fn add_river(doc: &mut Document, index: usize, river: River) -> Result<Applied, EditError> {
    if index > doc.rivers.len() {
        return Err(EditError::NoRiver(index));
    }
    doc.rivers.insert(index, river);
    if let Err(e) = validate::rivers(doc) {
        doc.rivers.remove(index);
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::DeleteRiver { index },
        scope: Scope::Rivers(index),
    })
}

fn replace_river(doc: &mut Document, index: usize, new: River) -> Result<Applied, EditError> {
    let old = std::mem::replace(doc.rivers.get_mut(index).ok_or(EditError::NoRiver(index))?, new);
    if let Err(e) = validate::rivers(doc) {
        doc.rivers[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::ReplaceRiver { index, river: old },
        scope: Scope::Rivers(index),
    })
}

fn replace_rocks(doc: &mut Document, index: usize, new: RockField) -> Result<Applied, EditError> {
    let old = std::mem::replace(&mut doc.rocks[index], new);
    if let Err(e) = validate::rock_fields(doc) {
        doc.rocks[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::ReplaceRocks { index, field: old },
        scope: Scope::Rocks(index),
    })
}

fn replace_tree(doc: &mut Document, index: usize, new: Tree) -> Result<Applied, EditError> {
    let old = std::mem::replace(&mut doc.trees[index], new);
    if let Err(e) = validate::trees(doc) {
        doc.trees[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::ReplaceTree { index, tree: old },
        scope: Scope::Trees,
    })
}

fn replace_grove(doc: &mut Document, index: usize, new: Grove) -> Result<Applied, EditError> {
    let old = std::mem::replace(&mut doc.groves[index], new);
    if let Err(e) = validate::groves(doc) {
        doc.groves[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::ReplaceGrove { index, grove: old },
        scope: Scope::Trees,
    })
}

fn no_point(curve: &CurvePath, index: usize) -> EditError {
    EditError::NoPoint {
        curve: curve.clone(),
        index,
    }
}

/// Changes top-level region `index` with `f`, keeping the change only if the region stays valid
/// and the terrain engine's memory within its limit. Figure edits cannot change a region's
/// boundary, so overlap with other regions is unaffected.
fn change_region(doc: &mut Document, index: usize, f: impl FnOnce(&mut Document)) -> Result<(), EditError> {
    let saved = doc.regions.get(index).ok_or(EditError::NoRegion(index))?.clone();
    f(doc);
    let checked = validate::region(&doc.grid, &doc.regions[index], index).and_then(|()| validate::memory(doc));
    if let Err(e) = checked {
        doc.regions[index] = saved;
        return Err(e.into());
    }
    Ok(())
}

fn replace_figure(doc: &mut Document, at: &FigurePath, new: Figure, old: Figure) -> Result<Applied, EditError> {
    change_region(doc, at.region(), |d| {
        if let Some(f) = at.get_mut(d) {
            *f = new;
        }
    })?;
    Ok(Applied {
        inverse: Edit::ReplaceFigure {
            at: at.clone(),
            figure: old,
        },
        scope: Scope::Figures(FigureList::of(at), ListChange::Replaced(at.index())),
    })
}

fn replace_region(doc: &mut Document, index: usize, new: Region, scope: Scope) -> Result<Applied, EditError> {
    validate::region(&doc.grid, &new, index)?;
    let mask = cells::closed_mask(&doc.grid, &new.boundary);
    validate::region_overlap(index, &mask, region_masks(doc).iter().enumerate())?;
    let old = std::mem::replace(&mut doc.regions[index], new);
    if let Err(e) = validate::memory(doc) {
        doc.regions[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: Edit::ReplaceRegion { index, region: old },
        scope,
    })
}

fn curve_points(doc: &Document, curve: &CurvePath) -> Result<(Vec<Point>, bool), EditError> {
    match curve {
        CurvePath::Boundary(r) => Ok((
            doc.regions.get(*r).ok_or(EditError::NoRegion(*r))?.boundary.clone(),
            true,
        )),
        CurvePath::Figure(at) => {
            let f = at.get(doc).ok_or_else(|| EditError::NoFigure(at.clone()))?;
            Ok((f.points.clone(), f.kind == FigureKind::Closed))
        }
    }
}

/// Replaces a curve's points, checking the result.
fn set_curve(doc: &mut Document, curve: &CurvePath, points: Vec<Point>) -> Result<Scope, EditError> {
    match curve {
        CurvePath::Boundary(r) => {
            let mut new = doc.regions[*r].clone();
            new.boundary = points;
            replace_region(doc, *r, new, Scope::RegionOutline(*r)).map(|a| a.scope)
        }
        CurvePath::Figure(at) => {
            change_region(doc, at.region(), |d| {
                if let Some(f) = at.get_mut(d) {
                    f.points = points;
                }
            })?;
            Ok(Scope::Figures(FigureList::of(at), ListChange::Outline(at.index())))
        }
    }
}
