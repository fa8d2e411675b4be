//! Exact Euclidean distance transforms in linear time (Felzenszwalb & Huttenlocher, "Distance
//! transforms of sampled functions", 2012), the distances of the `euclidean` metric.
//!
//! The squared distance to the nearest source cell is separable: a pass down each column gives
//! every cell its vertical distance `g` to the nearest source in its column, then each row is
//! the lower envelope of the parabolas `(x − q)² + g(q)²` over its columns q, built and read in
//! one sweep. Both passes are linear, so a map costs O(cells of the box) whatever its distances.
//! Intersections of parabolas are compared as exact fractions (integer cross products), not as
//! floating-point numbers, so the squared distances are exact integers; the distance is their
//! square root rounded once to `f32`. The cross products fit 64 bits for boxes up to 2^20 cells a
//! side (`Wide`), which is every box a usual grid has; a longer box (a grid may be 2^24 × 1)
//! uses 128 bits. Rows are independent, so the row pass runs on all cores.
//!
//! `df` is the distance to the nearest cell outside the region, less one (so that a cell with a
//! 4-neighbour outside has `df = 0`, as in the taxicab metric, where `df` is the taxicab distance
//! to the outside less one). It is geodesic — the length of the shortest path inside the region —
//! for any region, convex or not: the disc of radius `d` around a cell holds no outside cell, so
//! the straight segment to the nearest outside cell crosses only region cells. `dp`, the distance
//! from a figure, is the straight-line distance to its nearest cell, which in a region with a
//! bay may cross the bay (`docs/modeler.md` says what that does).

use std::ops::{Add, Div, Mul, Sub};

use rayon::prelude::*;

use crate::cells::{Cell, Mask};
use crate::pool::{self, COLUMNS};

/// No source in the column (or the row).
pub(crate) const FAR: u32 = u32::MAX;

/// Squared Euclidean distance from each cell of a `w × h` box (row-major) to the nearest cell
/// where `source` is true, or `u64::MAX` when there is no source at all.
pub fn squared(w: usize, h: usize, source: &[bool]) -> Vec<u64> {
    debug_assert_eq!(source.len(), w * h);
    let mut out = vec![u64::MAX; w * h];
    let mut g: Vec<u32> = source.iter().map(|&s| if s { 0 } else { FAR }).collect();
    transform(w, h, &mut g, &mut out, |d2| d2 as u64);
    out
}

/// The squared distances of [`squared`] from `g` (0 at the sources, [`FAR`] elsewhere; the
/// column distances on return) through `f` into `out` (cells of a row without any source are
/// left as they are): the engine's maps take their square roots as each row is done, with no
/// squared map in between. `f` takes them as `f64`s (exact: below 2^53), computed in `f64` from
/// the start, so that a row's cells take their square roots two at a time (vector instructions).
fn transform<O: Send>(w: usize, h: usize, g: &mut [u32], out: &mut [O], f: impl Fn(f64) -> O + Sync) {
    debug_assert_eq!(g.len(), w * h);
    columns(w, h, g);
    if w.max(h) <= NARROW_SIDE {
        rows::<i64, O>(w, g, out, &f);
    } else {
        rows::<i128, O>(w, g, out, &f);
    }
}

/// [`transform`] for the engine's maps: each cell's distance `√d² − less` as an `f32` (`less` 0
/// for `dp`, 1 for `df`), each row's envelope read out through [`sqrt_row`] (in the widest
/// copy of [`crate::simd`] the CPU has).
fn transform_sqrt(w: usize, h: usize, g: &mut [u32], out: &mut [f32], less: f64) {
    debug_assert_eq!(g.len(), w * h);
    columns(w, h, g);
    if w.max(h) <= NARROW_SIDE {
        g.par_chunks(w.max(1))
            .zip(out.par_chunks_mut(w.max(1)))
            .with_min_len(16)
            .for_each_init(
                || Envelope::<i64>::with_capacity(w),
                |env, (row, dst)| sqrt_row(env, row, dst, less),
            );
    } else {
        rows::<i128, f32>(w, g, out, &|d2| (d2.sqrt() - less) as f32);
    }
}

