//! Editing a document with undo and redo, journaled so that a crash loses nothing.
//!
//! An [`Editor`] owns the document and its [`TerrainEngine`]. Each edit is applied to the
//! document ([`Edit::apply_to`], which says what changed), the terrain brought up to date with
//! that scope, then
//! appended to the journal and flushed to disk, then pushed on the undo stack; if the journal
//! cannot be written the edit is rolled back and the error returned. Opening a document replays
//! its journal (edits, undos and redos since the last save, and the undo history saved with it);
//! saving writes the document atomically and starts a new journal (compaction).
//!
//! A pull or a slope drag changes a figure many times a second; journaling every pen report would
//! put an `fsync` in each frame. [`Editor::preview`] shows such a change without recording it;
//! the final values are then recorded once with [`Editor::commit_preview`] (height and slope
//! of one grab are one step) or [`Editor::apply`], whose undo returns to the values before the
//! preview.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::address::FigurePath;
use crate::document::Document;
use crate::edit::{Edit, EditError};
use crate::engine::{Rect, TerrainEngine};
use crate::heightmap::Heightmap;
use crate::journal::{self, Entry, JournalError, Replay, UndoStep, Writer};
use crate::lock::{self, DocumentLock, LockError};
use crate::persist::{self, LoadError, SaveError};
use crate::revision::Revisions;
use crate::rocks::cache::Seated;
use crate::trees::Forest;
use crate::validate::ValidationError;

/// The most undo steps kept; older ones are forgotten.
pub const HISTORY_LIMIT: usize = 1000;

