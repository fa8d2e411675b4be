//! Box-filtered levels of the land look's ground colours (mipmaps): level `L` holds the mean of
//! `2^L × 2^L` cells of the colour map, so a pixel that spans many cells reads one value of the
//! level whose cells are about its size ([`level_for`]).
//!
//! Why: where a cell is smaller than a pixel, the shading read the nearest cell of the full map.
//! On a 4096² grid that map is 256 MB, neighbouring pixels read cells far apart, and the reads
//! missed every cache: 72 % of the shading's time at 4096² was that one load (`perf record`,
//! issue 18). A level with cells about a pixel wide is read almost in order. The mean is also what
//! the pixel should show: a nearest cell aliases (a pixel picks one of many cells, and the pick
//! changes as the view moves).
//!
//! A level's cell is packed into 4 bytes ([`Packed`]: the colour rounded to whole sRGB steps, the
//! fine noise's factor in steps of 1/1024), a quarter of the map's 16: the levels are read only
//! where a cell is under a pixel, where a step of colour does not show, and the smaller levels
//! stay in the caches (the load was still a third of the shading's time with 16-byte cells).
//! Each level is made from the one below as stored, so a level's rounding carries into the next
//! (at most half a step per level).
//!
//! The levels follow the map's changes: [`Mips::update`] recomputes only the parents of the
//! changed cells, level by level, so the levels after any sequence of changes equal fresh ones
//! to the bit (each parent is a function of its children alone).

use rayon::prelude::*;

/// Levels above the map kept at most: a level-8 cell is 256 cells across, more than a pixel of a
/// 4096² grid at any view that shows the grid.
const MAX_LEVELS: usize = 8;

/// Steps of the fine noise's factor per unit in a [`Packed`] cell: its ±0.07 take ±72 of an
/// `i8`'s ±127.
const FACTOR_STEPS: f32 = 1024.0;

/// A level's cell: sRGB 0–255 rounded, and the fine noise's factor × [`FACTOR_STEPS`] as an `i8`.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Packed([u8; 4]);

impl Packed {
    #[inline]
    fn pack(v: [f32; 4]) -> Packed {
        let byte = |x: f32| x.round().clamp(0.0, 255.0) as u8;
        let factor = (v[3] * FACTOR_STEPS).round().clamp(-127.0, 127.0) as i8;
        Packed([byte(v[0]), byte(v[1]), byte(v[2]), factor as u8])
    }

    /// The colour (sRGB 0–255) and the fine noise's factor.
    #[inline(always)]
    pub(crate) fn unpack(self) -> [f32; 4] {
        let [r, g, b, k] = self.0;
        [
            f32::from(r),
            f32::from(g),
            f32::from(b),
            f32::from(k as i8) / FACTOR_STEPS,
        ]
    }
}

/// One level: `cols × rows` cells, row-major.
#[derive(Debug, Default, Clone, PartialEq)]
pub(crate) struct Level {
    pub(crate) cols: usize,
    pub(crate) rows: usize,
    pub(crate) cells: Vec<Packed>,
}

/// What a level is made from: the map itself, or the level below.
#[derive(Clone, Copy)]
enum Below<'a> {
    Map(&'a [[f32; 4]]),
    Level(&'a [Packed]),
}

impl Below<'_> {
    #[inline]
    fn get(self, i: usize) -> [f32; 4] {
        match self {
            Below::Map(m) => m[i],
            Below::Level(l) => l[i].unpack(),
        }
    }
}

/// Levels 1, 2, … of a `cols × rows` map.
#[derive(Debug, Default)]
pub(crate) struct Mips {
    levels: Vec<Level>,
}

/// The level a pixel spanning `cells` cells of the map reads: `⌊log₂ cells⌋` (0 below 2 cells,
/// the map itself), at most `available`.
#[inline(always)]
pub(crate) fn level_for(cells: f32, available: usize) -> usize {
    // NaN and anything under 2 cells: the map itself.
    if cells.is_nan() || cells < 2.0 {
        return 0;
    }
    // The exponent of a finite f32 ≥ 2 is ⌊log₂⌋ (an infinite one saturates to the top).
    let exponent = ((cells.to_bits() >> 23) & 0xff) as usize - 127;
    exponent.min(available)
}

impl Mips {
    /// The levels above the map, level 1 first.
    pub(crate) fn levels(&self) -> &[Level] {
        &self.levels
    }