/// One row of [`transform_sqrt`]. Called through [`sqrt_row`].
#[inline(always)]
fn sqrt_row_body(env: &mut Envelope<i64>, g: &[u32], out: &mut [f32], less: f64) {
    // `√d² − 0` is `√d²` (never −0: a square root is +0 or more).
    env.row(g, out, |d2| (d2.sqrt() - less) as f32);
}

crate::simd::copies! {
    /// [`sqrt_row_body`], in the widest copy the CPU has ([`crate::simd`]).
    fn sqrt_row(env: &mut Envelope<i64>, g: &[u32], out: &mut [f32], less: f64) = sqrt_row_body;
}

/// The column pass over a `w × h` box: each cell's vertical distance to the nearest cell of its
/// column that holds 0 in `g` ([`FAR`] where none does), in place. Two sweeps over rows (row by
/// row rather than column by column, for the cache). `FAR` saturates, so each step is a minimum
/// without branches, which compiles to vector instructions. Called through [`columns`] (or inlined
/// into another function's copies).
#[inline(always)]
pub(crate) fn columns_body(w: usize, h: usize, g: &mut [u32]) {
    for y in 1..h {
        let (above, row) = g[(y - 1) * w..(y + 1) * w].split_at_mut(w);
        for (d, &a) in row.iter_mut().zip(above.iter()) {
            *d = (*d).min(a.saturating_add(1));
        }
    }
    for y in (0..h.saturating_sub(1)).rev() {
        let (row, below) = g[y * w..(y + 2) * w].split_at_mut(w);
        for (d, &b) in row.iter_mut().zip(below.iter()) {
            *d = (*d).min(b.saturating_add(1));
        }
    }
}

crate::simd::copies! {
    /// [`columns_body`], in the widest copy the CPU has ([`crate::simd`]).
    pub(crate) fn columns(w: usize, h: usize, g: &mut [u32]) = columns_body;
}

/// The longest box side whose envelope fractions fit `i64`: numerators are at most
/// `2·side²` (2^41) and denominators `2·side` (2^21), so their cross products stay below 2^62.
const NARROW_SIDE: usize = 1 << 20;

/// The row pass over `g`'s rows into `out` (each squared distance through `f`), rows in
/// parallel, with fractions in `T`.
fn rows<T: Wide, O: Send>(w: usize, g: &[u32], out: &mut [O], f: &(impl Fn(f64) -> O + Sync)) {
    let w1 = w.max(1);
    g.par_chunks(w1)
        .zip(out.par_chunks_mut(w1))
        .with_min_len(16)
        .for_each_init(
            || Envelope::<T>::with_capacity(w),
            |env, (row, dst)| env.row(row, dst, f),
        );
}

/// The integer type of the envelope's fractions: `i64` for boxes up to [`NARROW_SIDE`] a side,
/// `i128` beyond.
trait Wide:
    Copy
    + PartialOrd
    + From<i64>
    + TryInto<i64>
    + Add<Output = Self>
    + Div<Output = Self>
    + Mul<Output = Self>
    + Sub<Output = Self>
    + Send
{
    /// The first whole `x ≥ 0` with `x·den ≥ num` (`den > 0`), or `hi` if that is more.
    fn first_at_least(num: Self, den: Self, hi: usize) -> usize {
        let zero = Self::from(0);
        if num <= zero {
            return 0;
        }
        // ⌈num/den⌉ of positive numbers.
        let x = (num + den - Self::from(1)) / den;
        x.try_into().map_or(hi, |x: i64| (x as u64).min(hi as u64) as usize)
    }
}
impl Wide for i64 {}
impl Wide for i128 {}

/// A vertex of a row's lower envelope: the parabola's column `v`, its height `f` (the squared
/// column distance), `f + v²` (what [`Envelope::meet`] reads), and the fraction `z = num/den`
/// where it starts to be the lowest.
#[derive(Clone, Copy)]
struct Vertex<T> {
    v: i64,
    f: i64,
    h: i64,
    z: (T, T),
}

