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

/// Pixel offsets `(dx, dy)` with `dx² + dy² ≤ r²`, row by row.
pub(crate) fn disk(radius: f64) -> Vec<(i32, i32)> {
    let reach = radius.floor() as i32;
    let r2 = radius * radius;
    let mut out = Vec::new();
    for dy in -reach..=reach {
        for dx in -reach..=reach {
            if f64::from(dx * dx + dy * dy) <= r2 {
                out.push((dx, dy));
            }
        }
    }
    out
}

/// The number of darts the seed throws (eq. 1): `A·c_d / (π(0.5r)²)`, `A` the pixels.
pub fn seed_throws(width: u32, height: u32, radius: f64, fill: f64) -> u64 {
    let area = f64::from(width) * f64::from(height);
    (area * fill / (std::f64::consts::PI * (0.5 * radius).powi(2))).round() as u64
}

/// Flags the pixels within `r` of `(x, y)`.
fn flag(flags: &mut [bool], width: u32, height: u32, x: u32, y: u32, offsets: &[(i32, i32)]) {
    let (w, h) = (width as i32, height as i32);
    let (x, y) = (x as i32, y as i32);
    for &(dx, dy) in offsets {
        let (px, py) = (x + dx, y + dy);
        if px >= 0 && py >= 0 && px < w && py < h {
            flags[(py * w + px) as usize] = true;
        }
    }
}

/// Seeds by visiting every pixel once in random order (maximal, see the module doc). Pixel
/// indices `y·width + x`, in the order they were kept (the field sorts them into pixel order).
pub fn saturate(width: u32, height: u32, radius: f64, rng: &mut impl Rng) -> Vec<u32> {
    let n = width as usize * height as usize;
    let offsets = disk(radius);
    let mut flags = vec![false; n];
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut kept = Vec::new();
    // Fisher–Yates, drawn lazily: position i takes a random pixel of those not yet visited.
    for i in 0..n {
        let j = rng.random_range(i..n);
        order.swap(i, j);
        let p = order[i];
        if !flags[p as usize] {
            kept.push(p);
            flag(&mut flags, width, height, p % width, p / width, &offsets);
        }
    }
    kept
}

/// The seed's dart throwing: `throws` darts at uniformly random pixels.
pub fn darts(width: u32, height: u32, radius: f64, throws: u64, rng: &mut impl Rng) -> Vec<u32> {
    let n = width as usize * height as usize;
    let offsets = disk(radius);
    let mut flags = vec![false; n];
    let mut kept = Vec::new();
    for _ in 0..throws {
        let p = rng.random_range(0..n as u32);
        if !flags[p as usize] {
            kept.push(p);
            flag(&mut flags, width, height, p % width, p / width, &offsets);
        }
    }
    kept
}
