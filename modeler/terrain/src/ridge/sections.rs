//! The parallel sections of the horizon sweep ([`super::sun`], Alg. 3.1), and the upper-hull
//! pass along one that the tests compare the lanes of [`super::walk`] with.
//!
//! For a direction whose dominant axis is u (the grid's columns; a column-major direction works
//! on the transposed grid) with slope `t = dv/du` in [−1, 1], line b samples column u at row
//! `v = b + u·t`, the height interpolated linearly between rows `⌊v⌋` and `⌊v⌋ + 1`. With b an
//! integer, the row offset `⌊u·t⌋` and the upper row's weight `frac(u·t)` depend on u alone: all
//! lines are translates of line 0. Both are tabled once per direction, so a line's samples and
//! the spreading of their values back to the cells cost no position arithmetic per sample.

use std::ops::Range;

use rayon::prelude::*;

/// One direction's lines over a `w × h` grid (row-major, u along the rows).
pub(super) struct Sections {
    w: usize,
    h: usize,
    /// Per column u: `⌊u·t⌋`.
    o: Vec<isize>,
    /// Per column u: `⌊u·t⌋·w + u`, line 0's lower cell there (line b adds `b·w`).
    off: Vec<isize>,
    /// Per column u: the lower row's weight `1 − frac(u·t)` and the upper row's `frac(u·t)`.
    lo: Vec<f32>,
    hi: Vec<f32>,
    /// Whether `t ≥ 0` (rows grow with u).
    rising: bool,
    /// Metres between neighbouring samples of a line.
    pub spacing: f32,
}

impl Sections {
    /// The lines of slope `t` (|t| ≤ 1) over a `w × h` grid of `cell`-metre cells.
    pub fn new(w: usize, h: usize, t: f64, cell: f64) -> Sections {
        let mut s = Sections {
            w,
            h,
            o: Vec::with_capacity(w),
            off: Vec::with_capacity(w),
            lo: Vec::with_capacity(w),
            hi: Vec::with_capacity(w),
            rising: t >= 0.0,
            spacing: ((1.0 + t * t).sqrt() * cell) as f32,
        };
        for u in 0..w {
            let p = u as f64 * t;
            let o = p.floor();
            let hi = (p - o) as f32;
            s.o.push(o as isize);
            s.off.push(o as isize * w as isize + u as isize);
            s.lo.push(1.0 - hi);
            s.hi.push(hi);
        }
        s
    }

    /// The lines with samples on the grid (some at the ends may have none).
    pub fn lines(&self) -> Range<isize> {
        let (min, max) = self.o.iter().fold((0, 0), |(a, b), &o| (o.min(a), o.max(b)));
        -max..self.h as isize - min
    }

    /// The columns where line b's samples lie on the grid: both rows inside (or the upper one's
    /// weight 0). Consecutive, as `u·t` is monotonic.
    pub fn columns(&self, b: isize) -> Range<usize> {
        let last = self.h as isize - 1;
        let (o, hi) = (&self.o, &self.hi);
        let top = |u: usize| b + o[u] + isize::from(hi[u] > 0.0);
        let n = self.w;
        let (start, end) = if self.rising {
            (part(n, |u| b + o[u] < 0), part(n, |u| top(u) <= last))
        } else {
            (part(n, |u| top(u) > last), part(n, |u| b + o[u] >= 0))
        };
        start..end.max(start)
    }

    /// The lines `b0..b0 + nb` valid at column u, as indices from b0.
    #[inline]
    fn valid(&self, u: usize, b0: isize, nb: usize) -> Range<usize> {
        let first = -self.o[u];
        let last = self.h as isize - 1 - self.o[u] - isize::from(self.hi[u] > 0.0);
        let start = (first - b0).clamp(0, nb as isize) as usize;
        let end = (last + 1 - b0).clamp(0, nb as isize) as usize;
        start..end.max(start)
    }

    /// The lines with a sample at column u (both its rows on the grid, or the upper one's weight
    /// 0): those whose lower row there is in `0..h`, less the last when the upper row counts.
    pub fn lines_at(&self, u: usize) -> Range<isize> {
        let first = -self.o[u];
        let last = self.h as isize - 1 - self.o[u] - isize::from(self.hi[u] > 0.0);
        first..(last + 1).max(first)
    }

