//! Edits: incremental regeneration equals full regeneration, undo and redo restore the exact
//! documents, refused edits change nothing, and the journal brings back every edit after a crash.

use crate::common;

use std::fs;

use common::*;
use penmodel_terrain::change::Scope;
use penmodel_terrain::editor::{Editor, EditorError, OpenReport};
use penmodel_terrain::validate::CurveDefect;
use penmodel_terrain::{
    CurvePath, Defect, Detail, Document, Edit, EditError, Erosion, Figure, FigurePath, Metric, TerrainEngine, generate,
    journal,
};
use proptest::prelude::*;

/// Every figure path of the document, depth first.
fn figure_paths(doc: &Document) -> Vec<FigurePath> {
    fn walk(fs: &[Figure], at: Option<FigurePath>, region: usize, out: &mut Vec<FigurePath>) {
        for (i, f) in fs.iter().enumerate() {
            let p = match &at {
                None => FigurePath::new(region, i),
                Some(parent) => parent.child(i),
            };
            out.push(p.clone());
            walk(&f.figures, Some(p), region, out);
        }
    }
    let mut out = Vec::new();
    for (r, region) in doc.regions.iter().enumerate() {
        walk(&region.figures, None, r, &mut out);
    }
    out
}

#[derive(Debug, Clone)]
pub(crate) enum Op {
    Height(usize, f64),
    Slope(usize, f64),
    MoveFigure(usize, [f64; 2]),
    MovePoint(usize, usize, [f64; 2]),
    MoveBoundaryPoint(usize, [f64; 2]),
    InsertPoint(usize, usize),
    DeletePoint(usize, usize),
    Delete(usize),
    Add(usize, Figure),
    Undo,
    Redo,
}

pub(crate) fn op() -> impl Strategy<Value = Op> {
    let d = || [-3.0..3.0f64, -3.0..3.0f64];
    prop_oneof![
        4 => (any::<usize>(), height()).prop_map(|(i, h)| Op::Height(i, h)),
        2 => (any::<usize>(), slope()).prop_map(|(i, s)| Op::Slope(i, s)),
        2 => (any::<usize>(), d()).prop_map(|(i, by)| Op::MoveFigure(i, by)),
        2 => (any::<usize>(), any::<usize>(), d()).prop_map(|(i, p, by)| Op::MovePoint(i, p, by)),
        1 => (any::<usize>(), d()).prop_map(|(p, by)| Op::MoveBoundaryPoint(p, by)),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, p)| Op::InsertPoint(i, p)),
        1 => (any::<usize>(), any::<usize>()).prop_map(|(i, p)| Op::DeletePoint(i, p)),
        1 => any::<usize>().prop_map(Op::Delete),
        1 => (any::<usize>(), open_figure([20.0, 20.0], 8.0)).prop_map(|(i, f)| Op::Add(i, f)),
        1 => Just(Op::Undo),
        1 => Just(Op::Redo),
    ]
}

