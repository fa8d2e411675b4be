//! The engine's two copies of its hot loops (`penmodel_terrain::simd`: the baseline x86-64 one
//! and the AVX2 one the CPU picks at run time) give the same terrain to the bit, so the baseline
//! copy stays tested on a machine that runs the AVX2 one. On a CPU without AVX2 both runs take
//! the baseline copy (the tests say so on stderr).

use std::path::PathBuf;
use std::sync::{Mutex, PoisonError};

use crate::common::*;
use crate::editing::{Op, detail, edit_for, erosion, metric, op};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::{Document, Heightmap, Metric, generate, simd};
use proptest::prelude::*;

/// The tests that switch the copies, one at a time (the switch is the whole process's).
static SWITCH: Mutex<()> = Mutex::new(());

/// Forces the baseline copies while it lives (and holds the switch).
struct Baseline<'a>(#[allow(dead_code)] std::sync::MutexGuard<'a, ()>);

/// Runs `f` with the baseline copies forced, then with the CPU's choice: the two results.
fn both<T>(mut f: impl FnMut() -> T) -> (T, T) {
    let guard = SWITCH.lock().unwrap_or_else(PoisonError::into_inner);
    simd::force_baseline(true);
    let on = Baseline(guard);
    let baseline = f();
    drop(on);
    (baseline, f())
}

impl Drop for Baseline<'_> {
    fn drop(&mut self) {
        simd::force_baseline(false);
    }
}

fn bits(map: &Heightmap) -> Vec<u32> {
    map.heights().iter().map(|h| h.to_bits()).collect()
}

#[test]
fn both_copies_give_the_examples_the_same_terrain() {
    if !simd::has_avx2() {
        eprintln!("no AVX2 on this CPU: both runs took the baseline copies");
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 5);
    for path in paths {
        let doc = Document::load(&path).unwrap();
        for metric in [Metric::Taxicab, Metric::Euclidean] {
            // The example's own grid, and 256² over the same square.
            for n in [None, Some(256)] {
                let mut doc = doc.clone();
                doc.terrain.metric = metric;
                if let Some(n) = n {
                    let extent = doc.grid.width();
                    (doc.grid.cols, doc.grid.rows, doc.grid.cell_size) = (n, n, extent / f64::from(n));
                }
                let (baseline, avx2) = both(|| generate(&doc).unwrap());
                assert!(
                    bits(&baseline) == bits(&avx2),
                    "{} {metric:?} {n:?}: the copies differ",
                    path.display()
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Two editors, one run with the baseline copies and one with the CPU's choice, given the
    /// same edits (every kind: pulls, slopes, moves, figures added and deleted, undo, redo) hold
    /// the same terrain to the bit after each.
    #[test]
    fn both_copies_edit_to_the_same_terrain(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..14), metric in metric(), detail in detail(), erosion in erosion()) {
        doc.terrain.metric = metric;
        doc.terrain.detail = detail;
        doc.terrain.erosion = erosion;
        let (mut baseline, mut avx2) = both(|| Editor::new(doc.clone()).unwrap());
        prop_assert!(bits(baseline.heightmap()) == bits(avx2.heightmap()));
        for op in &ops {
            let step = |e: &mut Editor| match op {
                Op::Undo => e.undo().is_ok(),
                Op::Redo => e.redo().is_ok(),
                _ => edit_for(e.document(), op).is_some_and(|edit| e.apply(edit).is_ok()),
            };
            let mut which = 0;
            let (a, b) = both(|| {
                which += 1;
                step(if which == 1 { &mut baseline } else { &mut avx2 })
            });
            prop_assert_eq!(a, b);
            prop_assert!(bits(baseline.heightmap()) == bits(avx2.heightmap()), "after {:?}", op);
        }
    }
}
