//! The exact incircle test of the rocks' triangulations, cheaper than calling
//! [`robust::incircle`] alone when points are nearly cocircular.
//!
//! Why: Voronoi cells of seeds on pixel centres are often exactly cocircular (square and
//! rectangular cells of r = 1, cells cut by the field's edges), so about one rock in two asks
//! `incircle` of four cocircular points. The filter then fails and `robust`'s adaptive stage
//! zero-fills some 20 KB of stack for its later stages (two 1152-entry expansions) before its
//! first exact stage — fig. 1 spent a fifth of all its instructions in that `memset`. Here the
//! filter is `robust`'s, and the next stage is Shewchuk's stage B with buffers sized for it
//! (at most 96 terms): when the coordinate differences are exact (their tails zero — always
//! so for such cells, whose vertices are close together), stage B's sum is the exact
//! determinant, and its value is the one `robust::incircle` returns on that same path. Otherwise
//! (differences that round) this falls back to `robust::incircle`, which starts again and goes
//! through its later stages. The functions below are Shewchuk's (`predicates.c`), as `robust`
//! ports them.

use robust::Coord;

const SPLITTER: f64 = 134_217_729f64;
const EPSILON: f64 = 0.000_000_000_000_000_111_022_302_462_515_65;
const ICCERRBOUND_A: f64 = (10.0 + 96.0 * EPSILON) * EPSILON;

/// Positive when `d` lies inside the circle through `a`, `b`, `c` (counter-clockwise), negative
/// outside, 0 when the four are cocircular; exact in sign, as [`robust::incircle`].
#[inline]
pub fn incircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    // Stage A: robust's filter, the same operations in the same order.
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
    if det > errbound || -det > errbound {
        return det;
    }
    exact_differences(a, b, c, d, det).unwrap_or_else(|| robust::incircle(co(a), co(b), co(c), co(d)))
}

/// Whether the six (exact) differences are whole multiples of 1/16 below 256 in size, as for
/// the cocircular cells (Voronoi vertices of pixel-centre seeds at halves and quarters, the
/// field's edges). Then every product and sum of the filter's determinant is a whole number of
/// 2⁻⁸ or 2⁻¹⁶ below 2⁵² of them, so the filter computed it exactly: its sign is the
/// determinant's.
#[inline]
fn small_dyadic(diffs: [f64; 6]) -> bool {
    diffs.iter().all(|&v| {
        let sixteenths = v * 16.0;
        sixteenths.abs() < 4096.0 && sixteenths == sixteenths.trunc()
    })
}

fn co(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Stage B when the six coordinate differences are exact: the determinant as an exact
/// expansion, its estimate returned (its sign is the determinant's), or the filter's
/// `filtered` when that was exact ([`small_dyadic`]). `None` when a difference rounds.
#[cold]
#[inline(never)]
fn exact_differences(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2], filtered: f64) -> Option<f64> {
    let (adx, adxt) = two_diff(a[0], d[0]);
    let (bdx, bdxt) = two_diff(b[0], d[0]);
    let (cdx, cdxt) = two_diff(c[0], d[0]);
    let (ady, adyt) = two_diff(a[1], d[1]);
    let (bdy, bdyt) = two_diff(b[1], d[1]);
    let (cdy, cdyt) = two_diff(c[1], d[1]);
    if [adxt, bdxt, cdxt, adyt, bdyt, cdyt].iter().any(|&t| t != 0.0) {
        return None;
    }
    if small_dyadic([adx, bdx, cdx, ady, bdy, cdy]) {
        return Some(filtered);
    }
    // det = (adx² + ady²)·(bdx·cdy − cdx·bdy) + (bdx² + bdy²)·(cdx·ady − adx·cdy)
    //     + (cdx² + cdy²)·(adx·bdy − bdx·ady), each term as robust's incircleadapt forms it.
    let term = |x: f64, y: f64, p: (f64, f64), q: (f64, f64), out: &mut [f64; 32]| -> usize {
        let (p1, p0) = two_product(p.0, p.1);
        let (q1, q0) = two_product(q.0, q.1);
        let (m3, m2, m1, m0) = two_two_diff(p1, p0, q1, q0);
        let m = [m0, m1, m2, m3];
        let (mut xm, mut xxm, mut ym, mut yym) = ([0f64; 8], [0f64; 16], [0f64; 8], [0f64; 16]);
        let xl = scale_expansion_zeroelim(&m, x, &mut xm);
        let xxl = scale_expansion_zeroelim(&xm[..xl], x, &mut xxm);
        let yl = scale_expansion_zeroelim(&m, y, &mut ym);
        let yyl = scale_expansion_zeroelim(&ym[..yl], y, &mut yym);
        fast_expansion_sum_zeroelim(&xxm[..xxl], &yym[..yyl], out)
    };
    let (mut adet, mut bdet, mut cdet) = ([0f64; 32], [0f64; 32], [0f64; 32]);
    let al = term(adx, ady, (bdx, cdy), (cdx, bdy), &mut adet);
    let bl = term(bdx, bdy, (cdx, ady), (adx, cdy), &mut bdet);
    let cl = term(cdx, cdy, (adx, bdy), (bdx, ady), &mut cdet);
    let mut ab = [0f64; 64];
    let abl = fast_expansion_sum_zeroelim(&adet[..al], &bdet[..bl], &mut ab);
    let mut fin = [0f64; 96];
    let fl = fast_expansion_sum_zeroelim(&ab[..abl], &cdet[..cl], &mut fin);
    Some(fin[..fl].iter().skip(1).fold(fin[0], |q, &t| q + t))
}