/// Why an editor operation failed.
#[allow(missing_docs)] // the fields say which file, where and why.
#[derive(Debug, Error)]
pub enum EditorError {
    /// The document could not be read.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The document could not be saved.
    #[error(transparent)]
    Save(#[from] SaveError),
    /// The edit was refused; nothing changed.
    #[error(transparent)]
    Edit(#[from] EditError),
    /// The journal could not be read or written; a failed edit was rolled back.
    #[error(transparent)]
    Journal(#[from] JournalError),
    /// A journal entry does not apply to the document it was recorded for.
    #[error("journal {} line {line}: cannot replay: {reason}", path.display())]
    Replay {
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        reason: String,
    },
    /// Only height and slope changes can be previewed.
    #[error("only set_height and set_slope can be previewed")]
    NotPreviewable,
    /// The editor has no file to save to.
    #[error("the document has no file yet: use save_as")]
    NoFile,
    /// Another writer has the document open ([`crate::lock`]); nothing was read or written.
    #[error(transparent)]
    Locked(#[from] LockError),
}

/// What [`Editor::open`] found in the journal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OpenReport {
    /// Journal entries replayed (edits, undos and redos).
    pub replayed: usize,
    /// Whether an incomplete last journal line (a write cut by a crash) was dropped.
    pub dropped_torn_line: bool,
    /// Where a journal that belonged to another version of the document was moved.
    pub stale_journal: Option<PathBuf>,
    /// A journal that belongs to another version of the document, left where it is and not
    /// replayed ([`Editor::open_read_only`] moves nothing), so that the caller can say so.
    pub ignored_stale_journal: Option<PathBuf>,
    /// What [`Editor::open_recovering`] left out of a journal with a bad line.
    pub recovered: Option<Recovered>,
}

/// A journal opened up to its last good line ([`Editor::open_recovering`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Recovered {
    /// The first line left out, how many were, and what is wrong with the first.
    pub dropped: journal::Dropped,
    /// Where the journal as it was, bad lines included, was copied before they were cut off.
    pub copy: PathBuf,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Property {
    Height,
    Slope,
}

/// A figure shown with a changed height or slope, or both, not yet recorded.
#[derive(Debug)]
struct Preview {
    at: FigurePath,
    /// The height before the preview, if the height is previewed.
    height: Option<f64>,
    /// The slope before the preview, if the slope is previewed.
    slope: Option<f64>,
}

impl Preview {
    fn original(&self, property: Property) -> Option<f64> {
        match property {
            Property::Height => self.height,
            Property::Slope => self.slope,
        }
    }

    /// The edits that restore the values from before the preview.
    fn restore(&self) -> Vec<Edit> {
        let mut edits = Vec::new();
        if let Some(slope) = self.slope {
            edits.push(set(self.at.clone(), Property::Slope, slope));
        }
        if let Some(height) = self.height {
            edits.push(set(self.at.clone(), Property::Height, height));
        }
        edits
    }
}

/// The result of an applied edit.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The edit that undoes it exactly.
    pub inverse: Edit,
    /// The cells whose height may have changed.
    pub changed: Rect,
}

/// Where the document lives on disk.
struct Store {
    path: PathBuf,
    journal: Writer,
    /// This editor is the document's only writer while it holds this.
    lock: DocumentLock,
}

/// A document being edited: terrain, undo and redo, journal.
pub struct Editor {
    doc: Document,
    terrain: TerrainEngine,
    undo: Vec<UndoStep>,
    redo: Vec<UndoStep>,
    store: Option<Store>,
    preview: Option<Preview>,
    /// The edit restoring a whole element — the `ridges` entry, a tree or a grove — from before
    /// an unrecorded preview of it ([`Editor::preview_ridges`], [`Editor::preview_tree`]).
    shown: Option<Edit>,
    /// The rock fields standing on the terrain, following every change.
    rocks: Seated,
    /// The trees and groves standing on the terrain, following every change.
    trees: Forest,
    /// The terrain's changes, for those who keep something made from its heights.
    revisions: Revisions,
}

/// Moves a stale journal to `JOURNAL.stale`, or `.stale.2`, `.stale.3`, … when one set aside
/// earlier is there: a rename would replace it, and the edits it holds with it.
fn set_aside(jpath: &Path) -> io::Result<PathBuf> {
    let aside = free_name(jpath, "stale");
    fs::rename(jpath, &aside)?;
    Ok(aside)
}

/// `JOURNAL.SUFFIX`, or `.SUFFIX.2`, `.SUFFIX.3`, …: the first name not taken.
fn free_name(jpath: &Path, suffix: &str) -> PathBuf {
    let mut n = 1u32;
    loop {
        let mut aside = jpath.as_os_str().to_owned();
        match n {
            1 => aside.push(format!(".{suffix}")),
            _ => aside.push(format!(".{suffix}.{n}")),
        }
        let aside = PathBuf::from(aside);
        if fs::symlink_metadata(&aside).is_err() {
            return aside;
        }
        n += 1;
    }
}

fn journal_io(path: &Path) -> impl FnOnce(io::Error) -> EditorError + '_ {
    move |cause| {
        EditorError::Journal(JournalError::Io {
            path: path.to_owned(),
            cause,
        })
    }
}

fn preview_target(edit: &Edit) -> Option<(FigurePath, Property, f64)> {
    match edit {
        Edit::SetHeight { at, height } => Some((at.clone(), Property::Height, *height)),
        Edit::SetSlope { at, slope } => Some((at.clone(), Property::Slope, *slope)),
        _ => None,
    }
}

/// A whole element an unrecorded preview replaces ([`Editor::preview_ridges`],
/// [`Editor::preview_tree`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Element {
    Ridges,
    Tree(usize),
    Grove(usize),
}

fn element_of(edit: &Edit) -> Option<Element> {
    match edit {
        Edit::SetRidges { .. } => Some(Element::Ridges),
        Edit::ReplaceTree { index, .. } => Some(Element::Tree(*index)),
        Edit::ReplaceGrove { index, .. } => Some(Element::Grove(*index)),
        _ => None,
    }
}

fn set(at: FigurePath, property: Property, value: f64) -> Edit {
    match property {
        Property::Height => Edit::SetHeight { at, height: value },
        Property::Slope => Edit::SetSlope { at, slope: value },
    }
}