/// The lower envelope of one row's parabolas: its vertices, columns increasing, in a buffer as
/// long as the row (the first `k` of them in use), so that adding and dropping one is an index;
/// and per column of the row, the column and height of the vertex whose parabola is lowest there.
struct Envelope<T> {
    verts: Vec<Vertex<T>>,
    columns: Vec<f64>,
    heights: Vec<f64>,
}

impl<T: Wide> Envelope<T> {
    fn with_capacity(n: usize) -> Envelope<T> {
        Envelope {
            verts: Vec::with_capacity(n),
            columns: Vec::with_capacity(n),
            heights: Vec::with_capacity(n),
        }
    }

    /// Where the parabola of column `q` (`hq = fq + q²`) starts to lie below the one of vertex
    /// `a`: `((fq + q²) − (fa + va²)) / (2(q − va))`, as a fraction with a positive denominator.
    #[inline(always)]
    fn meet(a: &Vertex<T>, q: i64, hq: i64) -> (T, T) {
        // Both terms fit i64 (at most 2·side² each); their difference too.
        ((hq - a.h).into(), (2 * (q - a.v)).into())
    }

    /// `a ≤ b` for fractions with positive denominators.
    #[inline(always)]
    fn at_most(a: (T, T), b: (T, T)) -> bool {
        a.0 * b.1 <= b.0 * a.1
    }

    /// The squared distances of one row from its columns' vertical distances `g`.
    #[inline(always)]
    fn row<O>(&mut self, g: &[u32], out: &mut [O], f: impl Fn(f64) -> O) {
        let zero = Vertex {
            v: 0,
            f: 0,
            h: 0,
            z: (T::from(0), T::from(0)),
        };
        let Envelope {
            verts,
            columns,
            heights,
        } = self;
        if verts.len() < g.len() {
            verts.resize(g.len(), zero);
        }
        let verts = &mut verts[..g.len()];
        let mut k = 0;
        for (q, &gq) in g.iter().enumerate() {
            if gq == FAR {
                continue;
            }
            let (q, fq) = (q as i64, i64::from(gq) * i64::from(gq));
            let hq = fq + q * q;
            // The first vertex's stretch starts at −∞.
            let mut z = (T::from(-1), T::from(0));
            // Drop the vertices the new parabola hides: those whose own stretch would start
            // after the new one's (never the first).
            while k > 0 {
                z = Self::meet(&verts[k - 1], q, hq);
                if k > 1 && Self::at_most(z, verts[k - 1].z) {
                    k -= 1;
                } else {
                    break;
                }
            }
            verts[k] = Vertex { v: q, f: fq, h: hq, z };
            k += 1;
        }
        if k == 0 {
            return;
        }
        // Each vertex's columns: from where the last one's ended to where the next one's stretch
        // starts (the first x with x·den ≥ num); the last one's end at the row's end, so every
        // column gets its vertex.
        let verts = &verts[..k];
        let w = out.len();
        if columns.len() < w {
            columns.resize(w, 0.0);
            heights.resize(w, 0.0);
        }
        let (columns, heights) = (&mut columns[..w], &mut heights[..w]);
        let mut start = 0;
        for (i, a) in verts.iter().enumerate() {
            let end = verts.get(i + 1).map_or(w, |b| T::first_at_least(b.z.0, b.z.1, w));
            if end > start {
                // Whole numbers below 2^53 in `f64`.
                columns[start..end].fill(a.v as f64);
                heights[start..end].fill(a.f as f64);
                start = end;
            }
        }
        // Then the squared distances in one loop over the row, which compiles to vector
        // instructions (a vertex's stretch is often a column or two): whole numbers below 2^53
        // in `f64`, so the same numbers exactly; a column as an `i32` (a box is narrower than
        // 2^31) converts several at a time.
        for (x, ((d, &v), &h)) in (0..w as i32).zip(out.iter_mut().zip(&*columns).zip(&*heights)) {
            let dx = f64::from(x) - v;
            *d = f(dx * dx + h);
        }
    }
}