#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = SPLITTER * a;
    let abig = c - a;
    let ahi = c - abig;
    (ahi, a - ahi)
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let (ahi, alo) = split(a);
    let (bhi, blo) = split(b);
    let err1 = x - (ahi * bhi);
    let err2 = err1 - (alo * bhi);
    let err3 = err2 - (ahi * blo);
    (x, (alo * blo) - err3)
}

#[inline]
fn two_product_presplit(a: f64, b: f64, bhi: f64, blo: f64) -> (f64, f64) {
    let x = a * b;
    let (ahi, alo) = split(a);
    let err1 = x - ahi * bhi;
    let err2 = err1 - alo * bhi;
    let err3 = err2 - ahi * blo;
    (x, alo * blo - err3)
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bvirt = x - a;
    let avirt = x - bvirt;
    let bround = b - bvirt;
    let around = a - avirt;
    (x, around + bround)
}

#[inline]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bvirt = x - a;
    (x, b - bvirt)
}

#[inline]
fn two_diff(a: f64, b: f64) -> (f64, f64) {
    let x = a - b;
    let bvirt = a - x;
    let avirt = x + bvirt;
    let bround = bvirt - b;
    let around = a - avirt;
    (x, around + bround)
}

#[inline]
fn two_one_diff(a1: f64, a0: f64, b: f64) -> (f64, f64, f64) {
    let (i, x0) = two_diff(a0, b);
    let (x2, x1) = two_sum(a1, i);
    (x2, x1, x0)
}

#[inline]
fn two_two_diff(a1: f64, a0: f64, b1: f64, b0: f64) -> (f64, f64, f64, f64) {
    let (j, r0, x0) = two_one_diff(a1, a0, b0);
    let (x3, x2, x1) = two_one_diff(j, r0, b1);
    (x3, x2, x1, x0)
}

fn scale_expansion_zeroelim(e: &[f64], b: f64, h: &mut [f64]) -> usize {
    let (bhi, blo) = split(b);
    let (mut q, hh) = two_product_presplit(e[0], b, bhi, blo);
    let mut n = 0;
    if hh != 0.0 {
        h[n] = hh;
        n += 1;
    }
    for &enow in &e[1..] {
        let (product1, product0) = two_product_presplit(enow, b, bhi, blo);
        let (sum, hh) = two_sum(q, product0);
        if hh != 0.0 {
            h[n] = hh;
            n += 1;
        }
        let (new_q, hh) = fast_two_sum(product1, sum);
        q = new_q;
        if hh != 0.0 {
            h[n] = hh;
            n += 1;
        }
    }
    if q != 0.0 || n == 0 {
        h[n] = q;
        n += 1;
    }
    n
}

fn fast_expansion_sum_zeroelim(e: &[f64], f: &[f64], h: &mut [f64]) -> usize {
    let (mut ei, mut fi) = (0, 0);
    let mut q;
    if (f[0] > e[0]) == (f[0] > -e[0]) {
        q = e[0];
        ei += 1;
    } else {
        q = f[0];
        fi += 1;
    }
    let mut n = 0;
    if ei < e.len() && fi < f.len() {
        let (qn, hh) = if (f[fi] > e[ei]) == (f[fi] > -e[ei]) {
            ei += 1;
            fast_two_sum(e[ei - 1], q)
        } else {
            fi += 1;
            fast_two_sum(f[fi - 1], q)
        };
        q = qn;
        if hh != 0.0 {
            h[n] = hh;
            n += 1;
        }
        while ei < e.len() && fi < f.len() {
            let (qn, hh) = if (f[fi] > e[ei]) == (f[fi] > -e[ei]) {
                ei += 1;
                two_sum(q, e[ei - 1])
            } else {
                fi += 1;
                two_sum(q, f[fi - 1])
            };
            q = qn;
            if hh != 0.0 {
                h[n] = hh;
                n += 1;
            }
        }
    }
    for &t in e[ei..].iter().chain(&f[fi..]) {
        let (qn, hh) = two_sum(q, t);
        q = qn;
        if hh != 0.0 {
            h[n] = hh;
            n += 1;
        }
    }
    if q != 0.0 || n == 0 {
        h[n] = q;
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The same value as `robust::incircle` (not only the same sign) on random, cocircular and
    /// nearly cocircular points, the last two taking the exact stage.
    #[test]
    fn agrees_with_robust() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let check = |a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]| {
            let ours = incircle(a, b, c, d);
            let theirs = robust::incircle(co(a), co(b), co(c), co(d));
            // The same sign always (the exact sign); the same value but where the exact
            // determinant is a small dyadic one, taken from the filter, which robust may sum in
            // another order.
            assert_eq!(
                ours.partial_cmp(&0.0),
                theirs.partial_cmp(&0.0),
                "{a:?} {b:?} {c:?} {d:?}"
            );
            let dyadic = [a, b, c]
                .iter()
                .flat_map(|p| [p[0] - d[0], p[1] - d[1]])
                .all(|v| (v * 16.0).abs() < 4096.0 && (v * 16.0).fract() == 0.0);
            if !dyadic {
                assert_eq!(ours.to_bits(), theirs.to_bits(), "{a:?} {b:?} {c:?} {d:?}");
            }
        };
        for _ in 0..20_000 {
            let p = |rng: &mut ChaCha8Rng| [rng.random::<f64>() * 512.0, rng.random::<f64>() * 512.0];
            check(p(&mut rng), p(&mut rng), p(&mut rng), p(&mut rng));
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
    }
}
