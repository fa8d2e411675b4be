//! Poisson-disk seeds on the field's image: points at pixel centres, no two within `r`.
//!
//! The seed throws darts at random pixels of a flag image: a dart on an unflagged pixel is kept
//! and flags every pixel within `r` of it; a dart on a flagged pixel is wasted. It throws
//! `N_p = A·c_d / (π(0.5r)²)` darts (eq. 1, `c_d ≈ 0.7`), which leaves unflagged holes where a
//! seed would still fit ([`darts`]).
//!
//! [`saturate`] runs the same process to the end without wasted throws: it visits every pixel
//! once, in a uniformly random order, and keeps it when it is not flagged. A dart that hits a pixel
//! already tried always lands on a flag (the pixel was kept, so flagged, or was flagged then), so
//! the kept points are distributed exactly as the seed's darts thrown until no pixel is left
//! unflagged: minimum distance `r`, and every pixel within `r` of a seed (maximal coverage). It
//! costs one pass over the pixels plus `πr²` flags per kept seed.

use rand::{Rng, RngExt};

/// The disk of pixels within `r` of a pixel, row by row: `(dy, half)` for the pixels `(dx, dy)`
/// with `|dx| ≤ half` (`dx² + dy² ≤ r²`). Rows, not offsets, so that flagging and painting run
/// along a row of the image with one range check a row.
pub(crate) fn disk_rows(radius: f64) -> Vec<(i32, i32)> {
    let reach = radius.floor() as i32;
    let r2 = radius * radius;
    (-reach..=reach)
        .filter_map(|dy| {
            (0..=reach)
                .take_while(|&dx| f64::from(dx * dx + dy * dy) <= r2)
                .last()
                .map(|half| (dy, half))
        })
        .collect()
}

/// `points`, distinct pixel indices below `n`, in ascending order: marked in a bitmap and read
/// back word by word (one pass over `n / 64` words instead of a sort).
pub(crate) fn in_pixel_order(points: &[u32], n: usize) -> Vec<u32> {
    let mut bits = vec![0u64; n.div_ceil(64)];
    for &p in points {
        bits[p as usize / 64] |= 1 << (p % 64);
    }
    let mut out = Vec::with_capacity(points.len());
    for (w, &word) in bits.iter().enumerate() {
        let mut word = word;
        while word != 0 {
            out.push((w * 64) as u32 + word.trailing_zeros());
            word &= word - 1;
        }
    }
    debug_assert_eq!(out.len(), points.len(), "pixel indices must be distinct");
    out
}

/// The number of darts the seed throws (eq. 1): `A·c_d / (π(0.5r)²)`, `A` the pixels.
pub fn seed_throws(width: u32, height: u32, radius: f64, fill: f64) -> u64 {
    let area = f64::from(width) * f64::from(height);
    (area * fill / (std::f64::consts::PI * (0.5 * radius).powi(2))).round() as u64
}

/// Flags the pixels within `r` of `(x, y)` (the disk's rows, [`disk_rows`]).
fn flag(flags: &mut [bool], width: u32, height: u32, x: u32, y: u32, rows: &[(i32, i32)]) {
    let (w, h) = (width as i32, height as i32);
    let (x, y) = (x as i32, y as i32);
    for &(dy, half) in rows {
        let py = y + dy;
        if py >= 0 && py < h {
            let (x0, x1) = ((x - half).max(0), (x + half).min(w - 1));
            let row = (py * w) as usize;
            flags[row + x0 as usize..=row + x1 as usize].fill(true);
        }
    }
}

/// A uniform draw from `low..high`, the same number as `rng.random_range(low..high)` (rand 0.10:
/// Canon's method on 32-bit draws while `high` fits in 32 bits) but inlined — the saturating
/// sampler draws one per pixel, and the call was half of its time.
#[inline(always)]
pub(crate) fn below(rng: &mut impl Rng, low: usize, high: usize) -> usize {
    debug_assert!(low < high);
    if high > u32::MAX as usize {
        return rng.random_range(low..high);
    }
    let range = (high - low) as u32;
    let wide = u64::from(rng.next_u32()) * u64::from(range);
    let (mut result, lo) = ((wide >> 32) as u32, wide as u32);
    // A draw near the top of the product's low half could carry: look one draw further.
    if lo > range.wrapping_neg() {
        let next = ((u64::from(rng.next_u32()) * u64::from(range)) >> 32) as u32;
        result += u32::from(lo.checked_add(next).is_none());
    }
    low + result as usize
}

/// Seeds by visiting every pixel once in random order (maximal, see the module doc). Pixel
/// indices `y·width + x`, in the order they were kept (the field sorts them into pixel order).
pub fn saturate(width: u32, height: u32, radius: f64, rng: &mut impl Rng) -> Vec<u32> {
    let n = width as usize * height as usize;
    let rows = disk_rows(radius);
    let mut flags = vec![false; n];
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut kept = Vec::new();
    // Fisher–Yates, drawn lazily: position i takes a random pixel of those not yet visited.
    for i in 0..n {
        let j = below(rng, i, n);
        order.swap(i, j);
        let p = order[i];
        if !flags[p as usize] {
            kept.push(p);
            flag(&mut flags, width, height, p % width, p / width, &rows);
        }
    }
    kept
}

/// The seed's dart throwing: `throws` darts at uniformly random pixels.
pub fn darts(width: u32, height: u32, radius: f64, throws: u64, rng: &mut impl Rng) -> Vec<u32> {
    let n = width as usize * height as usize;
    let rows = disk_rows(radius);
    let mut flags = vec![false; n];
    let mut kept = Vec::new();
    for _ in 0..throws {
        let p = rng.random_range(0..n as u32);
        if !flags[p as usize] {
            kept.push(p);
            flag(&mut flags, width, height, p % width, p / width, &rows);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// `below` draws what rand's `random_range` draws from the same generator, for ranges small
    /// and large, starting anywhere (both generators stay in step).
    #[test]
    fn below_is_rands_random_range() {
        let (mut ours, mut rands) = (ChaCha8Rng::seed_from_u64(3), ChaCha8Rng::seed_from_u64(3));
        let highs = [
            1usize,
            2,
            3,
            7,
            1000,
            262_144,
            1 << 24,
            (1 << 31) + 12_345,
            u32::MAX as usize,
        ];
        for (k, &high) in highs.iter().cycle().take(90_000).enumerate() {
            let low = (k * 7919) % high;
            assert_eq!(
                below(&mut ours, low, high),
                rands.random_range(low..high),
                "{low}..{high}"
            );
        }
    }

    /// Distinct pixel indices come back ascending, all of them.
    #[test]
    fn in_pixel_order_sorts_distinct_pixels() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n = 10_000;
        let mut all: Vec<u32> = (0..n as u32).collect();
        for i in 0..n {
            all.swap(i, rng.random_range(i..n));
        }
        let some = &all[..3_000];
        let mut sorted = some.to_vec();
        sorted.sort_unstable();
        assert_eq!(in_pixel_order(some, n), sorted);
    }
}