/// The edit an op stands for on `doc` (None for undo/redo or when there is no figure).
pub(crate) fn edit_for(doc: &Document, op: &Op) -> Option<Edit> {
    let paths = figure_paths(doc);
    let pick = |i: usize| paths.get(i % paths.len().max(1)).cloned();
    let vertex_count = |at: &FigurePath| {
        let f = at.get(doc).unwrap();
        if f.kind == penmodel_terrain::FigureKind::Closed {
            f.points.len() - 1
        } else {
            f.points.len()
        }
    };
    Some(match op {
        Op::Height(i, h) => Edit::SetHeight {
            at: pick(*i)?,
            height: *h,
        },
        Op::Slope(i, s) => Edit::SetSlope {
            at: pick(*i)?,
            slope: *s,
        },
        Op::MoveFigure(i, by) => Edit::MoveFigure { at: pick(*i)?, by: *by },
        Op::MovePoint(i, p, by) => {
            let at = pick(*i)?;
            let index = p % vertex_count(&at);
            let old = at.get(doc)?.points[index];
            Edit::MovePoint {
                curve: CurvePath::Figure(at),
                index,
                to: [old[0] + by[0], old[1] + by[1]],
            }
        }
        Op::MoveBoundaryPoint(p, by) => {
            let b = &doc.regions[0].boundary;
            let index = p % (b.len() - 1);
            Edit::MovePoint {
                curve: CurvePath::Boundary(0),
                index,
                to: [b[index][0] + by[0], b[index][1] + by[1]],
            }
        }
        Op::InsertPoint(i, p) => {
            let at = pick(*i)?;
            let n = vertex_count(&at);
            let index = p % (n + 1);
            let f = at.get(doc)?;
            // Halfway along an existing segment (or next to the only point), inside the figure's
            // region in most cases; validation refuses the rest.
            let a = f.points[index.min(f.points.len() - 1)];
            let b = f.points[index.saturating_sub(1)];
            let point = [(a[0] + b[0]) / 2.0 + 0.25, (a[1] + b[1]) / 2.0 + 0.25];
            Edit::InsertPoint {
                curve: CurvePath::Figure(at),
                index,
                point,
            }
        }
        Op::DeletePoint(i, p) => {
            let at = pick(*i)?;
            let index = p % vertex_count(&at);
            Edit::DeletePoint {
                curve: CurvePath::Figure(at),
                index,
            }
        }
        Op::Delete(i) => Edit::DeleteFigure { at: pick(*i)? },
        Op::Add(i, f) => Edit::AddFigure {
            at: FigurePath::new(0, i % (doc.regions[0].figures.len() + 1)),
            figure: f.clone(),
        },
        Op::Undo | Op::Redo => return None,
    })
}

pub(crate) fn metric() -> impl Strategy<Value = Metric> {
    prop_oneof![Just(Metric::Taxicab), Just(Metric::Euclidean)]
}

/// No detail, or detail of a random amount, scale (2 to 40 cells of the 40-cell grid), octaves
/// and seed.
pub(crate) fn detail() -> impl Strategy<Value = Option<Detail>> {
    prop::option::of(
        (0.0..=1.0f64, 2.0..40.0f64, 1u32..=6, any::<u64>()).prop_map(|(amount, scale, octaves, seed)| Detail {
            amount,
            scale,
            octaves,
            seed,
        }),
    )
}

/// The editor's terrain equals a full regeneration of its document to the bit.
/// No erosion, or erosion of a random talus, 1 to 8 steps and amount.
pub(crate) fn erosion() -> impl Strategy<Value = Option<Erosion>> {
    prop::option::of(
        (5.0..80.0f64, 1u32..=8, 0.0..=1.0f64).prop_map(|(talus, iterations, amount)| Erosion {
            talus,
            iterations,
            amount,
            fluvial: None,
        }),
    )
}

