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
        Edit::AddRocks { index, field } => insert(doc, *index, field),
        Edit::DeleteRocks { index } => remove::<RockField>(doc, *index),
        Edit::MoveRocks { index, by } => shift(doc, *index, |f: &mut RockField| f.at = plus(f.at, *by)),
        Edit::ReplaceRocks { index, field } => replace(doc, *index, field.clone()),
        Edit::AddRiver { index, river } => insert(doc, *index, river),
        Edit::DeleteRiver { index } => remove::<River>(doc, *index),
        Edit::ReplaceRiver { index, river } => replace(doc, *index, river.clone()),
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
        Edit::AddTree { index, tree } => insert(doc, *index, tree),
        Edit::DeleteTree { index } => remove::<Tree>(doc, *index),
        Edit::MoveTree { index, by } => shift(doc, *index, |t: &mut Tree| t.at = plus(t.at, *by)),
        Edit::ReplaceTree { index, tree } => replace(doc, *index, tree.clone()),
        Edit::AddGrove { index, grove } => insert(doc, *index, grove),
        Edit::DeleteGrove { index } => remove::<Grove>(doc, *index),
        Edit::MoveGrove { index, by } => shift(doc, *index, |g: &mut Grove| {
            for p in &mut g.region {
                *p = plus(*p, *by);
            }
        }),
        Edit::ReplaceGrove { index, grove } => replace(doc, *index, grove.clone()),
    }
}

fn plus(p: Point, by: Point) -> Point {
    [p[0] + by[0], p[1] + by[1]]
}

/// An element kind the document keeps in a list and edits by index (rock fields, rivers, trees,
/// groves): its list, its check, its edits and its scope. Adding, deleting, replacing and moving
/// are written once, below, for every such kind.
trait Listed: Clone + Sized {
    fn list(doc: &mut Document) -> &mut Vec<Self>;
    /// Checks the kind's elements after a change (the whole list: a check may compare them).
    fn check(doc: &Document) -> Result<(), ValidationError>;
    /// The error for a missing index.
    fn missing(index: usize) -> EditError;
    fn scope(index: usize) -> Scope;
    fn add(index: usize, element: Self) -> Edit;
    fn delete(index: usize) -> Edit;
    fn replace(index: usize, element: Self) -> Edit;
}

impl Listed for RockField {
    fn list(doc: &mut Document) -> &mut Vec<Self> {
        &mut doc.rocks
    }
    fn check(doc: &Document) -> Result<(), ValidationError> {
        validate::rock_fields(doc)
    }
    fn missing(index: usize) -> EditError {
        EditError::NoRocks(index)
    }
    fn scope(index: usize) -> Scope {
        Scope::Rocks(index)
    }
    fn add(index: usize, field: Self) -> Edit {
        Edit::AddRocks { index, field }
    }
    fn delete(index: usize) -> Edit {
        Edit::DeleteRocks { index }
    }
    fn replace(index: usize, field: Self) -> Edit {
        Edit::ReplaceRocks { index, field }
    }
}

impl Listed for River {
    fn list(doc: &mut Document) -> &mut Vec<Self> {
        &mut doc.rivers
    }
    fn check(doc: &Document) -> Result<(), ValidationError> {
        validate::rivers(doc)
    }
    fn missing(index: usize) -> EditError {
        EditError::NoRiver(index)
    }
    fn scope(index: usize) -> Scope {
        Scope::Rivers(index)
    }
    fn add(index: usize, river: Self) -> Edit {
        Edit::AddRiver { index, river }
    }
    fn delete(index: usize) -> Edit {
        Edit::DeleteRiver { index }
    }
    fn replace(index: usize, river: Self) -> Edit {
        Edit::ReplaceRiver { index, river }
    }
}

impl Listed for Tree {
    fn list(doc: &mut Document) -> &mut Vec<Self> {
        &mut doc.trees
    }
    fn check(doc: &Document) -> Result<(), ValidationError> {
        validate::trees(doc)
    }
    fn missing(index: usize) -> EditError {
        EditError::NoTree(index)
    }
    fn scope(_: usize) -> Scope {
        Scope::Trees
    }
    fn add(index: usize, tree: Self) -> Edit {
        Edit::AddTree { index, tree }
    }
    fn delete(index: usize) -> Edit {
        Edit::DeleteTree { index }
    }
    fn replace(index: usize, tree: Self) -> Edit {
        Edit::ReplaceTree { index, tree }
    }
}

impl Listed for Grove {
    fn list(doc: &mut Document) -> &mut Vec<Self> {
        &mut doc.groves
    }
    fn check(doc: &Document) -> Result<(), ValidationError> {
        validate::groves(doc)
    }
    fn missing(index: usize) -> EditError {
        EditError::NoGrove(index)
    }
    fn scope(_: usize) -> Scope {
        Scope::Trees
    }
    fn add(index: usize, grove: Self) -> Edit {
        Edit::AddGrove { index, grove }
    }
    fn delete(index: usize) -> Edit {
        Edit::DeleteGrove { index }
    }
    fn replace(index: usize, grove: Self) -> Edit {
        Edit::ReplaceGrove { index, grove }
    }
}

/// Inserts `element` at `index` (the list's length appends), if the kind's check passes.
fn insert<T: Listed>(doc: &mut Document, index: usize, element: &T) -> Result<Applied, EditError> {
    if index > T::list(doc).len() {
        return Err(T::missing(index));
    }
    T::list(doc).insert(index, element.clone());
    if let Err(e) = T::check(doc) {
        T::list(doc).remove(index);
        return Err(e.into());
    }
    Ok(Applied {
        inverse: T::delete(index),
        scope: T::scope(index),
    })
}

/// Removes element `index`; a removal leaves the other elements valid.
fn remove<T: Listed>(doc: &mut Document, index: usize) -> Result<Applied, EditError> {
    if index >= T::list(doc).len() {
        return Err(T::missing(index));
    }
    let old = T::list(doc).remove(index);
    Ok(Applied {
        inverse: T::add(index, old),
        scope: T::scope(index),
    })
}

/// Replaces element `index` with `new`, if the kind's check passes.
fn replace<T: Listed>(doc: &mut Document, index: usize, new: T) -> Result<Applied, EditError> {
    let slot = T::list(doc).get_mut(index).ok_or_else(|| T::missing(index))?;
    let old = std::mem::replace(slot, new);
    if let Err(e) = T::check(doc) {
        T::list(doc)[index] = old;
        return Err(e.into());
    }
    Ok(Applied {
        inverse: T::replace(index, old),
        scope: T::scope(index),
    })
}

/// Replaces element `index` with a copy changed by `by` (a move: the inverse restores the old
/// element exactly rather than moving back).
fn shift<T: Listed>(doc: &mut Document, index: usize, by: impl FnOnce(&mut T)) -> Result<Applied, EditError> {
    let mut new = T::list(doc).get(index).ok_or_else(|| T::missing(index))?.clone();
    by(&mut new);
    replace(doc, index, new)
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