    /// The heights of lines `b0..b0 + nb` into `block[(u − u0)·nb + j]` (line `b0 + j`, column
    /// u ≥ u0) where the line is on the grid. `zc` is the grid with its columns contiguous (`zc[u·h + v]`),
    /// an element more: per column the lines' samples are then one shifted linear interpolation
    /// of contiguous cells (vectorised).
    pub fn block_heights(&self, zc: &[f32], b0: isize, nb: usize, u0: usize, block: &mut [f32]) {
        for (u, dst) in block.chunks_exact_mut(nb).enumerate().map(|(i, d)| (u0 + i, d)) {
            if u >= self.w {
                break;
            }
            let j = self.valid(u, b0, nb);
            if j.is_empty() {
                continue;
            }
            let at = ((u * self.h) as isize + b0 + j.start as isize + self.o[u]) as usize;
            let (lo, hi, m) = (self.lo[u], self.hi[u], j.len());
            for ((d, &a), &b) in dst[j].iter_mut().zip(&zc[at..at + m]).zip(&zc[at + 1..at + 1 + m]) {
                *d = a * lo + b * hi;
            }
        }
    }

    /// Adds column u of a block (`src`, laid out like a column's chunk of
    /// [`Sections::block_heights`]'s block: line `b0 + j` at j) to the cells its values were
    /// sampled from, weighted like the heights, in `col`: the `h` cells of column u (`zc`'s
    /// layout). Blocks added to a column in the same order give the same bits whichever thread
    /// adds them.
    #[inline]
    pub fn column_spread(&self, u: usize, b0: isize, src: &[f32], col: &mut [f32]) {
        let j = self.valid(u, b0, src.len());
        if j.is_empty() {
            return;
        }
        let at = (b0 + j.start as isize + self.o[u]) as usize;
        let (lo, hi, m) = (self.lo[u], self.hi[u], j.len());
        let src = &src[j];
        for (d, &v) in col[at..at + m].iter_mut().zip(src) {
            *d += lo * v;
        }
        // A weight-0 upper row may lie past the column's last cell.
        if hi > 0.0 {
            for (d, &v) in col[at + 1..at + 1 + m].iter_mut().zip(src) {
                *d += hi * v;
            }
        }
    }

    /// [`Sections::column_spread`] with the weights summed into `weights` (as `col`), skipping
    /// NaN values: the weighted mean of a cell's samples is then `col / weights`.
    #[inline]
    pub fn column_spread_weighted(&self, u: usize, b0: isize, src: &[f32], col: &mut [f32], weights: &mut [f32]) {
        let j = self.valid(u, b0, src.len());
        if j.is_empty() {
            return;
        }
        let at = (b0 + j.start as isize + self.o[u]) as usize;
        let (lo, hi) = (self.lo[u], self.hi[u]);
        for (k, &v) in src[j].iter().enumerate() {
            if v.is_nan() {
                continue;
            }
            col[at + k] += lo * v;
            weights[at + k] += lo;
            // A weight-0 upper row may lie past the column's last cell.
            if hi > 0.0 {
                col[at + k + 1] += hi * v;
                weights[at + k + 1] += hi;
            }
        }
    }

    /// The weight all lines together give cell `(u, r)` when every sample is spread: 1 but on
    /// the first and last rows, where one of the cell's two lines has no sample.
    pub fn weight(&self, u: usize, r: usize) -> f32 {
        let (lo, hi) = (self.lo[u], self.hi[u]);
        // The line whose lower row is r, and the one whose upper row is r.
        let below = if r + usize::from(hi > 0.0) < self.h { lo } else { 0.0 };
        if r >= 1 { below + hi } else { below }
    }
}

/// The first index in `0..n` where `f` is false, `f` true on a prefix.
fn part(n: usize, f: impl Fn(usize) -> bool) -> usize {
    let (mut a, mut b) = (0, n);
    while a < b {
        let m = (a + b) / 2;
        if f(m) { a = m + 1 } else { b = m }
    }
    a
}

/// The upper hull of the samples swept so far, in two `f32` stacks reused from line to line:
/// one line's walk at a time, as the sky view and the direct light walked before their lines
/// went side by side ([`super::walk`]); kept as the reference the lanes are tested against.
///
/// Two stacks rather than one of `(f32, f32)` pairs: the pop test reads the vertex pushed one
/// sample earlier, and a pair written as two 4-byte stores and read back as one 8-byte load
/// cannot be forwarded from the store buffer, a stall on every sample. Same-width stores and
/// loads forward.
#[cfg(test)]
#[derive(Default)]
pub(super) struct Hull {
    s: Vec<f32>,
    h: Vec<f32>,
}