#[track_caller]
fn assert_matches_full(editor: &Editor, context: &str) {
    let full = generate(editor.document()).unwrap();
    if let Some((c, r, a, b)) = first_bit_difference(editor.heightmap(), &full) {
        panic!("{context}: incremental {a} vs full {b} at ({c}, {r})");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// After any sequence of edits (pulls, slopes, moved figures and points, figures added and
    /// deleted, nested closed figures; refused ones included), the incrementally updated terrain
    /// equals a full regeneration of the document to the bit, and a refused edit leaves the
    /// document and terrain exactly as they were; in either metric, with or without detail.
    #[test]
    fn incremental_equals_full(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..14), metric in metric(), detail in detail(), erosion in erosion()) {
        doc.terrain.metric = metric;
        doc.terrain.detail = detail;
        doc.terrain.erosion = erosion;
        let mut editor = Editor::new(doc).unwrap();
        for (n, op) in ops.iter().enumerate() {
            let Some(edit) = edit_for(editor.document(), op) else { continue };
            let (before_doc, before_map) = (editor.document().clone(), editor.heightmap().clone());
            match editor.apply(edit.clone()) {
                Ok(_) => assert_matches_full(&editor, &format!("after op {n} {edit:?}")),
                Err(_) => {
                    prop_assert_eq!(editor.document(), &before_doc);
                    prop_assert_eq!(editor.heightmap(), &before_map);
                }
            }
        }
    }

    /// Edits of shape alone (moves, points, figures added and deleted: no pull) leave a terrain
    /// equal to a full regeneration to the bit, in either metric, with or without detail and
    /// erosion: each rebuilt region is painted from its coefficients in the full regeneration's
    /// order, and the detail and the erosion are functions of that terrain.
    #[test]
    fn shape_edits_equal_full_to_the_bit(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..14), metric in metric(), detail in detail(), erosion in erosion()) {
        doc.terrain.metric = metric;
        doc.terrain.detail = detail;
        doc.terrain.erosion = erosion;
        let mut editor = Editor::new(doc).unwrap();
        for op in ops.iter().filter(|op| !matches!(op, Op::Height(..) | Op::Slope(..) | Op::Undo | Op::Redo)) {
            let Some(edit) = edit_for(editor.document(), op) else { continue };
            if editor.apply(edit.clone()).is_ok() {
                let bits = |m: &penmodel_terrain::Heightmap| m.heights().iter().map(|h| h.to_bits()).collect::<Vec<_>>();
                prop_assert!(bits(editor.heightmap()) == bits(&generate(editor.document()).unwrap()), "after {:?}", edit);
            }
        }
    }

    /// A drag as the pen makes it: pulls and slope changes shown as unrecorded previews (several
    /// steps of one figure, then another), between recorded edits of shape; after every step the
    /// terrain equals a full regeneration of the document to the bit (issue 18).
    #[test]
    fn drags_equal_full_to_the_bit(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..20), steps in 1usize..4, metric in metric()) {
        doc.terrain.metric = metric;
        let mut editor = Editor::new(doc).unwrap();
        for (n, op) in ops.iter().enumerate() {
            let Some(edit) = edit_for(editor.document(), op) else { continue };
            match &edit {
                Edit::SetHeight { at, height } => {
                    for step in 0..steps {
                        let height = height + step as f64 * 0.75;
                        if editor.preview(&Edit::SetHeight { at: at.clone(), height }).is_ok() {
                            assert_matches_full(&editor, &format!("pull step {step} of op {n} {edit:?}"));
                        }
                    }
                }
                Edit::SetSlope { at, slope } => {
                    for step in 0..steps {
                        let slope = (slope + step as f64 * 0.25).min(4.0);
                        if editor.preview(&Edit::SetSlope { at: at.clone(), slope }).is_ok() {
                            assert_matches_full(&editor, &format!("slope step {step} of op {n} {edit:?}"));
                        }
                    }
                }
                _ => {
                    if editor.apply(edit.clone()).is_ok() {
                        assert_matches_full(&editor, &format!("after op {n} {edit:?}"));
                    }
                }
            }
        }
    }

    /// Undo all returns the exact first document, redo all the exact last one; each undo and redo
    /// step regenerates correctly.
    #[test]
    fn undo_redo_exact(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..12), metric in metric()) {
        doc.terrain.metric = metric;
        let mut editor = Editor::new(doc.clone()).unwrap();
        let mut docs = vec![doc.clone()];
        for op in &ops {
            if let Some(edit) = edit_for(editor.document(), op) && editor.apply(edit).is_ok() {
                docs.push(editor.document().clone());
            }
        }
        let last = editor.document().clone();
        for expected in docs.iter().rev().skip(1) {
            prop_assert!(editor.undo().unwrap().is_some());
            prop_assert_eq!(editor.document(), expected);
            assert_matches_full(&editor, "after undo");
        }
        prop_assert!(editor.undo().unwrap().is_none());
        prop_assert_eq!(editor.document(), &doc);
        while editor.redo().unwrap().is_some() {}
        prop_assert_eq!(editor.document(), &last);
        assert_matches_full(&editor, "after redo");
    }

    /// A crash (the editor dropped without saving) loses nothing: reopening replays the journal
    /// to the same document, with the same undo history — also across a save in the middle.
    #[test]
    fn journal_replay_after_crash(doc in nested_document(), ops in prop::collection::vec(op(), 1..10), save_at in 0usize..10) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("terrain.json");
        let mut editor = Editor::create(&path, doc.clone()).unwrap();
        for (n, op) in ops.iter().enumerate() {
            if n == save_at {
                editor.save().unwrap();
            }
            match op {
                Op::Undo => { editor.undo().unwrap(); }
                Op::Redo => { editor.redo().unwrap(); }
                _ => if let Some(edit) = edit_for(editor.document(), op) { let _ = editor.apply(edit); },
            }
        }
        let expected = editor.document().clone();
        let expected_map = editor.heightmap().clone();
        let (can_undo, can_redo) = (editor.can_undo(), editor.can_redo());
        drop(editor); // the crash: no save

        let (mut reopened, _) = Editor::open(&path).unwrap();
        prop_assert_eq!(reopened.document(), &expected);
        prop_assert_eq!((reopened.can_undo(), reopened.can_redo()), (can_undo, can_redo));
        prop_assert!(first_bit_difference(reopened.heightmap(), &expected_map).is_none());
        // The whole history came back: undoing everything reaches the created document.
        while reopened.undo().unwrap().is_some() {}
        prop_assert_eq!(reopened.document(), &doc);
    }
}