impl Editor {
    /// Edits `doc` in memory, without a file (until [`Editor::save_as`]).
    pub fn new(doc: Document) -> Result<Editor, ValidationError> {
        let terrain = TerrainEngine::new(&doc)?;
        Ok(Editor {
            rocks: Seated::of(&doc, terrain.heightmap()),
            trees: Forest::of(&doc, terrain.heightmap()),
            terrain,
            doc,
            undo: Vec::new(),
            redo: Vec::new(),
            store: None,
            preview: None,
            shown: None,
            revisions: Revisions::new(),
        })
    }

    /// Opens the document at `path` and replays its journal; later edits are journaled there.
    pub fn open(path: &Path) -> Result<(Editor, OpenReport), EditorError> {
        Editor::open_with(path, true, false)
    }

    /// [`Editor::open`] for a journal with a bad line (a changed bit, a lost line, an entry
    /// that does not apply): the edits before the first bad line are replayed, the journal as
    /// it was is copied to `JOURNAL.corrupt` (`.corrupt.2`, …), and the bad lines are cut off
    /// so that later edits follow the good ones; [`OpenReport::recovered`] says what was left
    /// out. A journal without a bad line opens as with [`Editor::open`].
    pub fn open_recovering(path: &Path) -> Result<(Editor, OpenReport), EditorError> {
        Editor::open_with(path, true, true)
    }

    /// The document at `path` with its journal replayed, without writing anything (no journal is
    /// kept: edits to this editor are in memory only).
    pub fn open_read_only(path: &Path) -> Result<(Editor, OpenReport), EditorError> {
        Editor::open_with(path, false, false)
    }

    fn open_with(path: &Path, write: bool, recover: bool) -> Result<(Editor, OpenReport), EditorError> {
        // A writer locks before reading: another one's save or journal line cannot come between
        // what this one reads and what it appends.
        // A link is resolved: the document is its target, and its lock and journal are beside
        // it, whichever link (or none) it is opened by.
        let target = persist::resolve_link(path).map_err(|cause| LoadError::Io {
            path: path.to_owned(),
            cause,
        })?;
        let held = match write {
            true => Some(DocumentLock::acquire(&target, lock::mode_of(&target))?),
            false => None,
        };
        let (doc, bytes) = persist::read_document(&target)?;
        let base = journal::fingerprint(&bytes);
        let mut editor = Editor::new(doc).map_err(LoadError::from)?;
        let mut report = OpenReport::default();
        let jpath = journal::path_for(&target);
        let mut continued = None;
        let replay = match recover {
            true => journal::read_recovering(&jpath, &base)?,
            false => journal::read(&jpath, &base)?,
        };
        match replay {
            Replay::Missing => {}
            Replay::Stale(_) => {
                if write {
                    let aside = set_aside(&jpath).map_err(journal_io(&jpath))?;
                    report.stale_journal = Some(aside);
                } else {
                    report.ignored_stale_journal = Some(jpath.clone());
                }
            }
            Replay::Entries {
                entries,
                starts,
                valid_len,
                torn,
                version,
                mut dropped,
            } => {
                let mut len = valid_len;
                let count = entries.len();
                for (i, entry) in entries.into_iter().enumerate() {
                    // The undo history saved with the document is not a change to it.
                    let change = !matches!(entry, Entry::History { .. });
                    // Line numbers: the open line is 1.
                    let line = i + 2;
                    match editor.replay(entry) {
                        Ok(()) => report.replayed += usize::from(change),
                        Err(reason) if recover => {
                            // A failed replay changes nothing: the editor is as after the line before.
                            let after = dropped.take().map_or(0, |d| d.lines);
                            dropped = Some(journal::Dropped {
                                line,
                                lines: count - i + after,
                                reason: format!("cannot replay: {reason}"),
                            });
                            len = starts[i];
                            break;
                        }
                        Err(reason) => {
                            return Err(EditorError::Replay {
                                path: jpath.clone(),
                                line,
                                reason,
                            });
                        }
                    }
                }
                report.dropped_torn_line = torn;
                if let Some(dropped) = dropped {
                    // The bad lines are cut off only by a writer, after they are copied aside.
                    let copy = free_name(&jpath, "corrupt");
                    if write {
                        let bytes = crate::input::read_input(&jpath, persist::MAX_JOURNAL_BYTES)
                            .and_then(|bytes| {
                                persist::write_atomic_with_mode(&copy, &bytes, Some(lock::mode_of(&target)))
                            })
                            .map_err(journal_io(&jpath));
                        bytes?;
                    }
                    report.recovered = Some(Recovered { dropped, copy });
                }
                // Lines kept: the open line and one per entry replayed or carried.
                let kept = report.recovered.as_ref().map_or(count, |r| r.dropped.line - 2);
                continued = Some((len, version, kept as u64 + 2));
            }
        }
        if let Some(lock) = held {
            let mode = lock::mode_of(&target);
            let writer = match continued {
                Some((len, version, next)) => Writer::append_to(&jpath, len, mode, version, next),
                None => Writer::create(&jpath, &base, &[], &[], mode),
            }
            .map_err(journal_io(&jpath))?;
            editor.store = Some(Store {
                path: path.to_owned(),
                journal: writer,
                lock,
            });
        }
        Ok((editor, report))
    }

