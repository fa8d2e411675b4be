//! Binary morphology by a diamond: the seed's structuring element of level `n` is the
//! `(2n − 1) × (2n − 1)` diamond `{(dx, dy) : |dx| + |dy| ≤ n − 1}`, which is `n − 1` iterated
//! 4-neighbour crosses (level 1 is the single cell, the identity).
//!
//! Dilating by it keeps every cell within city-block distance `n − 1` of the set; eroding keeps
//! every cell farther than `n − 1` from the complement. Both read one city-block distance
//! transform ([`distance`]): two raster passes, exact for the 4-neighbour metric, so the cost is
//! two sweeps of the image whatever the level. Cells outside the image count as background, as in
//! `scipy.ndimage.binary_dilation`/`binary_erosion` with their default `border_value=0`.

/// The largest structuring-element level (the seed's 6: an 11 × 11 diamond).
pub const MAX_LEVEL: u8 = 6;

/// A distance no cell of an image reaches (distances saturate here).
const FAR: u16 = u16::MAX;

/// The diamond of `level` (1 to [`MAX_LEVEL`]) as a `(2n − 1)²` row-major image of 0/1.
pub fn diamond(level: u8) -> Vec<u8> {
    let r = i32::from(level.max(1)) - 1;
    let side = 2 * r + 1;
    (0..side * side)
        .map(|i| u8::from((i % side - r).abs() + (i / side - r).abs() <= r))
        .collect()
}

/// City-block distance from every cell of a `width × height` image to the nearest cell whose
/// value is `target != 0` (saturating at `u16::MAX`). With `outside_is_target`, the cells beyond
/// the image's edge count as target cells (distance 1 from the edge cells).
pub fn distance(image: &[u8], width: usize, height: usize, target: bool, outside_is_target: bool) -> Vec<u16> {
    // The distance of a cell beyond the edge.
    let outside = if outside_is_target { 0 } else { FAR };
    let mut d: Vec<u16> = image
        .iter()
        .map(|&v| if (v != 0) == target { 0 } else { FAR })
        .collect();
    // Forward pass: from the left and from above.
    for r in 0..height {
        let row = r * width;
        for c in 0..width {
            let i = row + c;
            let left = if c > 0 { d[i - 1] } else { outside };
            let up = if r > 0 { d[i - width] } else { outside };
            let best = left.min(up).saturating_add(1);
            if best < d[i] {
                d[i] = best;
            }
        }
    }
    // Backward pass: from the right and from below.
    for r in (0..height).rev() {
        let row = r * width;
        for c in (0..width).rev() {
            let i = row + c;
            let right = if c + 1 < width { d[i + 1] } else { outside };
            let down = if r + 1 < height { d[i + width] } else { outside };
            let best = right.min(down).saturating_add(1);
            if best < d[i] {
                d[i] = best;
            }
        }
    }
    d
}

/// The image dilated by the diamond of `level` (the cells within `level − 1` of the set).
pub fn dilate(image: &[u8], width: usize, height: usize, level: u8) -> Vec<u8> {
    let reach = u16::from(level.max(1)) - 1;
    distance(image, width, height, true, false)
        .into_iter()
        .map(|d| u8::from(d <= reach))
        .collect()
}

/// The image eroded by the diamond of `level` (the cells farther than `level − 1` from the
/// complement, the outside counting as complement).
pub fn erode(image: &[u8], width: usize, height: usize, level: u8) -> Vec<u8> {
    let reach = u16::from(level.max(1)) - 1;
    distance(image, width, height, false, true)
        .into_iter()
        .map(|d| u8::from(d > reach))
        .collect()
}