fn sample() -> Document {
    document(
        40,
        vec![penmodel_terrain::Region {
            metric: None,
            boundary: polygon([20.0, 20.0], 15.0, 8, 0.1),
            figures: vec![
                point([14.2, 18.3], 30.0, -1.0),
                closed(
                    polygon([24.0, 22.0], 5.0, 6, 0.0),
                    12.0,
                    0.5,
                    vec![point([24.1, 22.2], 25.0, 0.0)],
                ),
            ],
        }],
    )
}

#[test]
fn refused_edits_name_the_problem() {
    let mut editor = Editor::new(sample()).unwrap();
    let outside = editor.apply(Edit::MoveFigure {
        at: FigurePath::new(0, 0),
        by: [30.0, 0.0],
    });
    let Err(EditorError::Edit(EditError::Invalid(e))) = outside else {
        panic!("{outside:?}")
    };
    assert_eq!(e.path, "regions[0].figures[0].points[0]");
    assert!(
        matches!(e.defect, Defect::Curve(CurveDefect::OutsideGrid { .. })),
        "{e}"
    );
    let nan = editor.apply(Edit::SetHeight {
        at: FigurePath::new(0, 1).child(0),
        height: f64::NAN,
    });
    let Err(EditorError::Edit(EditError::Invalid(e))) = nan else {
        panic!("{nan:?}")
    };
    assert_eq!(
        (e.path.as_str(), e.defect),
        ("regions[0].figures[1].figures[0].height", Defect::NotFinite)
    );
    let missing = editor.apply(Edit::DeleteFigure {
        at: FigurePath::new(0, 5),
    });
    assert!(
        matches!(&missing, Err(EditorError::Edit(EditError::NoFigure(at))) if *at == FigurePath::new(0, 5)),
        "{missing:?}"
    );
    assert_eq!(editor.document(), &sample());
}

#[test]
fn preview_is_not_recorded_and_commit_undoes_to_before() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let mut editor = Editor::create(&path, sample()).unwrap();
    let at = FigurePath::new(0, 0);
    for h in [31.0, 35.0, 40.0] {
        editor
            .preview(&Edit::SetHeight {
                at: at.clone(),
                height: h,
            })
            .unwrap();
    }
    assert_eq!(at.get(editor.document()).unwrap().height, 40.0);
    editor
        .apply(Edit::SetHeight {
            at: at.clone(),
            height: 42.0,
        })
        .unwrap();
    editor.undo().unwrap();
    assert_eq!(editor.document(), &sample());
    // Only the committed edit and its undo reached the journal.
    let text = fs::read_to_string(journal::path_for(&path)).unwrap();
    assert_eq!(text.lines().count(), 3, "{text}");
    assert!(text.lines().nth(1).unwrap().contains("\"height\":42.0"));
    // A refused commit keeps the preview, which cancelling then undoes.
    editor
        .preview(&Edit::SetHeight {
            at: at.clone(),
            height: 77.0,
        })
        .unwrap();
    assert!(
        editor
            .apply(Edit::SetHeight {
                at: at.clone(),
                height: f64::NAN
            })
            .is_err()
    );
    assert_eq!(at.get(editor.document()).unwrap().height, 77.0);
    editor.cancel_preview().unwrap();
    assert_eq!(editor.document(), &sample());
    // An uncommitted preview is cancelled by saving: the saved document has the old value.
    editor
        .preview(&Edit::SetHeight {
            at: at.clone(),
            height: 99.0,
        })
        .unwrap();
    editor.save().unwrap();
    assert_eq!(Document::load(&path).unwrap(), sample());
    assert_eq!(editor.document(), &sample());
}

