//! The exact Euclidean distance transform of a binary image (Felzenszwalb & Huttenlocher's
//! separable lower envelope of parabolas, [`crate::edt`]; linear in the cells).
//!
//! Why beside [`super::morph::distance`]: the banks blend into the ground by the distance to the
//! water, and the city-block distance's contours are diamonds, so every bank stepped like the
//! diamonds that shaped the water; the Euclidean distance's contours are round.

/// Euclidean distance (cells) from every cell of a `width × height` image to the nearest cell
/// whose value is not 0; infinite when there is none. Cells beyond the image are not targets.
/// The transform is the terrain's ([`crate::edt::squared`], exact integer squared distances).
pub fn euclidean(image: &[u8], width: usize, height: usize) -> Vec<f32> {
    let targets: Vec<bool> = image.iter().map(|&v| v != 0).collect();
    crate::edt::squared(width, height, &targets)
        .into_iter()
        .map(|d2| {
            if d2 == u64::MAX {
                f32::INFINITY
            } else {
                (d2 as f64).sqrt() as f32
            }
        })
        .collect()
}
