//! Edits with undo and redo.
pub struct Editor;