/// One row of a one-source map: the cells' distances from the source at column `sx`, `dy2` rows'
/// squares away (infinite outside the region, where `flags` is false). The squared distances are
/// whole numbers below 2⁵³, exact in `f64`: the transform's numbers. Called through
/// [`one_source_row`].
#[inline(always)]
fn one_source_body(row: &mut [f32], flags: &[bool], sx: i32, dy2: f64) {
    // Columns as `i32` (a box is narrower than 2³¹) convert to `f64` four at a time.
    for (x, (o, &b)) in (0..row.len() as i32).zip(row.iter_mut().zip(flags)) {
        let dx = f64::from(x - sx);
        *o = if b {
            (dx * dx + dy2).sqrt() as f32
        } else {
            f32::INFINITY
        };
    }
}

crate::simd::copies! {
    /// [`one_source_body`], in the widest copy the CPU has ([`crate::simd`]).
    fn one_source_row(row: &mut [f32], flags: &[bool], sx: i32, dy2: f64) = one_source_body;
}

/// `dp` in the Euclidean metric: the distance of every region cell from the nearest of
/// `sources` (straight-line), over the mask's box; cells outside the region are infinite, and
/// so is every cell when no source lies in the region. Sources outside the region are ignored.
pub fn from_sources(mask: &Mask, sources: &[Cell]) -> Vec<f32> {
    let bits = mask.bits();
    let inside: Vec<usize> = sources
        .iter()
        .filter_map(|&s| mask.index(s).filter(|&i| bits[i]))
        .collect();
    let w = (mask.width as usize).max(1);
    if let Some(&first) = inside.first()
        && inside.iter().all(|&i| i == first)
    {
        // One source cell (a point figure): the squared distances directly, those the transform
        // would find (its one parabola per row), with no transform.
        let (sx, sy) = ((first % w) as i32, (first / w) as f64);
        let mut out = pool::MAPS.unfilled(mask.box_len(), f32::INFINITY);
        out.par_chunks_mut(w)
            .zip(bits.par_chunks(w))
            .enumerate()
            .for_each(|(y, (row, flags))| {
                let dy = y as f64 - sy;
                one_source_row(row, flags, sx, dy * dy);
            });
        return out;
    }
    let mut g = COLUMNS.filled(mask.box_len(), FAR);
    for &i in &inside {
        g[i] = 0;
    }
    // With a source, the column pass gives every row of the box a finite distance (the source's
    // column), so the row pass writes every cell; without, no cell is written.
    let mut out = if inside.is_empty() {
        pool::MAPS.filled(mask.box_len(), f32::INFINITY)
    } else {
        pool::MAPS.unfilled(mask.box_len(), f32::INFINITY)
    };
    transform_sqrt(mask.width as usize, mask.height as usize, &mut g, &mut out, 0.0);
    COLUMNS.give(g);
    // The cells outside the region, in a second sweep without branches.
    for (o, &b) in out.iter_mut().zip(bits) {
        *o = if b { *o } else { f32::INFINITY };
    }
    out
}

