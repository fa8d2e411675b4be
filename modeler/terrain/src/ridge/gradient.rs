//! The Sobel gradient the seed names for the rain's direction (and the sun's surface normal).

/// The Sobel estimate of `(∂z/∂x, ∂z/∂y)` at cell `(c, r)` of a `cols × rows` row-major grid of
/// `cell` metres: `[[−1 0 1] [−2 0 2] [−1 0 1]] / 8s` and its transpose, the edge cells repeated
/// beyond the grid.
#[inline]
pub fn sobel(z: &[f32], cols: u32, rows: u32, cell: f64, c: u32, r: u32) -> [f64; 2] {
    let w = cols as usize;
    let cm = c.saturating_sub(1) as usize;
    let cp = (c + 1).min(cols - 1) as usize;
    let rm = r.saturating_sub(1) as usize * w;
    let r0 = r as usize * w;
    let rp = (r + 1).min(rows - 1) as usize * w;
    let at = |row: usize, col: usize| f64::from(z[row + col]);
    let gx = (at(rm, cp) + 2.0 * at(r0, cp) + at(rp, cp)) - (at(rm, cm) + 2.0 * at(r0, cm) + at(rp, cm));
    let gy =
        (at(rp, cm) + 2.0 * at(rp, c as usize) + at(rp, cp)) - (at(rm, cm) + 2.0 * at(rm, c as usize) + at(rm, cp));
    let k = 1.0 / (8.0 * cell);
    [gx * k, gy * k]
}
