//! The incircle test of the rocks' triangulations: Shewchuk's filter alone (as `robust` computes
//! it), answering 0 — "do not flip" — when the floating-point determinant is within its error
//! bound of 0.
//!
//! Why not the exact test: Voronoi cells of seeds on pixel centres are often exactly cocircular
//! (square and rectangular cells of r = 1, cells cut by the field's edges), so about one rock in
//! two asks about four cocircular points, which the exact stages resolve at some thousands of
//! instructions a call — for nothing, since any triangulation of cocircular points is Delaunay.
//! An edge is flipped only when the filter proves its quadrilateral's fourth point strictly
//! inside the circle, so every flip is one the exact test would make: Lawson's flips still end,
//! and the result is Delaunay to within the filter's bound (about 10⁻¹⁵ of the determinant's
//! terms), which is what the tests check with their own circumcircles.

const EPSILON: f64 = 0.000_000_000_000_000_111_022_302_462_515_65;
const ICCERRBOUND_A: f64 = (10.0 + 96.0 * EPSILON) * EPSILON;

/// Positive when `d` is certainly inside the circle through `a`, `b`, `c` (counter-clockwise),
/// negative when certainly outside, 0 when too near the circle for floating point to tell.
#[inline]
pub fn incircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    // robust's filter, the same operations in the same order.
    let adx = a[0] - d[0];
    let bdx = b[0] - d[0];
    let cdx = c[0] - d[0];
    let ady = a[1] - d[1];
    let bdy = b[1] - d[1];
    let cdy = c[1] - d[1];
    let bdxcdy = bdx * cdy;
    let cdxbdy = cdx * bdy;
    let alift = adx * adx + ady * ady;
    let cdxady = cdx * ady;
    let adxcdy = adx * cdy;
    let blift = bdx * bdx + bdy * bdy;
    let adxbdy = adx * bdy;
    let bdxady = bdx * ady;
    let clift = cdx * cdx + cdy * cdy;
    let det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * alift
        + (cdxady.abs() + adxcdy.abs()) * blift
        + (adxbdy.abs() + bdxady.abs()) * clift;
    let errbound = ICCERRBOUND_A * permanent;
    if det > errbound || -det > errbound { det } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use robust::Coord;

    fn co(p: [f64; 2]) -> Coord<f64> {
        Coord { x: p[0], y: p[1] }
    }

    /// Never the wrong sign against `robust::incircle` (exact), on random, cocircular and nearly
    /// cocircular points; 0 for exactly cocircular ones; and decided on random points.
    #[test]
    fn never_contradicts_the_exact_test() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut undecided = 0;
        let check = |a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]| {
            let ours = incircle(a, b, c, d);
            let exact = robust::incircle(co(a), co(b), co(c), co(d));
            assert!(
                ours == 0.0 || ours.signum() == exact.signum(),
                "{a:?} {b:?} {c:?} {d:?}"
            );
            if exact == 0.0 {
                assert_eq!(ours, 0.0, "{a:?} {b:?} {c:?} {d:?}");
            }
            ours
        };
        for _ in 0..20_000 {
            let p = |rng: &mut ChaCha8Rng| [rng.random::<f64>() * 512.0, rng.random::<f64>() * 512.0];
            if check(p(&mut rng), p(&mut rng), p(&mut rng), p(&mut rng)) == 0.0 {
                undecided += 1;
            }
            // A rectangle's corners (exactly cocircular), at a random place and size.
            let (x, y) = (
                (rng.random::<f64>() * 512.0).floor() + 0.5,
                (rng.random::<f64>() * 512.0).floor(),
            );
            let (w, h) = (rng.random::<f64>() * 3.0, rng.random::<f64>() * 3.0);
            check([x, y], [x + w, y], [x + w, y + h], [x, y + h]);
            // Nearly cocircular: the fourth corner nudged by an ulp.
            check([x, y], [x + w, y], [x + w, y + h], [x.next_up(), y + h]);
            // A diamond about a pixel centre.
            check([x, y - 0.5], [x + 0.5, y], [x, y + 0.5], [x - 0.5, y]);
            // Quarter-cell corners, cocircular and a quarter off.
            let (i, j) = (x.floor(), y.floor());
            check([i, j], [i + 1.25, j], [i + 1.25, j + 0.75], [i, j + 0.75]);
            check([i, j], [i + 1.25, j], [i + 1.25, j + 0.75], [i + 0.25, j + 0.75]);
            check([i, j], [i + 1.25, j], [i + 1.25, j + 0.75], [i - 0.25, j + 0.75]);
        }
        assert!(undecided < 20, "{undecided} random quadruples undecided");
    }
}