    fn replay(&mut self, entry: Entry) -> Result<(), String> {
        match entry {
            Entry::History { undo, redo } => {
                self.undo = undo;
                self.redo = redo;
            }
            Entry::Do { edit } => {
                self.record(edit).map_err(|e| e.to_string())?;
            }
            Entry::Undo => {
                self.step_back().map_err(|e| e.to_string())?.ok_or("nothing to undo")?;
            }
            Entry::Redo => {
                self.step_forward()
                    .map_err(|e| e.to_string())?
                    .ok_or("nothing to redo")?;
            }
            Entry::Open { .. } => return Err("a second \"open\" entry".into()),
        }
        Ok(())
    }

    /// Creates the document file at `path` (atomically) with a new journal, and edits it there.
    pub fn create(path: &Path, doc: Document) -> Result<Editor, EditorError> {
        let mut editor = Editor::new(doc).map_err(SaveError::from)?;
        editor.save_as(path)?;
        Ok(editor)
    }

    /// The document as edited so far (a preview included).
    pub fn document(&self) -> &Document {
        &self.doc
    }

    /// The terrain of [`Editor::document`].
    pub fn heightmap(&self) -> &Heightmap {
        self.terrain.heightmap()
    }

    /// The rivers' water over [`Editor::heightmap`] (level per cell, lakes), if there are rivers.
    pub fn water(&self) -> Option<&crate::river::layer::Water> {
        self.terrain.water()
    }

    /// The terrain engine (the rivers' processed shapes: [`TerrainEngine::rivers`]).
    pub fn terrain(&self) -> &TerrainEngine {
        &self.terrain
    }

    /// The terrain's history of changes: what changed since a [`Mark`](crate::revision::Mark).
    pub fn revisions(&self) -> &Revisions {
        &self.revisions
    }

    /// The document's rock fields standing on [`Editor::heightmap`], one mesh each.
    pub fn rocks(&self) -> &Seated {
        &self.rocks
    }

    /// The document's trees and groves standing on [`Editor::heightmap`].
    pub fn trees(&self) -> &Forest {
        &self.trees
    }

    /// Applies `edit` to the document and the terrain, with no history or journal. On error
    /// nothing changes.
    fn change(&mut self, edit: &Edit) -> Result<Outcome, EditError> {
        if let Edit::Group { edits } = edit {
            return self.change_group(edits);
        }
        let applied = edit.apply_to(&mut self.doc)?;
        let changed = self.terrain.update(&self.doc, &applied.scope);
        self.revisions.record(changed);
        let cells = (changed.c0, changed.r0, changed.width, changed.height);
        self.rocks.follow(&self.doc, self.terrain.heightmap(), Some(cells));
        self.trees.follow(&self.doc, self.terrain.heightmap(), Some(cells));
        Ok(Outcome {
            inverse: applied.inverse,
            changed,
        })
    }

