//! The session's document: the one `penmodel open` continues, or a new one that never
//! overwrites a user's work, and what a session created, removed again when nothing is modeled.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use penmodel::session::blank_document;
use penmodel_terrain::editor::{Editor, EditorError};
use penmodel_terrain::journal::JournalError;

use super::LiveArgs;

/// The file beside the demo's document that says an earlier demo wrote it, so the next demo may
/// replace it; a user's document has none.
const DEMO_MARK: &str = ".penmodel-demo";
const DEMO_MARK_TEXT: &str = "document.json here was written by penmodel's built-in demo; the next demo replaces it.\n";

/// What a session created, to remove when nothing is modeled.
#[derive(Default)]
pub struct Created {
    /// The --out folder, when it did not exist.
    pub out: Option<PathBuf>,
    /// Its frames folder, when it did not exist.
    pub frames: Option<PathBuf>,
    /// A new session's document (and its journal).
    pub document: Option<PathBuf>,
    /// The demo's mark beside it.
    pub demo_mark: Option<PathBuf>,
}

impl Created {
    /// `result`, with what was created removed first when it is an error (issue 47: a failed
    /// `penmodel open` left the `--out` folder it made).
    pub fn on_error<T>(&self, result: Result<T>) -> Result<T> {
        if result.is_err() {
            // The first error is the one to report; a failure to tidy up is secondary.
            let _ = self.remove();
        }
        result
    }

    /// Removes what was created; folders only if empty.
    pub fn remove(&self) -> Result<()> {
        let remove = |path: &Path| match std::fs::remove_file(path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(e).with_context(|| format!("cannot remove {}", path.display()))
            }
            _ => Ok(()),
        };
        if let Some(doc) = &self.document {
            remove(doc)?;
            remove(&penmodel_terrain::journal::path_for(doc))?;
            // The session's own lock goes with the document it created (still held: nothing
            // else can have opened a document this session only just made).
            remove(&penmodel_terrain::lock::path_for(doc))?;
        }
        if let Some(mark) = &self.demo_mark {
            remove(mark)?;
        }
        // A folder goes only if empty (remove_dir refuses any other): its frames folder first.
        for dir in self.frames.iter().chain(&self.out) {
            let _ = std::fs::remove_dir(dir);
        }
        Ok(())
    }
}

/// The document `penmodel open` continues (its journal replayed), or a new session's, created
/// where `--doc` or `--out` says; what it creates goes into `created`. `recover`: open a journal
/// with a bad line up to its last good one (`penmodel open --recover`).
pub fn open(
    args: &LiveArgs,
    open: Option<&Path>,
    recover: bool,
    demo: bool,
    created: &mut Created,
) -> Result<(Editor, PathBuf)> {
    Ok(match open {
        Some(path) => {
            let opened = match recover {
                true => Editor::open_recovering(path),
                false => Editor::open(path),
            };
            let (editor, report) = match opened {
                Ok(opened) => opened,
                Err(e @ (EditorError::Journal(JournalError::Corrupt { .. }) | EditorError::Replay { .. })) => {
                    bail!(
                        "{e}\n`penmodel open --recover {}` opens it up to the last good line (the journal as it is \
                         is kept beside it)",
                        path.display()
                    )
                }
                Err(e) => return Err(e.into()),
            };
            if let Some(r) = &report.recovered {
                eprintln!(
                    "penmodel: recovered: journal lines {} to {} left out ({} line{}; line {}: {}); the journal as it \
                     was is kept as {}",
                    r.dropped.line,
                    r.dropped.line + r.dropped.lines - 1,
                    r.dropped.lines,
                    if r.dropped.lines == 1 { "" } else { "s" },
                    r.dropped.line,
                    r.dropped.reason,
                    r.copy.display()
                );
            }
            if report.replayed > 0 {
                eprintln!("penmodel: {} journal entries replayed", report.replayed);
            }
            if let Some(stale) = report.stale_journal {
                eprintln!(
                    "penmodel: a journal of another version was set aside: {}",
                    stale.display()
                );
            }
            (editor, path.to_owned())
        }
        None => {
            let path = args.doc.clone().unwrap_or_else(|| args.out().join("document.json"));
            // The demo replaces only a document an earlier demo wrote (its mark beside it); a
            // real session never overwrites anything, and no session plays the demo into work.
            let demo_mark = args.out().join(DEMO_MARK);
            let replaceable = demo && args.doc.is_none() && demo_mark.exists();
            if path.exists() && !replaceable {
                let hint = if demo {
                    "; give the demo another --out"
                } else {
                    ", or give another --doc"
                };
                bail!(
                    "{} exists: `penmodel open {}` continues it{hint}",
                    path.display(),
                    path.display()
                );
            }
            let editor = match Editor::create(&path, blank_document()) {
                Ok(editor) => editor,
                Err(e) => {
                    // The --out folder made for it goes again.
                    created.remove()?;
                    return Err(e.into());
                }
            };
            created.document = Some(path.clone());
            if demo && args.doc.is_none() {
                std::fs::write(&demo_mark, DEMO_MARK_TEXT)
                    .with_context(|| format!("cannot write {}", demo_mark.display()))?;
                created.demo_mark = Some(demo_mark.clone());
            } else if path == args.out().join("document.json") && demo_mark.exists() {
                // This document is the user's now: the next demo must not replace it.
                std::fs::remove_file(&demo_mark).with_context(|| format!("cannot remove {}", demo_mark.display()))?;
            }
            (editor, path)
        }
    })
}
