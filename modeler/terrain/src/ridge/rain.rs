//! Ridge and valley areas by rain (seed 002 §3.1): one drop on every cell, each traced downhill,
//! and per cell the number of drops that pass through it. Often passed = valley, rarely =
//! ridge.
//!
//! A drop in cell c moves to the neighbour (of 8) nearest the direction of steepest descent, the
//! negative Sobel gradient ([`super::gradient::sobel`]), if that neighbour is strictly lower;
//! otherwise it stops there (a flat, a pit, or a step that would climb). It also stops at the
//! grid's edge when the descent points off the grid. Since every step goes strictly down, no
//! drop loops, and each cell's move is the same whichever drop arrives, so the count of a cell
//! is 1 + the counts of the cells that move into it: counted in one pass over the cells in
//! upstream-first order ([`counts`]) instead of tracing a million drops one by one (the tests
//! trace them one by one and compare).

use rayon::prelude::*;

use super::gradient::sobel;

/// No move: the drop stops in this cell.
pub const STOP: u32 = u32::MAX;

/// tan 22.5°: the descent's octant boundary.
const TAN_22_5: f64 = 0.414_213_562_373_095_03;

/// Per cell, the cell a drop moves to ([`STOP`] if it stays).
pub fn directions(z: &[f32], cols: u32, rows: u32, cell: f64) -> Vec<u32> {
    let mut next = vec![STOP; z.len()];
    next.par_chunks_mut(cols as usize).enumerate().for_each(|(r, line)| {
        let r = r as u32;
        for (c, n) in line.iter_mut().enumerate() {
            *n = step(z, cols, rows, cell, c as u32, r);
        }
    });
    next
}

/// Where a drop in cell `(c, r)` moves ([`STOP`] if it stays).
pub fn step(z: &[f32], cols: u32, rows: u32, cell: f64, c: u32, r: u32) -> u32 {
    let [gx, gy] = sobel(z, cols, rows, cell, c, r);
    if gx == 0.0 && gy == 0.0 {
        return STOP;
    }
    // The octant nearest the descent's angle, by comparing the components with tan 22.5°.
    let (ax, ay) = (-gx, -gy);
    let sx = if ax > 0.0 { 1 } else { -1 };
    let sy = if ay > 0.0 { 1 } else { -1 };
    let (dc, dr) = if ay.abs() <= ax.abs() * TAN_22_5 {
        (sx, 0)
    } else if ax.abs() <= ay.abs() * TAN_22_5 {
        (0, sy)
    } else {
        (sx, sy)
    };
    let (nc, nr) = (c as i32 + dc, r as i32 + dr);
    if nc < 0 || nr < 0 || nc >= cols as i32 || nr >= rows as i32 {
        return STOP;
    }
    let (i, j) = (
        r as usize * cols as usize + c as usize,
        nr as usize * cols as usize + nc as usize,
    );
    if z[j] < z[i] { j as u32 } else { STOP }
}

/// The rain pass counts: per cell, how many drops (one started on every cell) pass through it,
/// its own included.
pub fn counts(z: &[f32], cols: u32, rows: u32, cell: f64) -> Vec<u32> {
    accumulate(&directions(z, cols, rows, cell))
}

/// The pass counts of the moves `next` ([`directions`]).
pub fn accumulate(next: &[u32]) -> Vec<u32> {
    downstream(next, |from, to| to + from)
}

/// Per cell, the number of cells on the longest path of moves `next` ([`directions`]) that ends
/// there, its own included: the count a cell would have if no two paths joined above it. On a
/// plane every path runs beside the others and the pass count equals it; where water gathers,
/// as in a valley, the count exceeds it many times.
pub fn longest_paths(next: &[u32]) -> Vec<u32> {
    downstream(next, |from, to| to.max(from + 1))
}

/// Per cell a value, 1 to start with, passed down the moves `next` in upstream-first (Kahn's)
/// order: a cell is passed on once every cell moving into it was, its value at the cell it moves
/// to becoming `join(its value, the value there)`.
fn downstream(next: &[u32], join: impl Fn(u32, u32) -> u32) -> Vec<u32> {
    let mut inflow = vec![0u32; next.len()];
    for &n in next {
        if n != STOP {
            inflow[n as usize] += 1;
        }
    }
    let mut value = vec![1u32; next.len()];
    let mut ready: Vec<u32> = (0..next.len() as u32).filter(|&i| inflow[i as usize] == 0).collect();
    while let Some(i) = ready.pop() {
        let n = next[i as usize];
        if n != STOP {
            value[n as usize] = join(value[i as usize], value[n as usize]);
            inflow[n as usize] -= 1;
            if inflow[n as usize] == 0 {
                ready.push(n);
            }
        }
    }
    value
}

/// The cells a drop starting in cell `start` passes through, `start` first.
pub fn trace(next: &[u32], start: u32) -> Vec<u32> {
    let mut path = vec![start];
    let mut i = start;
    while next[i as usize] != STOP {
        i = next[i as usize];
        path.push(i);
    }
    path
}

/// Thresholds of the classification.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Classes {
    /// A cell passed by at most this many drops is ridge.
    pub ridge_max: u32,
    /// A cell passed by at least this many drops is valley…
    pub valley_min: u32,
    /// … and by at least this many times the drops of its longest path ([`longest_paths`]):
    /// water gathers there rather than running down a flank. 1 is the seed's count alone, under
    /// which a long plane flank is "valley" from some way down (38 % of a straight ridge's
    /// slopes at 32 drops).
    pub valley_convergence: u32,
}

impl Classes {
    /// Ridge: no drop but its own passes (1) and its own moves on; valley: 32 drops or more,
    /// at least twice its longest path's.
    pub const DEFAULT: Classes = Classes {
        ridge_max: 1,
        valley_min: 32,
        valley_convergence: 2,
    };

    /// 1.0 where the count is ridge, else 0.0. A cell whose drop stays put (a flat or a pit,
    /// `next` [`STOP`]) is never ridge: nothing passes a flat plain either, but it sheds no water.
    pub fn ridges(&self, counts: &[u32], next: &[u32]) -> Vec<f32> {
        counts
            .iter()
            .zip(next)
            .map(|(&n, &m)| f32::from(u8::from(n <= self.ridge_max && m != STOP)))
            .collect()
    }

    /// Whether a cell of pass count `count` and longest path `longest` is valley.
    pub fn is_valley(&self, count: u32, longest: u32) -> bool {
        count >= self.valley_min && u64::from(count) >= u64::from(self.valley_convergence) * u64::from(longest)
    }

    /// 1.0 where the cell is valley ([`Classes::is_valley`]), else 0.0.
    pub fn valleys(&self, counts: &[u32], longest: &[u32]) -> Vec<f32> {
        counts
            .iter()
            .zip(longest)
            .map(|(&n, &l)| f32::from(u8::from(self.is_valley(n, l))))
            .collect()
    }
}