/// `df` in the Euclidean metric: for every region cell, the distance to the nearest cell outside
/// the region (or the grid) less one, over the mask's box; cells outside the region are infinite.
pub fn to_edge(mask: &Mask) -> Vec<f32> {
    let (w, h) = (mask.width as usize, mask.height as usize);
    let bits = mask.bits();
    // The box with a one-cell border of outside cells: every cell beyond the box is outside the
    // region, and the border is the nearest of them along rows and columns.
    let (pw, ph) = (w + 2, h + 2);
    let mut g = COLUMNS.filled(pw * ph, 0);
    for y in 0..h {
        for (x, &inside) in bits[y * w..(y + 1) * w].iter().enumerate() {
            if inside {
                g[(y + 1) * pw + x + 1] = FAR;
            }
        }
    }
    // Every row of the bordered box has a source (its border), so each of its cells is written.
    let mut bordered = pool::MAPS.unfilled(pw * ph, 0.0);
    transform_sqrt(pw, ph, &mut g, &mut bordered, 1.0);
    COLUMNS.give(g);
    let mut out = pool::MAPS.filled(w * h, f32::INFINITY);
    for (y, row) in out.chunks_mut(w.max(1)).enumerate() {
        let inner = &bordered[(y + 1) * pw + 1..][..w];
        for ((o, &d), &inside) in row.iter_mut().zip(inner).zip(&bits[y * w..(y + 1) * w]) {
            if inside {
                *o = d;
            }
        }
    }
    pool::MAPS.give(bordered);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The squared distances by brute force, for comparison.
    fn brute(w: usize, h: usize, source: &[bool]) -> Vec<u64> {
        let sources: Vec<(i64, i64)> = (0..w * h)
            .filter(|&i| source[i])
            .map(|i| ((i % w) as i64, (i / w) as i64))
            .collect();
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                sources
                    .iter()
                    .map(|&(sx, sy)| ((x - sx).pow(2) + (y - sy).pow(2)) as u64)
                    .min()
                    .unwrap_or(u64::MAX)
            })
            .collect()
    }

    #[test]
    fn both_widths_of_fraction_give_the_brute_force_distances() {
        let (w, h) = (37, 23);
        // A fixed scatter of sources (a multiplicative hash), some rows and columns without any.
        let source: Vec<bool> = (0..w * h).map(|i| (i as u64 * 2_654_435_761) % 97 < 3).collect();
        let mut g = vec![FAR; w * h];
        let full = squared(w, h, &source);
        assert_eq!(full, brute(w, h, &source));
        // The row pass alone, in each width, on the same column distances.
        for (x, y) in (0..w * h).map(|i| (i % w, i / w)) {
            g[y * w + x] = (0..h)
                .filter(|&r| source[r * w + x])
                .map(|r| r.abs_diff(y) as u32)
                .min()
                .unwrap_or(FAR);
        }
        let (mut narrow, mut wide) = (vec![u64::MAX; w * h], vec![u64::MAX; w * h]);
        rows::<i64, u64>(w, &g, &mut narrow, &|d2| d2 as u64);
        rows::<i128, u64>(w, &g, &mut wide, &|d2| d2 as u64);
        assert_eq!(narrow, full);
        assert_eq!(wide, full);
    }

    #[test]
    fn one_source_cell_gives_the_straight_line_distances_of_the_transform() {
        // A 9 × 7 box with holes, the source given twice, and a second source elsewhere.
        let cells: Vec<Cell> = (0..63u32)
            .filter(|i| i % 5 != 3)
            .map(|i| (10 + i % 9, 20 + i / 9))
            .collect();
        let mask = Mask::from_cells(&cells);
        let (w, h) = (mask.width as usize, mask.height as usize);
        for sources in [vec![(14, 23)], vec![(14, 23), (14, 23)], vec![(14, 23), (11, 20)]] {
            let mut source = vec![false; w * h];
            for &s in &sources {
                source[mask.index(s).unwrap()] = true;
            }
            let want: Vec<f32> = brute(w, h, &source)
                .iter()
                .zip(mask.bits())
                .map(|(&d2, &b)| if b { (d2 as f64).sqrt() as f32 } else { f32::INFINITY })
                .collect();
            let got = from_sources(&mask, &sources);
            assert_eq!(got.len(), want.len());
            for (i, (g, e)) in got.iter().zip(&want).enumerate() {
                assert_eq!(g.to_bits(), e.to_bits(), "{sources:?} cell {i}");
            }
        }
    }

    #[test]
    fn a_box_longer_than_the_narrow_side_takes_the_wide_fractions_and_stays_exact() {
        let w = NARROW_SIDE + 3;
        let mut source = vec![false; w];
        for s in [0, 5, w / 2, w - 1] {
            source[s] = true;
        }
        let got = squared(w, 1, &source);
        for x in [1usize, 3, 6, w / 4, w / 2 + 1, w - 2] {
            let want = [0usize, 5, w / 2, w - 1]
                .iter()
                .map(|&s| (x.abs_diff(s) as u64).pow(2))
                .min();
            assert_eq!(Some(got[x]), want, "x {x}");
        }
    }
}
