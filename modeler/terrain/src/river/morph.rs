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
    if width == 0 {
        return d;
    }
    // Forward pass: from above, then from the left along the row.
    for r in 0..height {
        let (done, rest) = d.split_at_mut(r * width);
        let row = &mut rest[..width];
        match done.len().checked_sub(width) {
            Some(up) => {
                for (v, &u) in row.iter_mut().zip(&done[up..]) {
                    *v = (*v).min(u.saturating_add(1));
                }
            }
            None => row.iter_mut().for_each(|v| *v = (*v).min(outside.saturating_add(1))),
        }
        let mut left = outside;
        for v in row.iter_mut() {
            left = (*v).min(left.saturating_add(1));
            *v = left;
        }
    }
    // Backward pass: from below, then from the right.
    for r in (0..height).rev() {
        let (head, below) = d.split_at_mut((r + 1) * width);
        let row = &mut head[r * width..];
        if below.is_empty() {
            row.iter_mut().for_each(|v| *v = (*v).min(outside.saturating_add(1)));
        } else {
            for (v, &u) in row.iter_mut().zip(&below[..width]) {
                *v = (*v).min(u.saturating_add(1));
            }
        }
        let mut right = outside;
        for v in row.iter_mut().rev() {
            right = (*v).min(right.saturating_add(1));
            *v = right;
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