    /// Applies `edits` in order; if one is refused, undoes those before it.
    fn change_group(&mut self, edits: &[Edit]) -> Result<Outcome, EditError> {
        let mut inverses = Vec::with_capacity(edits.len());
        let mut changed = Rect::EMPTY;
        for edit in edits {
            match self.change(edit) {
                Ok(outcome) => {
                    inverses.push(outcome.inverse);
                    changed = changed.union(outcome.changed);
                }
                Err(e) => {
                    // Each inverse restores the document it was made from, so it applies.
                    for inverse in inverses.iter().rev() {
                        let _ = self.change(inverse);
                    }
                    return Err(e);
                }
            }
        }
        inverses.reverse();
        Ok(Outcome {
            inverse: Edit::Group { edits: inverses },
            changed,
        })
    }

    /// Follow changes under the fluvial erosion progressively
    /// ([`TerrainEngine::set_progressive_erosion`]); [`Editor::settle_erosion`] advances it.
    pub fn set_progressive_erosion(&mut self, on: bool) {
        self.terrain.set_progressive_erosion(on);
    }

    /// Advances a running exact erosion by up to `steps` steps; when it replaces the land shown,
    /// the rocks and trees are seated on it again and the whole grid is returned as changed.
    pub fn settle_erosion(&mut self, steps: u32) -> Rect {
        let changed = self.terrain.settle_erosion(&self.doc, steps);
        if changed.width > 0 && changed.height > 0 {
            self.revisions.record(changed);
            let cells = (changed.c0, changed.r0, changed.width, changed.height);
            self.rocks.follow(&self.doc, self.terrain.heightmap(), Some(cells));
            self.trees.follow(&self.doc, self.terrain.heightmap(), Some(cells));
        }
        changed
    }

    /// Runs a pending exact erosion to its end ([`Editor::settle_erosion`]): the land is then
    /// the document's, as `generate` makes it. Returns what changed.
    pub fn finish_erosion(&mut self) -> Rect {
        self.settle_erosion(u32::MAX)
    }

    /// The document's file, if it has one.
    pub fn path(&self) -> Option<&Path> {
        self.store.as_ref().map(|s| s.path.as_path())
    }

    /// Whether there is an edit to undo.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is an undone edit to redo.
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    fn log(&mut self, entry: &Entry) -> Result<(), EditorError> {
        if let Some(store) = &mut self.store {
            let path = store.journal.path().to_owned();
            store.journal.append(entry).map_err(journal_io(&path))?;
        }
        Ok(())
    }

    /// Applies `edit`, journals it and makes it undoable.
    pub fn apply(&mut self, edit: Edit) -> Result<Outcome, EditorError> {
        if self.shown.is_some() {
            self.cancel_preview()?;
        }
        // Committing the previewed property: undo returns to the value before the preview.
        // (Only a preview of that one property: a preview of both is recorded by
        // [`Editor::commit_preview`].)
        let mut original = None;
        if let Some(p) = &self.preview {
            match preview_target(&edit) {
                Some((at, property, _))
                    if at == p.at && p.height.is_some() != p.slope.is_some() && p.original(property).is_some() =>
                {
                    original = p.original(property).map(|v| set(at, property, v));
                }
                _ => {
                    self.cancel_preview()?;
                }
            }
        }
        // A refused commit leaves the preview as it was.
        let mut outcome = self.change(&edit)?;
        if let Some(inverse) = original {
            outcome.inverse = inverse;
            self.preview = None;
        }
        if let Err(e) = self.log(&Entry::Do { edit: edit.clone() }) {
            // Not journaled, so not done: restore.
            self.change(&outcome.inverse)?;
            return Err(e);
        }
        self.push_undo(UndoStep {
            edit,
            inverse: outcome.inverse.clone(),
        });
        self.redo.clear();
        Ok(outcome)
    }