    /// Brings the levels up to date with `base` (`cols × rows`) after its cells in columns
    /// `c0..c1`, rows `r0..r1` changed; all of them when the map's size changed.
    pub(crate) fn update(&mut self, base: &[[f32; 4]], (cols, rows): (usize, usize), rect: [usize; 4]) {
        let sizes = sizes(cols, rows);
        let fresh = self.levels.len() != sizes.len()
            || self
                .levels
                .iter()
                .zip(&sizes)
                .any(|(l, &(c, r))| l.cols != c || l.rows != r);
        let [mut c0, mut c1, mut r0, mut r1] = if fresh { [0, cols, 0, rows] } else { rect };
        if fresh {
            self.levels = sizes
                .iter()
                .map(|&(c, r)| Level {
                    cols: c,
                    rows: r,
                    cells: vec![Packed::default(); c * r],
                })
                .collect();
        }
        let (mut below, mut below_size) = (Below::Map(base), (cols, rows));
        for level in &mut self.levels {
            if c1 <= c0 || r1 <= r0 {
                return;
            }
            // The parents of the changed children.
            (c0, c1, r0, r1) = (c0 / 2, c1.div_ceil(2), r0 / 2, r1.div_ceil(2));
            average(below, below_size, level, [c0, c1, r0, r1]);
            below = Below::Level(&level.cells);
            below_size = (level.cols, level.rows);
        }
    }
}

/// The sizes of levels 1, 2, … of a `cols × rows` map: halved (rounding up) until a level is a
/// single cell or [`MAX_LEVELS`] are made.
fn sizes(cols: usize, rows: usize) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let (mut c, mut r) = (cols, rows);
    while (c > 1 || r > 1) && c > 0 && r > 0 && out.len() < MAX_LEVELS {
        (c, r) = (c.div_ceil(2), r.div_ceil(2));
        out.push((c, r));
    }
    out
}

