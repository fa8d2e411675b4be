//! The terrain's revisions: a number that moves with every change of the heights, and the
//! rectangles the last changes touched, so that whoever keeps something made from the heights
//! (the renderer's land maps, issue 20) can ask what changed since it made it instead of
//! comparing every height.
//!
//! A [`Revisions`] belongs to one terrain's history (an [`Editor`](crate::Editor)): its *lineage*
//! is a number no other history in the process shares, so a [`Mark`] taken from one terrain never
//! answers for another. The log keeps the last [`KEPT`] changes; asking about an older mark, or
//! another lineage's, answers `None`: "everything may have changed".

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::rect::Rect;

/// Changes the log keeps: a renderer a few frames behind finds its mark; one further behind
/// remakes everything, which is what it would do anyway after that many changes.
pub const KEPT: usize = 64;

/// A point in a terrain's history.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Mark {
    /// The history's number, unique in the process.
    pub lineage: u64,
    /// Changes recorded before this point.
    pub number: u64,
}

/// A terrain's history of changes: the current [`Mark`] and the last [`KEPT`] changed rectangles.
#[derive(Debug, Clone)]
pub struct Revisions {
    now: Mark,
    /// `(number after the change, cells it changed)`, oldest first.
    log: VecDeque<(u64, Rect)>,
}

impl Default for Revisions {
    fn default() -> Revisions {
        Revisions::new()
    }
}

impl Revisions {
    /// A new history at number 0, of a lineage no other history shares.
    pub fn new() -> Revisions {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        Revisions {
            now: Mark {
                lineage: NEXT.fetch_add(1, Ordering::Relaxed),
                number: 0,
            },
            log: VecDeque::with_capacity(KEPT),
        }
    }

    /// The current point.
    pub fn mark(&self) -> Mark {
        self.now
    }

    /// Records that the heights in `rect` may have changed; an empty rectangle is no change.
    pub fn record(&mut self, rect: Rect) {
        if rect.width == 0 || rect.height == 0 {
            return;
        }
        self.now.number += 1;
        if self.log.len() == KEPT {
            self.log.pop_front();
        }
        self.log.push_back((self.now.number, rect));
    }

    /// The cells that may have changed since `mark` ([`Rect::EMPTY`] when none), or `None` when
    /// this history cannot say: `mark` is another lineage's, from its future, or older than the
    /// log.
    pub fn since(&self, mark: Mark) -> Option<Rect> {
        if mark.lineage != self.now.lineage || mark.number > self.now.number {
            return None;
        }
        if mark.number == self.now.number {
            return Some(Rect::EMPTY);
        }
        // The changes numbered mark.number + 1 ..= now must all be in the log.
        let oldest = self.log.front().map_or(u64::MAX, |&(n, _)| n);
        if oldest > mark.number + 1 {
            return None;
        }
        Some(
            self.log
                .iter()
                .filter(|&&(n, _)| n > mark.number)
                .fold(Rect::EMPTY, |acc, &(_, r)| acc.union(r)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(c0: u32, r0: u32, width: u32, height: u32) -> Rect {
        Rect { c0, r0, width, height }
    }

    #[test]
    fn since_is_the_union_of_the_later_changes_and_none_when_it_cannot_say() {
        let mut a = Revisions::new();
        let start = a.mark();
        assert_eq!(a.since(start), Some(Rect::EMPTY));
        a.record(rect(2, 3, 4, 5));
        a.record(Rect::EMPTY);
        let middle = a.mark();
        assert_eq!(middle.number, 1, "an empty change is none");
        a.record(rect(10, 1, 1, 1));
        assert_eq!(a.since(start), Some(rect(2, 1, 9, 7)));
        assert_eq!(a.since(middle), Some(rect(10, 1, 1, 1)));
        assert_eq!(a.since(a.mark()), Some(Rect::EMPTY));
        let b = Revisions::new();
        assert_eq!(a.since(b.mark()), None, "another lineage");
        assert_eq!(b.since(a.mark()), None);
        for _ in 0..KEPT {
            a.record(rect(0, 0, 1, 1));
        }
        assert_eq!(a.since(start), None, "older than the log");
        let recent = Mark {
            number: a.mark().number - KEPT as u64,
            ..a.mark()
        };
        assert_eq!(a.since(recent), Some(rect(0, 0, 1, 1)));
    }
}