#[test]
fn torn_last_line_is_dropped_and_stale_journal_set_aside() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let mut editor = Editor::create(&path, sample()).unwrap();
    editor
        .apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 50.0,
        })
        .unwrap();
    let after_one = editor.document().clone();
    drop(editor);
    // A crash in the middle of writing the next line.
    let jpath = journal::path_for(&path);
    let mut bytes = fs::read(&jpath).unwrap();
    bytes.extend_from_slice(b"{\"op\":\"do\",\"edit\":{\"op\":\"set_hei");
    fs::write(&jpath, &bytes).unwrap();
    let (mut editor, report) = Editor::open(&path).unwrap();
    assert_eq!(
        report,
        OpenReport {
            replayed: 1,
            dropped_torn_line: true,
            stale_journal: None,
            ignored_stale_journal: None,
            recovered: None,
        }
    );
    assert_eq!(editor.document(), &after_one);
    // Appending after the dropped fragment gives a clean journal.
    editor
        .apply(Edit::SetSlope {
            at: FigurePath::new(0, 0),
            slope: 2.0,
        })
        .unwrap();
    let after_two = editor.document().clone();
    drop(editor);
    let (editor, report) = Editor::open(&path).unwrap();
    assert_eq!((report.replayed, report.dropped_torn_line), (2, false));
    assert_eq!(editor.document(), &after_two);
    drop(editor); // the next writer would be refused while this one has it open

    // The document saved by someone else (or a crash between saving the document and starting
    // the new journal): the journal's base no longer matches, so it is not replayed again.
    after_two.save(&path).unwrap();
    let (editor, report) = Editor::open(&path).unwrap();
    assert_eq!(report.replayed, 0);
    let aside = report.stale_journal.expect("stale journal set aside");
    assert!(aside.exists());
    assert_eq!(editor.document(), &after_two);
}

#[test]
fn corrupt_journal_line_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let mut editor = Editor::create(&path, sample()).unwrap();
    editor
        .apply(Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 50.0,
        })
        .unwrap();
    drop(editor);
    let jpath = journal::path_for(&path);
    let mut text = fs::read_to_string(&jpath).unwrap();
    text.push_str("{\"op\":\"frobnicate\"}\n");
    fs::write(&jpath, text).unwrap();
    let err = Editor::open(&path).err().expect("refused");
    let msg = err.to_string();
    assert!(msg.contains("line 3"), "{msg}");
}

#[test]
fn an_edit_regenerates_only_its_region() {
    let mut doc = sample();
    doc.regions[0].boundary = polygon([12.0, 20.0], 9.0, 8, 0.1);
    doc.regions[0].figures = vec![point([11.0, 19.0], 30.0, -1.0)];
    doc.regions.push(penmodel_terrain::Region {
        metric: None,
        boundary: polygon([31.0, 20.0], 7.0, 8, 0.1),
        figures: vec![point([31.0, 21.0], 20.0, 0.0)],
    });
    let mut editor = Editor::new(doc).unwrap();
    let region1 = penmodel_terrain::cells::closed_mask(&editor.document().grid, &editor.document().regions[1].boundary);
    let before = editor.heightmap().clone();
    for edit in [
        Edit::SetHeight {
            at: FigurePath::new(0, 0),
            height: 44.0,
        },
        Edit::SetSlope {
            at: FigurePath::new(0, 0),
            slope: 1.0,
        },
        Edit::MoveFigure {
            at: FigurePath::new(0, 0),
            by: [1.5, -0.5],
        },
        Edit::MovePoint {
            curve: CurvePath::Boundary(0),
            index: 2,
            to: [14.0, 27.5],
        },
    ] {
        let out = editor.apply(edit.clone()).unwrap();
        // The changed rectangle lies left of region 1's box, and region 1's heights are untouched.
        assert!(
            out.changed.c0 + out.changed.width <= region1.c0,
            "{edit:?}: {:?}",
            out.changed
        );
        for (c, r) in region1.cells() {
            assert_eq!(editor.heightmap().get(c, r).to_bits(), before.get(c, r).to_bits());
        }
        assert_matches_full(&editor, &format!("{edit:?}"));
    }
}