    /// Applies an edit as a journal replay does: no preview, no journal.
    fn record(&mut self, edit: Edit) -> Result<Outcome, EditError> {
        let outcome = self.change(&edit)?;
        self.push_undo(UndoStep {
            edit,
            inverse: outcome.inverse.clone(),
        });
        self.redo.clear();
        Ok(outcome)
    }

    fn push_undo(&mut self, step: UndoStep) {
        if self.undo.len() == HISTORY_LIMIT {
            self.undo.remove(0);
        }
        self.undo.push(step);
    }

    fn step_back(&mut self) -> Result<Option<Outcome>, EditError> {
        let Some(step) = self.undo.pop() else { return Ok(None) };
        match self.change(&step.inverse) {
            Ok(outcome) => {
                self.redo.push(step);
                Ok(Some(outcome))
            }
            Err(e) => {
                self.undo.push(step);
                Err(e)
            }
        }
    }

    fn step_forward(&mut self) -> Result<Option<Outcome>, EditError> {
        let Some(step) = self.redo.pop() else { return Ok(None) };
        match self.change(&step.edit) {
            Ok(outcome) => {
                self.push_undo(step);
                Ok(Some(outcome))
            }
            Err(e) => {
                self.redo.push(step);
                Err(e)
            }
        }
    }

    /// Undoes the last edit; `None` when there is none.
    pub fn undo(&mut self) -> Result<Option<Outcome>, EditorError> {
        self.cancel_preview()?;
        let Some(outcome) = self.step_back()? else {
            return Ok(None);
        };
        if let Err(e) = self.log(&Entry::Undo) {
            self.step_forward()?;
            return Err(e);
        }
        Ok(Some(outcome))
    }

    /// Redoes the last undone edit; `None` when there is none.
    pub fn redo(&mut self) -> Result<Option<Outcome>, EditorError> {
        self.cancel_preview()?;
        let Some(outcome) = self.step_forward()? else {
            return Ok(None);
        };
        if let Err(e) = self.log(&Entry::Redo) {
            self.step_back()?;
            return Err(e);
        }
        Ok(Some(outcome))
    }

    /// Shows a height or slope change at once without recording it (the frames of a pull).
    /// Height and slope of the same figure can be previewed together (a pull, then the slope set
    /// while pulling). [`Editor::commit_preview`] records the previewed values as one step, or
    /// [`Editor::apply`] of the one previewed property records its final value; undo returns to
    /// the values from before the preview. Any other operation, or [`Editor::cancel_preview`],
    /// first restores them.
    pub fn preview(&mut self, edit: &Edit) -> Result<Outcome, EditorError> {
        let (at, property, _) = preview_target(edit).ok_or(EditorError::NotPreviewable)?;
        if self.shown.is_some() {
            self.cancel_preview()?;
        }
        if self.preview.as_ref().is_some_and(|p| p.at != at) {
            self.cancel_preview()?;
        }
        let outcome = self.change(edit)?;
        let before = match &outcome.inverse {
            Edit::SetHeight { height, .. } => *height,
            Edit::SetSlope { slope, .. } => *slope,
            _ => return Err(EditorError::NotPreviewable),
        };
        let p = self.preview.get_or_insert(Preview {
            at,
            height: None,
            slope: None,
        });
        let slot = match property {
            Property::Height => &mut p.height,
            Property::Slope => &mut p.slope,
        };
        slot.get_or_insert(before);
        Ok(outcome)
    }

    /// Whether a preview is showing.
    pub fn previewing(&self) -> bool {
        self.preview.is_some() || self.shown.is_some()
    }

    /// Shows `ridges` as the `ridges` entry at once without recording it: the frames of a
    /// ridgeline's node dragged with the pen, the terrain following incrementally.
    /// [`Editor::commit_ridges_preview`] records what is shown as one `set_ridges` step whose
    /// undo returns to the entry from before the preview; any other operation, or
    /// [`Editor::cancel_preview`], first restores it.
    pub fn preview_ridges(&mut self, ridges: Option<crate::document::Ridges>) -> Result<Outcome, EditorError> {
        self.preview_element(&Edit::SetRidges { ridges })
    }

