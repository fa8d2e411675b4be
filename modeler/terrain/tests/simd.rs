//! The engine's copies of its hot loops (`penmodel_terrain::simd`: baseline x86-64, AVX2 and
//! AVX-512, the CPU's widest picked at run time) give the same terrain to the bit, so the
//! narrower copies stay tested on a machine that runs the widest. A copy the CPU lacks is not
//! compared (the tests say so on stderr).

use std::sync::{Mutex, PoisonError};

use crate::common::*;
use crate::editing::{Op, detail, edit_for, erosion, metric, op};
use penmodel_terrain::editor::Editor;
use penmodel_terrain::simd::{self, Level};
use penmodel_terrain::{Heightmap, Metric, generate};
use proptest::prelude::*;

/// The tests that switch the copies, one at a time (the switch is the whole process's).
static SWITCH: Mutex<()> = Mutex::new(());

/// The copies this CPU has, narrowest first.
fn levels() -> Vec<Level> {
    let all = [Level::Baseline, Level::Avx2, Level::Avx512];
    let have: Vec<Level> = all.into_iter().filter(|&l| l <= simd::available()).collect();
    if have.len() < all.len() {
        eprintln!("this CPU runs only the copies {have:?}: the others are not compared");
    }
    have
}

/// Lets the CPU choose its copy again when dropped (after a panic too).
struct Uncap;

impl Drop for Uncap {
    fn drop(&mut self) {
        simd::force_at_most(Level::Avx512);
    }
}

/// `f`'s result with each copy the CPU has, narrowest first.
fn each<T>(mut f: impl FnMut(Level) -> T) -> Vec<(Level, T)> {
    let _one = SWITCH.lock().unwrap_or_else(PoisonError::into_inner);
    let _uncap = Uncap;
    levels()
        .into_iter()
        .map(|level| {
            simd::force_at_most(level);
            assert_eq!(simd::level(), level);
            (level, f(level))
        })
        .collect()
}

fn bits(map: &Heightmap) -> Vec<u32> {
    map.heights().iter().map(|h| h.to_bits()).collect()
}

#[test]
fn the_copies_give_the_examples_the_same_terrain() {
    let examples = crate::examples::examples();
    assert_eq!(examples.len(), 5);
    for (name, doc) in examples {
        for metric in [Metric::Taxicab, Metric::Euclidean] {
            // The example's own grid, and 256² over the same square.
            for n in [None, Some(256)] {
                let mut doc = doc.clone();
                doc.terrain.metric = metric;
                if let Some(n) = n {
                    let extent = doc.grid.width();
                    (doc.grid.cols, doc.grid.rows, doc.grid.cell_size) = (n, n, extent / f64::from(n));
                }
                let maps = each(|_| bits(&generate(&doc).unwrap()));
                for (level, map) in &maps[1..] {
                    assert!(
                        *map == maps[0].1,
                        "{name} {metric:?} {n:?}: the {level:?} copy differs from the baseline"
                    );
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// One editor per copy the CPU has, each run with its copy, given the same edits (every
    /// kind: pulls, slopes, moves, figures added and deleted, undo, redo) hold the same terrain
    /// to the bit after each.
    #[test]
    fn the_copies_edit_to_the_same_terrain(mut doc in nested_document(), ops in prop::collection::vec(op(), 1..14), metric in metric(), detail in detail(), erosion in erosion()) {
        doc.terrain.metric = metric;
        doc.terrain.detail = detail;
        doc.terrain.erosion = erosion;
        let mut editors: Vec<(Level, Editor)> = each(|_| Editor::new(doc.clone()).unwrap());
        for op in &ops {
            let mut results = Vec::new();
            for (level, editor) in &mut editors {
                let _one = SWITCH.lock().unwrap_or_else(PoisonError::into_inner);
                let _uncap = Uncap;
                simd::force_at_most(*level);
                results.push(match op {
                    Op::Undo => editor.undo().is_ok(),
                    Op::Redo => editor.redo().is_ok(),
                    _ => edit_for(editor.document(), op).is_some_and(|edit| editor.apply(edit).is_ok()),
                });
            }
            prop_assert!(results.iter().all(|&r| r == results[0]));
            let first = bits(editors[0].1.heightmap());
            for (level, editor) in &editors[1..] {
                prop_assert!(bits(editor.heightmap()) == first, "{:?} copy, after {:?}", level, op);
            }
        }
    }
}