#[test]
fn a_pull_with_a_slope_is_one_step() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.json");
    let mut editor = Editor::create(&path, sample()).unwrap();
    let at = FigurePath::new(0, 0);
    let before = at.get(editor.document()).unwrap().clone();
    for h in [20.0, 45.0] {
        editor
            .preview(&Edit::SetHeight {
                at: at.clone(),
                height: h,
            })
            .unwrap();
    }
    for s in [-0.5, -1.5] {
        editor
            .preview(&Edit::SetSlope {
                at: at.clone(),
                slope: s,
            })
            .unwrap();
    }
    // Previewing the slope kept the height.
    assert_eq!(at.get(editor.document()).unwrap().height, 45.0);
    let committed = editor.commit_preview().unwrap().expect("something to commit");
    assert!(
        matches!(&committed, Edit::Group { edits } if edits.len() == 2),
        "{committed:?}"
    );
    let after = editor.document().clone();
    assert_eq!(editor.commit_preview().unwrap(), None, "nothing left to commit");
    // The terrain equals a fresh generation of the committed document.
    assert_eq!(editor.heightmap(), &generate(&after).unwrap());
    // One undo restores both.
    editor.undo().unwrap();
    assert_eq!(at.get(editor.document()).unwrap(), &before);
    assert!(!editor.can_undo());
    editor.redo().unwrap();
    assert_eq!(editor.document(), &after);
    // The journal holds the group, and replaying it gives the same document.
    drop(editor);
    let (reopened, report) = Editor::open(&path).unwrap();
    assert!(report.replayed >= 3, "{report:?}");
    assert_eq!(reopened.document(), &after);
}

#[test]
fn a_refused_group_changes_nothing() {
    let mut editor = Editor::new(sample()).unwrap();
    let at = FigurePath::new(0, 0);
    let group = Edit::Group {
        edits: vec![
            Edit::SetHeight {
                at: at.clone(),
                height: 12.0,
            },
            Edit::SetSlope {
                at: FigurePath::new(0, 9),
                slope: 1.0,
            },
        ],
    };
    let refused = editor.apply(group);
    assert!(
        matches!(&refused, Err(EditorError::Edit(EditError::NoFigure(at))) if *at == FigurePath::new(0, 9)),
        "{refused:?}"
    );
    assert_eq!(editor.document(), &sample());
    assert_eq!(editor.heightmap(), &generate(&sample()).unwrap());
    assert!(!editor.can_undo());
}

/// The engine follows the document it is given: the document after an edit, and the scope the
/// edit reports. A scope that does not fit the engine's regions regenerates everything.
#[test]
fn the_engine_updates_from_the_document_and_a_scope() {
    let mut doc = sample();
    let mut terrain = TerrainEngine::new(&doc).unwrap();
    let at = FigurePath::new(0, 1).child(0);
    let applied = Edit::SetHeight { at, height: 44.0 }.apply_to(&mut doc).unwrap();
    assert_eq!(applied.scope, Scope::Height(FigurePath::new(0, 1).child(0)));
    let changed = terrain.update(&doc, &applied.scope);
    assert!(changed.width > 0 && changed.height > 0);
    assert_eq!(
        first_bit_difference(terrain.heightmap(), &generate(&doc).unwrap()),
        None
    );

    Edit::DeleteFigure {
        at: FigurePath::new(0, 0),
    }
    .apply_to(&mut doc)
    .unwrap();
    let changed = terrain.update(&doc, &Scope::RegionRemoved(3));
    assert_eq!((changed.width, changed.height), (doc.grid.cols, doc.grid.rows));
    assert_eq!(terrain.heightmap(), &generate(&doc).unwrap());
}
