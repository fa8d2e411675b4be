//! Alg. 2.1's low-pass filter: `passes` rounds of a separable box filter of half-width `radius`
//! cells (a row pass then a column pass, each the mean of `2·radius + 1` cells, the grid's edge
//! cells repeated beyond it). Repeated box filters approach a Gaussian of standard deviation
//! `radius·√(2·passes/3)` cells. 0 passes (or radius 0) leaves the maximum unfiltered.
//!
//! Every output cell is summed in the same order whether the whole grid or a rectangle of it is
//! filtered ([`apply`]), which is what keeps incremental updates bit-identical to a rebuild.

use rayon::prelude::*;

use crate::rect::Rect;

/// The filter's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Filter {
    /// Half-width of the box in cells.
    pub radius: u32,
    /// How many times the box is applied.
    pub passes: u32,
}

impl Filter {
    /// The default: radius 1, 2 passes (a 5-cell-wide bell).
    pub const DEFAULT: Filter = Filter { radius: 1, passes: 2 };

    /// No filtering.
    pub const NONE: Filter = Filter { radius: 0, passes: 0 };

    /// How far, in cells, a change in the input reaches in the output.
    pub fn reach(&self) -> u32 {
        if self.radius == 0 {
            0
        } else {
            self.radius.saturating_mul(self.passes)
        }
    }
}

/// Grows `r` by `by` cells on every side, clamped to the `cols × rows` grid.
pub fn grow(r: Rect, by: u32, cols: u32, rows: u32) -> Rect {
    if r.width == 0 || r.height == 0 {
        return r;
    }
    let c0 = r.c0.saturating_sub(by);
    let r0 = r.r0.saturating_sub(by);
    let c1 = (r.c0 + r.width).saturating_add(by).min(cols);
    let r1 = (r.r0 + r.height).saturating_add(by).min(rows);
    Rect {
        c0,
        r0,
        width: c1 - c0,
        height: r1 - r0,
    }
}

/// Writes the filtered `input` (a `cols`-wide row-major grid) into `out` over `rect`; `out`'s
/// other cells are left alone.
pub fn apply(input: &[f32], cols: u32, filter: Filter, rect: Rect, out: &mut [f32]) {
    let rows = (input.len() / cols.max(1) as usize) as u32;
    let w = cols as usize;
    if rect.width == 0 || rect.height == 0 {
        return;
    }
    if filter.reach() == 0 {
        for r in rect.r0..rect.r0 + rect.height {
            let s = r as usize * w + rect.c0 as usize;
            out[s..s + rect.width as usize].copy_from_slice(&input[s..s + rect.width as usize]);
        }
        return;
    }
    // The input rectangle every pass reads from; cells outside the shrinking valid part are
    // computed from clamped reads and never reach `rect`.
    let e = grow(rect, filter.reach(), cols, rows);
    let (ew, eh) = (e.width as usize, e.height as usize);
    // Copied on all cores: for the whole grid (a full build) the copies and the first touch
    // of the buffers' pages are a tenth of the work.
    let mut buf = vec![0.0f32; ew * eh];
    // Rows in pieces of 64 at least: a drag's few rows stay one piece.
    buf.par_chunks_mut(ew)
        .with_min_len(64)
        .enumerate()
        .for_each(|(y, line)| {
            let s = (e.r0 as usize + y) * w + e.c0 as usize;
            line.copy_from_slice(&input[s..s + ew]);
        });
    let mut tmp = vec![0.0f32; ew * eh];
    let k = filter.radius as i64;
    let norm = 1.0 / (2 * k + 1) as f32;
    // Grid coordinate → buffer coordinate, the grid's edge repeated, the buffer's edge too.
    let col = |gc: i64| {
        (gc.clamp(0, i64::from(cols) - 1)
            .clamp(i64::from(e.c0), i64::from(e.c0) + ew as i64 - 1)
            - i64::from(e.c0)) as usize
    };
    let row = |gr: i64| {
        (gr.clamp(0, i64::from(rows) - 1)
            .clamp(i64::from(e.r0), i64::from(e.r0) + eh as i64 - 1)
            - i64::from(e.r0)) as usize
    };
    // Columns whose whole window is inside the buffer (and the grid) read it directly; the rest
    // through the clamps. Either way the taps are summed from -k to k, so the bits agree.
    let (lo, hi) = (k as usize, ew.saturating_sub(k as usize));
    for _ in 0..filter.passes {
        tmp.par_chunks_mut(ew).enumerate().for_each(|(y, line)| {
            let src = &buf[y * ew..(y + 1) * ew];
            for (x, o) in line.iter_mut().enumerate() {
                let mut s = 0.0f32;
                if x >= lo && x < hi {
                    for v in &src[x - lo..=x + lo] {
                        s += v;
                    }
                } else {
                    let gc = i64::from(e.c0) + x as i64;
                    for dx in -k..=k {
                        s += src[col(gc + dx)];
                    }
                }
                *o = s * norm;
            }
        });
        buf.par_chunks_mut(ew).enumerate().for_each(|(y, line)| {
            let gr = i64::from(e.r0) + y as i64;
            let taps: Vec<usize> = (-k..=k).map(|dy| row(gr + dy) * ew).collect();
            line.fill(0.0);
            for &t in &taps {
                for (o, v) in line.iter_mut().zip(&tmp[t..t + ew]) {
                    *o += v;
                }
            }
            for o in line.iter_mut() {
                *o *= norm;
            }
        });
    }
    let rows_out = &mut out[rect.r0 as usize * w..(rect.r0 + rect.height) as usize * w];
    rows_out
        .par_chunks_mut(w)
        .with_min_len(64)
        .enumerate()
        .for_each(|(y, line)| {
            let b = (rect.r0 - e.r0) as usize * ew + y * ew + (rect.c0 - e.c0) as usize;
            line[rect.c0 as usize..(rect.c0 + rect.width) as usize].copy_from_slice(&buf[b..b + rect.width as usize]);
        });
}