    /// Records the previewed `ridges` entry as one undoable `set_ridges` step and returns it;
    /// `None` when no ridge preview is showing. If the journal cannot be written, the preview is
    /// undone and the error returned.
    pub fn commit_ridges_preview(&mut self) -> Result<Option<Edit>, EditorError> {
        self.commit_element(|e| e == Element::Ridges)
    }

    /// Shows a `replace_tree` or `replace_grove` at once without recording it: the frames of a
    /// tree's pull or a grove's resize with the pen, the forest following each one.
    /// [`Editor::commit_tree_preview`] records what is shown as one step whose undo returns to
    /// the element from before the preview; a preview of another element, any other operation,
    /// or [`Editor::cancel_preview`], first restores it.
    pub fn preview_tree(&mut self, edit: &Edit) -> Result<Outcome, EditorError> {
        match element_of(edit) {
            Some(Element::Tree(_) | Element::Grove(_)) => self.preview_element(edit),
            _ => Err(EditorError::NotPreviewable),
        }
    }

    /// Shows `edit`, which replaces a whole [`Element`], unrecorded; the restoring edit is kept
    /// from the first preview of that element (a figure's or another element's preview is
    /// restored first).
    fn preview_element(&mut self, edit: &Edit) -> Result<Outcome, EditorError> {
        let target = element_of(edit);
        let other = self.shown.as_ref().is_some_and(|old| element_of(old) != target);
        if self.preview.is_some() || other {
            self.cancel_preview()?;
        }
        let outcome = self.change(edit)?;
        if self.shown.is_none() {
            self.shown = Some(outcome.inverse.clone());
        }
        Ok(outcome)
    }

    /// Records the previewed element, if `wanted` accepts it, as one undoable step whose undo
    /// restores it from before the preview; `None` when no such preview is showing.
    fn commit_element(&mut self, wanted: impl Fn(Element) -> bool) -> Result<Option<Edit>, EditorError> {
        let Some(element) = self.shown.as_ref().and_then(element_of).filter(|&e| wanted(e)) else {
            return Ok(None);
        };
        let edit = match element {
            Element::Ridges => Some(Edit::SetRidges {
                ridges: self.doc.ridges.clone(),
            }),
            Element::Tree(index) => self
                .doc
                .trees
                .get(index)
                .map(|t| Edit::ReplaceTree { index, tree: t.clone() }),
            Element::Grove(index) => self.doc.groves.get(index).map(|g| Edit::ReplaceGrove {
                index,
                grove: g.clone(),
            }),
        };
        let Some(inverse) = self.shown.take() else {
            return Ok(None);
        };
        let Some(edit) = edit else { return Ok(None) };
        self.record_previewed(edit, inverse).map(Some)
    }

    /// Records the previewed tree or grove as one undoable `replace_tree` or `replace_grove`
    /// step and returns it; `None` when no tree preview is showing. If the journal cannot be
    /// written, the preview is undone and the error returned.
    pub fn commit_tree_preview(&mut self) -> Result<Option<Edit>, EditorError> {
        self.commit_element(|e| matches!(e, Element::Tree(_) | Element::Grove(_)))
    }

    /// Records the previewed values as one undoable step (a `set_height`, a `set_slope`, or a
    /// `group` of both) and returns it; `None` when nothing is previewed. If the journal cannot
    /// be written, the preview is undone and the error returned.
    pub fn commit_preview(&mut self) -> Result<Option<Edit>, EditorError> {
        let Some(p) = self.preview.take() else { return Ok(None) };
        let doc = &self.doc;
        let Some(figure) = p.at.get(doc) else {
            return Ok(None);
        };
        let mut edits = Vec::new();
        if p.height.is_some() {
            edits.push(set(p.at.clone(), Property::Height, figure.height));
        }
        if p.slope.is_some() {
            edits.push(set(p.at.clone(), Property::Slope, figure.slope));
        }
        let mut inverse = p.restore();
        let (edit, inverse) = if edits.len() == 1 {
            (edits.remove(0), inverse.remove(0))
        } else {
            (Edit::Group { edits }, Edit::Group { edits: inverse })
        };
        self.record_previewed(edit, inverse).map(Some)
    }