#[cfg(test)]
impl Hull {
    /// Sweeps a line's heights `z` from the far end back — from the last sample to the first
    /// when `AHEAD_UP` (ahead is increasing index), else from the first — keeping the upper
    /// hull of the samples passed (those ahead). Sample k's horizon is the tangent
    /// `rise[k] / (steps[k] · spacing)` to the hull, `steps[k] ≥ 1` samples ahead; the first
    /// sample swept has nothing ahead: `rise` NaN. Samples under the hull are popped for good:
    /// O(1) amortised per sample.
    #[inline]
    pub fn pass<const AHEAD_UP: bool>(&mut self, z: &[f32], rise: &mut [f32], steps: &mut [f32]) {
        let samples = z.iter().zip(rise.iter_mut().zip(steps.iter_mut()));
        if AHEAD_UP {
            self.run(z.len(), samples.rev());
        } else {
            self.run(z.len(), samples);
        }
    }

    /// The stacks for a line of n samples, a power of two above n + 1 long (indices masked with
    /// the returned mask need no bounds checks), with the bottom vertex in place.
    #[inline(always)]
    fn stacks(&mut self, n: usize) -> (usize, (&mut [f32], &mut [f32])) {
        let cap = (n + 1).next_power_of_two();
        if self.s.len() < cap {
            self.s.resize(cap, 0.0);
            self.h.resize(cap, 0.0);
        }
        let (ss, hs) = (&mut self.s[..cap], &mut self.h[..cap]);
        // At the bottom a vertex no line to the next one passes over (infinitely low), so
        // that the pop test needs no check for an empty stack.
        ss[0] = 1.0;
        hs[0] = f32::NEG_INFINITY;
        (cap - 1, (ss, hs))
    }

    #[inline]
    fn run<'a>(&mut self, n: usize, mut samples: impl Iterator<Item = (&'a f32, (&'a mut f32, &'a mut f32))>) {
        let (mask, (ss, hs)) = self.stacks(n);
        let mut top = 1usize;
        let Some((&h0, (r0, d0))) = samples.next() else {
            return;
        };
        (*r0, *d0) = (f32::NAN, 1.0);
        // Positions: minus the sweep count, so that they grow ahead; exact integers in f32.
        let (mut h1, mut s) = (h0, 0.0f32);
        for (&h, (rise, steps)) in samples {
            s -= 1.0;
            (*rise, *steps) = step(ss, hs, mask, &mut top, &mut h1, s, h);
        }
    }
}

/// One sample of a hull walk: the sample at position s, height h; `h1` the previous sample's
/// height (one step ahead, not yet on the stacks `ss`, `hs` of `top` vertices). Returns the rise
/// and the steps to the horizon vertex, and leaves this sample as the previous one.
#[cfg(test)]
#[inline(always)]
fn step(ss: &mut [f32], hs: &mut [f32], mask: usize, top: &mut usize, h1: &mut f32, s: f32, h: f32) -> (f32, f32) {
    // The nearest vertex (the previous sample, one step ahead) relative to this one.
    let (mut a, mut b, mut hv) = (*h1 - h, 1.0f32, *h1);
    let mut t = *top;
    // Pop it while it lies on or under the line to the next one. Two tests a turn, so that the
    // vertex popped and the one under it need no register copies.
    loop {
        let i = (t - 1) & mask;
        let (h2, c) = (hs[i], ss[i] - s);
        let d = h2 - h;
        if a * c > d * b {
            break;
        }
        t -= 1;
        let i = (t - 1) & mask;
        let (h3, e) = (hs[i], ss[i] - s);
        let f = h3 - h;
        if d * e > f * c {
            (a, b, hv) = (d, c, h2);
            break;
        }
        t -= 1;
        (a, b, hv) = (f, e, h3);
    }
    // b + s is the vertex's position, exactly (integers).
    ss[t & mask] = b + s;
    hs[t & mask] = hv;
    *top = t + 1;
    *h1 = h;
    (a, b)
}

/// `z` (`cols × rows`, row-major) transposed: `rows × cols`, followed by `pad` zeros. In tiles,
/// so that both the reads and the writes stay within a few cache lines and pages (a plain
/// column walk misses the cache on every cell of a large grid).
pub(super) fn transpose(z: &[f32], cols: usize, rows: usize, pad: usize) -> Vec<f32> {
    const TILE: usize = 64;
    let (w, h) = (cols, rows);
    let mut t = super::scratch::zeros(z.len() + pad);
    // Each task writes TILE rows of the result (TILE columns of `z`).
    t[..z.len()]
        .par_chunks_mut(h.max(1) * TILE)
        .enumerate()
        .for_each(|(tc, out)| {
            let c0 = tc * TILE;
            let nc = out.len() / h.max(1);
            for r0 in (0..h).step_by(TILE) {
                for c in c0..c0 + nc {
                    let dst = &mut out[(c - c0) * h..(c - c0 + 1) * h];
                    for r in r0..(r0 + TILE).min(h) {
                        dst[r] = z[r * w + c];
                    }
                }
            }
        });
    t
}