/// `level`'s cells in columns `c0..c1`, rows `r0..r1` as the mean of their children in `below`
/// (`cols × rows`); a parent on an odd edge has one or two children.
fn average(below: Below, (cols, rows): (usize, usize), level: &mut Level, [c0, c1, r0, r1]: [usize; 4]) {
    let width = level.cols;
    level.cells[r0 * width..r1 * width]
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(k, line)| {
            let r = r0 + k;
            let (ra, rb) = (2 * r, (2 * r + 1).min(rows - 1));
            for (c, out) in line.iter_mut().enumerate().take(c1).skip(c0) {
                let (ca, cb) = (2 * c, (2 * c + 1).min(cols - 1));
                let (a, b) = (ra * cols, rb * cols);
                // Children counted once each (an edge parent repeats its only row or column, and
                // the repeat is not counted twice).
                let kids = [a + ca, a + cb, b + ca, b + cb].map(|i| below.get(i));
                let n = match (ca == cb, ra == rb) {
                    (false, false) => 4.0,
                    (true, true) => 1.0,
                    _ => 2.0,
                };
                let mut sum = [0.0f32; 4];
                for (i, kid) in kids.iter().enumerate() {
                    let repeat = (i % 2 == 1 && ca == cb) || (i >= 2 && ra == rb);
                    if !repeat {
                        for (s, v) in sum.iter_mut().zip(kid) {
                            *s += v;
                        }
                    }
                }
                *out = Packed::pack(sum.map(|s| s / n));
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map whose cell `(c, r)` holds distinct values per channel.
    fn map(cols: usize, rows: usize, salt: f32) -> Vec<[f32; 4]> {
        (0..cols * rows)
            .map(|i| {
                let (c, r) = ((i % cols) as f32, (i / cols) as f32);
                [c + salt, r, (c * 7.0 + r * 3.0 + salt) % 11.0, 0.002 * c - 0.03]
            })
            .collect()
    }

    /// The mean of the level-0 cells a level-`l` cell covers, computed directly.
    fn block_mean(base: &[[f32; 4]], cols: usize, rows: usize, l: u32, (c, r): (usize, usize)) -> [f32; 4] {
        let f = 1usize << l;
        let mut sum = [0.0f64; 4];
        let mut n = 0.0;
        for rr in r * f..((r + 1) * f).min(rows) {
            for cc in c * f..((c + 1) * f).min(cols) {
                for (s, v) in sum.iter_mut().zip(base[rr * cols + cc]) {
                    *s += f64::from(v);
                }
                n += 1.0;
            }
        }
        sum.map(|s| (s / n) as f32)
    }

    #[test]
    fn a_level_is_the_mean_of_its_cells_on_even_grids() {
        // On a power-of-two grid every level's cell covers exactly 4^l cells: the mean of means
        // is the mean, up to half a packing step per level.
        let (cols, rows) = (32, 16);
        let base = map(cols, rows, 0.0);
        let mut mips = Mips::default();
        mips.update(&base, (cols, rows), [0, cols, 0, rows]);
        assert_eq!(mips.levels().len(), 5);
        for (k, level) in mips.levels().iter().enumerate() {
            let l = k as u32 + 1;
            assert_eq!((level.cols, level.rows), (cols >> l, (rows >> l).max(1)));
            for r in 0..level.rows {
                for c in 0..level.cols {
                    let want = block_mean(&base, cols, rows, l, (c, r));
                    let got = level.cells[r * level.cols + c].unpack();
                    let steps = [1.0, 1.0, 1.0, 1.0 / FACTOR_STEPS];
                    for ((got, want), step) in got.iter().zip(want).zip(steps) {
                        let slack = 0.5 * step * l as f32 + 1e-4;
                        assert!(
                            (got - want).abs() <= slack,
                            "level {l} ({c}, {r}): {got} against {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn odd_edges_average_only_the_cells_that_exist() {
        let (cols, rows) = (5, 3);
        let base = map(cols, rows, 0.0);
        let mut mips = Mips::default();
        mips.update(&base, (cols, rows), [0, cols, 0, rows]);
        let l1 = &mips.levels()[0];
        assert_eq!((l1.cols, l1.rows), (3, 2));
        // The corner parent (2, 1) has one child, (4, 2); the edge parent (2, 0) has two.
        assert_eq!(l1.cells[5], Packed::pack(base[2 * cols + 4]));
        let (a, b) = (base[4], base[cols + 4]);
        assert_eq!(l1.cells[2], Packed::pack([0, 1, 2, 3].map(|i| (a[i] + b[i]) / 2.0)));
        // A full parent: (0, 0) has four.
        let four = [base[0], base[1], base[cols], base[cols + 1]];
        let mean = [0, 1, 2, 3].map(|i| four.iter().map(|v| v[i]).sum::<f32>() / 4.0);
        assert_eq!(l1.cells[0], Packed::pack(mean));
    }

    #[test]
    fn updates_over_changed_cells_equal_fresh_levels() {
        let (cols, rows) = (37, 29);
        let mut base = map(cols, rows, 0.0);
        let mut mips = Mips::default();
        mips.update(&base, (cols, rows), [0, cols, 0, rows]);
        for (i, rect) in [[3, 9, 4, 5], [0, 1, 0, 1], [30, 37, 20, 29], [10, 30, 0, 29]]
            .into_iter()
            .enumerate()
        {
            let [c0, c1, r0, r1] = rect;
            for r in r0..r1 {
                for c in c0..c1 {
                    base[r * cols + c] = [i as f32 + c as f32, 3.0 * r as f32, 0.5, -0.02];
                }
            }
            mips.update(&base, (cols, rows), rect);
            let mut fresh = Mips::default();
            fresh.update(&base, (cols, rows), [0, cols, 0, rows]);
            assert_eq!(mips.levels(), fresh.levels(), "after change {i}");
        }
        // An update that ignored the rectangle would leave a level stale: the test can fail.
        base[10 * cols + 10] = [1e6; 4];
        mips.update(&base, (cols, rows), [20, 21, 20, 21]);
        let mut fresh = Mips::default();
        fresh.update(&base, (cols, rows), [0, cols, 0, rows]);
        assert_ne!(mips.levels(), fresh.levels());
    }

    #[test]
    fn packing_rounds_to_the_nearest_step() {
        for v in [
            [0.0, 255.0, 17.4, 0.07],
            [12.5001, 99.49, 254.6, -0.07],
            [-3.0, 300.0, 1.0, 0.0],
        ] {
            let back = Packed::pack(v).unpack();
            for (i, (b, v)) in back.iter().zip(v).enumerate() {
                let (lo, hi, step) = if i < 3 {
                    (0.0, 255.0, 1.0)
                } else {
                    (-1.0, 1.0, 1.0 / FACTOR_STEPS)
                };
                assert!((b - v.clamp(lo, hi)).abs() <= 0.5 * step + 1e-6, "{v:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn the_level_is_the_floor_of_the_cells_log() {
        assert_eq!(level_for(0.3, 8), 0);
        assert_eq!(level_for(1.99, 8), 0);
        assert_eq!(level_for(2.0, 8), 1);
        assert_eq!(level_for(3.99, 8), 1);
        assert_eq!(level_for(4.0, 8), 2);
        assert_eq!(level_for(1000.0, 8), 8);
        assert_eq!(level_for(1000.0, 3), 3);
        assert_eq!(level_for(f32::INFINITY, 8), 8);
        assert_eq!(level_for(f32::NAN, 8), 0);
    }
}