    /// Journals a preview already applied as `edit` and makes it one undo step; if the journal
    /// cannot be written, undoes it with `inverse` and returns the error.
    fn record_previewed(&mut self, edit: Edit, inverse: Edit) -> Result<Edit, EditorError> {
        if let Err(e) = self.log(&Entry::Do { edit: edit.clone() }) {
            self.change(&inverse)?;
            return Err(e);
        }
        self.push_undo(UndoStep {
            edit: edit.clone(),
            inverse,
        });
        self.redo.clear();
        Ok(edit)
    }

    /// Restores the values from before an unrecorded preview; `None` when there is none.
    pub fn cancel_preview(&mut self) -> Result<Option<Outcome>, EditorError> {
        if let Some(restore) = self.shown.take() {
            return Ok(Some(self.change(&restore)?));
        }
        let Some(p) = self.preview.take() else { return Ok(None) };
        let restore = p.restore();
        let edit = match <[Edit; 1]>::try_from(restore) {
            Ok([one]) => one,
            Err(both) => Edit::Group { edits: both },
        };
        Ok(Some(self.change(&edit)?))
    }

    /// Saves to the document's file (ending any preview) and compacts the journal.
    pub fn save(&mut self) -> Result<(), EditorError> {
        let path = self.store.as_ref().ok_or(EditorError::NoFile)?.path.clone();
        self.save_as(&path)
    }

    /// Saves to `path` (ending any preview), which becomes the document's file, and starts its
    /// journal afresh; the undo history carries over.
    pub fn save_as(&mut self, path: &Path) -> Result<(), EditorError> {
        self.cancel_preview()?;
        // Writing another file than this editor's own needs that file's lock first; the old one
        // is released once the new file is this editor's.
        // Through a link, the target is written in place ([`persist::write_atomic`]), and its
        // lock and journal are beside it.
        let target = persist::resolve_link(path).map_err(|cause| SaveError::Io {
            path: path.to_owned(),
            cause,
        })?;
        let same = self.store.as_ref().is_some_and(|s| s.lock.document() == target);
        let new_lock = match same {
            true => None,
            false => Some(DocumentLock::acquire(&target, lock::mode_of(&target))?),
        };
        // A base heightmap named relative to the old file's folder is named by its whole path
        // in a file elsewhere, so the new file still finds it.
        if let (Some(store), Some(base)) = (&self.store, &mut self.doc.terrain.base)
            && Path::new(&base.path).is_relative()
            && store.lock.document().parent() != target.parent()
            && let Some(whole) = store
                .lock
                .document()
                .parent()
                .and_then(|dir| std::fs::canonicalize(dir.join(&base.path)).ok())
                .and_then(|p| p.to_str().map(str::to_owned))
        {
            base.path = whole;
        }
        // Document first: a crash between the two leaves a journal whose base no longer matches,
        // which is then set aside rather than replayed twice.
        let bytes = self.doc.save(&target)?;
        let jpath = journal::path_for(&target);
        let mode = lock::mode_of(&target);
        let writer = Writer::create(&jpath, &journal::fingerprint(&bytes), &self.undo, &self.redo, mode)
            .map_err(journal_io(&jpath))?;
        match (new_lock, &mut self.store) {
            (None, Some(store)) => store.journal = writer,
            (Some(lock), _) => {
                self.store = Some(Store {
                    path: path.to_owned(),
                    journal: writer,
                    lock,
                })
            }
            // `same` means there is a store.
            (None, None) => return Err(EditorError::NoFile),
        }
        Ok(())
    }
}
