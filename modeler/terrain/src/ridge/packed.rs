//! A direction's lines as blocks stored over only the columns their lines cross, swept in passes
//! of bounded size.
//!
//! A block held over every column, as the sweeps first did, makes lines × columns values: for a
//! long grid that is the square of its long side (issue 47: 65536 × 256 asked for 14.4 GB,
//! 16777216 × 1 for 224 TB). Packed, the blocks hold what their lines sample, O(cells) in all;
//! passes of at most [`Passes::budget`] values (but one block) keep even that bounded, and a
//! pass spreads only over the columns its blocks cross. Blocks are spread to a cell in block
//! order whatever the passes, so the sums — and the bits — are those of one pass over all.

use std::ops::Range;

use super::sections::Sections;

/// The packed blocks of `nb` lines of one direction.
pub(super) struct Packed {
    /// The first line and the end of the lines.
    start: isize,
    end: isize,
    nb: usize,
    /// Per block: the columns where any of its lines is on the grid (empty when none is).
    cols: Vec<Range<usize>>,
    /// Per block, the values of the blocks before it (and their total at the end).
    at: Vec<usize>,
}

impl Packed {
    pub fn new(lines: &Sections, nb: usize) -> Packed {
        let all = lines.lines();
        let blocks = all.len().div_ceil(nb);
        let cols = (0..blocks)
            .map(|k| {
                let b0 = all.start + (k * nb) as isize;
                let (mut u0, mut u1) = (usize::MAX, 0);
                for b in b0..b0 + nb as isize {
                    let c = lines.columns(b);
                    if !c.is_empty() {
                        (u0, u1) = (u0.min(c.start), u1.max(c.end));
                    }
                }
                if u0 < u1 { u0..u1 } else { 0..0 }
            })
            .collect::<Vec<Range<usize>>>();
        let at = std::iter::once(0)
            .chain(cols.iter().scan(0, |sum, c| {
                *sum += c.len() * nb;
                Some(*sum)
            }))
            .collect();
        Packed {
            start: all.start,
            end: all.end,
            nb,
            cols,
            at,
        }
    }

    /// Block k's first line and columns.
    pub fn block(&self, k: usize) -> (isize, Range<usize>) {
        (self.start + (k * self.nb) as isize, self.cols[k].clone())
    }

    /// Consecutive runs of blocks of at most `budget` values each (a block bigger than that on
    /// its own), in order.
    pub fn passes(&self, budget: usize) -> Vec<Range<usize>> {
        let mut out = Vec::new();
        let (mut k0, mut size) = (0, 0);
        for (k, c) in self.cols.iter().enumerate() {
            let n = c.len() * self.nb;
            if size > 0 && size + n > budget {
                out.push(k0..k);
                (k0, size) = (k, 0);
            }
            size += n;
        }
        if k0 < self.cols.len() {
            out.push(k0..self.cols.len());
        }
        out
    }

    /// The blocks of `pass` as disjoint parts of `values` (resized to fit), with their index.
    pub fn split<'a>(&self, pass: Range<usize>, values: &'a mut Vec<f32>) -> Vec<(usize, &'a mut [f32])> {
        let total = self.at[pass.end] - self.at[pass.start];
        values.clear();
        values.resize(total, 0.0);
        let mut rest = &mut values[..];
        pass.map(|k| {
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(self.cols[k].len() * self.nb);
            rest = tail;
            (k, part)
        })
        .collect()
    }

    /// The columns any block of `pass` crosses.
    pub fn columns(&self, pass: Range<usize>) -> Range<usize> {
        let (mut u0, mut u1) = (usize::MAX, 0);
        for c in self.cols[pass].iter().filter(|c| !c.is_empty()) {
            (u0, u1) = (u0.min(c.start), u1.max(c.end));
        }
        if u0 < u1 { u0..u1 } else { 0..0 }
    }

    /// Calls `f(b0, values)` for the blocks of `pass` with a line sampled at column u, in block
    /// order: the block's first line and its `nb` (fewer in the last block) values at u, from
    /// `values` laid out as [`Packed::split`] made it.
    pub fn at_column(
        &self,
        lines: &Sections,
        pass: Range<usize>,
        values: &[f32],
        u: usize,
        mut f: impl FnMut(isize, &[f32]),
    ) {
        let at = lines.lines_at(u);
        if at.is_empty() {
            return;
        }
        let block_of = |b: isize| ((b - self.start).max(0) as usize / self.nb).clamp(pass.start, pass.end);
        let (k0, k1) = (block_of(at.start), (block_of(at.end - 1) + 1).min(pass.end));
        for k in k0..k1 {
            let c = &self.cols[k];
            if c.contains(&u) {
                let b0 = self.start + (k * self.nb) as isize;
                let n = self.nb.min((self.end - b0) as usize);
                let i = self.at[k] - self.at[pass.start] + (u - c.start) * self.nb;
                f(b0, &values[i..i + n]);
            }
        }
    }
}
