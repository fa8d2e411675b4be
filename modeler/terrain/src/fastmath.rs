//! The natural logarithm and exponential the terrain engine evaluates eq. 2 with (issue 18):
//! short polynomials without tables or branches, so that a loop over a stretch of cells compiles
//! to vector instructions (SSE2's two `f64` lanes on the baseline x86-64 target, four and eight
//! in the AVX2 and AVX-512 copies of the engine's loops, [`crate::simd`]), where `libm`'s
//! functions are one call per cell.
//!
//! They are not `libm`'s to the bit. Measured against `libm` over the domains the engine uses
//! (the tests below, dense samples, 24 Nov): [`ln`] within 2⁻⁴⁹·⁴ relative (its series'
//! truncation, 2⁻⁵⁰·⁴, plus roundings), so `ln(x) as f32` is `libm`'s except within that distance
//! of a rounding boundary, and then one `f32` unit away (none of the 1.3 million samples);
//! [`exp`] within 2⁻⁴⁶·⁷ relative (the Taylor polynomial's truncation, 2⁻⁴⁷·², plus roundings). The engine's
//! heights therefore differ from a `libm` evaluation ([`crate::profile::shape_log`] and
//! [`crate::profile::shape_from_log`], the seed's equations) by at most an `f32` unit of the
//! relief in a few cells; they are still the same on every path of the engine, since every path
//! calls these functions ([`shape_log`], [`shape_from_log`]).

/// ln 2 split so that `k·LN2_HI` is exact for |k| < 2¹¹ (its low bits are zero), and `LN2_LO`
/// the next 53 bits (ln 2 − `LN2_HI` rounded, not `LN_2 − LN2_HI`, which lacks them).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// The bits of √½: the reduction puts the mantissa in [√½, √2).
const SQRT_HALF_BITS: u64 = 0x3fe6_a09e_667f_3bcd;

/// 2⁵² + 2⁵¹: adding it rounds an `f64` below 2⁵¹ in magnitude to a whole number, which then
/// sits in the low bits of the sum.
const SHIFTER: f64 = 6_755_399_441_055_744.0;

/// `ln x`, for `x` positive and normal (the engine's `1 − w` and `w`, in (0, 1]), and `−∞` for
/// `x = 0`; relative error below 2⁻⁴⁹, and exactly 0 at 1. Other inputs (negative, subnormal,
/// infinite, NaN) give meaningless numbers.
///
/// `x = 2^k·m` with `m ∈ [√½, √2)`, `ln m = 2·atanh(t)` with `t = (m − 1)/(m + 1)`, |t| ≤ 0.1716,
/// by the series `2t·Σ t²ⁱ/(2i + 1)` to `t¹⁷` (the rest is below 2⁻⁵⁰·⁴ of the sum).
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    let bits = x.to_bits();
    // `tmp`'s top 12 bits are k (two's complement), its low 52 the mantissa's offset from √½.
    let tmp = bits.wrapping_sub(SQRT_HALF_BITS);
    let m = f64::from_bits(bits.wrapping_sub(tmp & 0xfff0_0000_0000_0000));
    // k + 2048 in [0, 4096) as an `f64` by the exponent trick (SSE2 has no vector conversion of
    // 64-bit integers): 2⁵² + (k + 2048), less 2⁵² + 2048.
    let k_biased = ((tmp >> 52).wrapping_add(2048)) & 0xfff;
    let k = f64::from_bits(k_biased | 0x4330_0000_0000_0000) - (4_503_599_627_370_496.0 + 2048.0);
    let f = m - 1.0;
    let t = f / (2.0 + f);
    let z = t * t;
    // Estrin's scheme: short chains of dependent operations.
    let z2 = z * z;
    let z4 = z2 * z2;
    let a = (1.0 + z * (1.0 / 3.0)) + z2 * (1.0 / 5.0 + z * (1.0 / 7.0));
    let b = (1.0 / 9.0 + z * (1.0 / 11.0)) + z2 * (1.0 / 13.0 + z * (1.0 / 15.0));
    let p = a + z4 * (b + z4 * (1.0 / 17.0));
    let v = k * LN2_HI + (2.0 * t * p + k * LN2_LO);
    if x == 0.0 { f64::NEG_INFINITY } else { v }
}

/// `e^y`, for `y ≤ 709` (the engine's `y ≤ 0`, `−∞` included); relative error below 2⁻⁴⁶,
/// exactly 1 at 0, and 0 below −708 (where `libm`'s is below 2⁻¹⁰²¹, 0 in `f32`).
///
/// `y = n·ln 2 + r` with n whole and |r| ≤ ½ ln 2, `e^r` by its Taylor polynomial of degree 11
/// (the rest is below 2⁻⁴⁷·²), times 2ⁿ built in the exponent bits.
#[inline(always)]
pub fn exp(y: f64) -> f64 {
    // Clamped so that 2ⁿ is a normal number (the comparisons also map −∞ to −708).
    let x = if y < -708.0 { -708.0 } else { y };
    let x = if x > 709.0 { 709.0 } else { x };
    let t = x * std::f64::consts::LOG2_E + SHIFTER;
    let n = t - SHIFTER;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let r2 = r * r;
    let r4 = r2 * r2;
    let lo = (1.0 + r) + r2 * (1.0 / 2.0 + r * (1.0 / 6.0));
    let mid = (1.0 / 24.0 + r * (1.0 / 120.0)) + r2 * (1.0 / 720.0 + r * (1.0 / 5_040.0));
    let hi = (1.0 / 40_320.0 + r * (1.0 / 362_880.0)) + r2 * (1.0 / 3_628_800.0 + r * (1.0 / 39_916_800.0));
    let p = lo + r4 * (mid + r4 * hi);
    // n + 1023 in the exponent field: the low bits of `t` hold n (two's complement).
    let scale = f64::from_bits(t.to_bits().wrapping_add(1023) << 52);
    if y < -708.0 { 0.0 } else { p * scale }
}

/// [`crate::profile::shape_log`] with [`ln`]: eq. 2's logarithm for a weight `w` and the sign of
/// the slope `s`, rounded to `f32` — `ln(1 − w)` for `s > 0`, `ln(w)` for `s < 0`, 0 for `s = 0`.
#[inline(always)]
pub fn shape_log(w: f64, s: f64) -> f32 {
    // The argument is chosen first, so that the one `ln` is taken without a branch.
    let x = if s > 0.0 {
        1.0 - w
    } else if s < 0.0 {
        w
    } else {
        1.0
    };
    ln(x) as f32
}

/// [`crate::profile::shape_from_log`] with [`exp`]: eq. 2 divided by the relief from
/// [`shape_log`]'s `l` for the same sign of `s` — `1 − e^((1+s)·l)` for `s > 0`, `e^((1−s)·l)`
/// for `s < 0`, `w` for `s = 0`. The same as [`shape_from_exp`] of the [`exp`] of [`power`], the
/// three steps the engine takes in separate loops.
#[inline(always)]
pub fn shape_from_log(w: f64, l: f32, s: f64) -> f64 {
    shape_from_exp(w, exp(power(l, s)), s)
}

/// The power eq. 2 takes the exponential of, from [`shape_log`]'s `l`: `(1 + |s|)·l`.
#[inline(always)]
pub fn power(l: f32, s: f64) -> f64 {
    let p = if s > 0.0 { 1.0 + s } else { 1.0 - s };
    p * f64::from(l)
}

/// Eq. 2 divided by the relief from the exponential `e` of [`power`]: `1 − e` for `s > 0`, `e`
/// for `s < 0`, `w` for `s = 0`.
#[inline(always)]
pub fn shape_from_exp(w: f64, e: f64, s: f64) -> f64 {
    let v = if s > 0.0 { 1.0 - e } else { e };
    if s == 0.0 { w } else { v }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed scatter of `n` numbers over `[lo, hi)` (a multiplicative hash), with the ends.
    fn scatter(lo: f64, hi: f64, n: u64) -> Vec<f64> {
        let mut v: Vec<f64> = (0..n)
            .map(|i| lo + (hi - lo) * ((i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11) as f64 / (1u64 << 53) as f64))
            .collect();
        v.extend([lo, hi]);
        v
    }

    /// `x`'s distance from `want` in units of `want`'s magnitude.
    fn relative(x: f64, want: f64) -> f64 {
        if x == want { 0.0 } else { ((x - want) / want).abs() }
    }

    /// The units in the last place of `f32` between two numbers of the same sign.
    fn f32_ulps(a: f32, b: f32) -> u32 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs() as u32
    }

    /// Logarithms of (0, 1] — every binade down to 2⁻¹⁰²² and the engine's range of weights
    /// densely — and a few above 1.
    fn ln_inputs() -> Vec<f64> {
        let mut xs = scatter(0.0, 1.0, 1_000_000);
        xs.retain(|&x| x > 0.0);
        xs.extend(scatter(0.999_999, 1.0, 100_000));
        for e in -1022..8 {
            let b = 2f64.powi(e);
            xs.extend(scatter(b, 2.0 * b, 200));
        }
        xs.extend([
            1.0,
            f64::MIN_POSITIVE,
            1.0 - f64::EPSILON / 2.0,
            std::f64::consts::FRAC_1_SQRT_2,
        ]);
        xs
    }

    #[test]
    fn ln_is_within_2_pow_minus_49_of_libm() {
        let (mut worst, mut f32_off, mut n) = (0.0f64, 0, 0);
        for x in ln_inputs() {
            let (got, want) = (ln(x), x.ln());
            worst = worst.max(relative(got, want));
            let ulps = f32_ulps(got as f32, want as f32);
            assert!(ulps <= 1, "ln {x:e}: {got:e} against {want:e}");
            f32_off += usize::from(ulps != 0);
            n += 1;
        }
        assert!(worst < 2f64.powi(-49), "worst relative error {worst:e}");
        // Rounded to `f32`, almost every logarithm is `libm`'s.
        assert!(f32_off * 10_000 < n, "{f32_off} of {n} off by an f32 unit");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
    }

    #[test]
    fn exp_is_within_2_pow_minus_46_of_libm() {
        let mut ys = scatter(-40.0, 0.0, 1_000_000);
        ys.extend(scatter(-708.0, 709.0, 200_000));
        ys.extend(scatter(-1e-6, 0.0, 10_000));
        let mut worst = 0.0f64;
        for &y in &ys {
            worst = worst.max(relative(exp(y), y.exp()));
        }
        assert!(worst < 2f64.powi(-46), "worst relative error {worst:e}");
        assert_eq!(exp(0.0), 1.0);
        for y in [-708.5, -745.0, -1e300, f64::NEG_INFINITY] {
            assert_eq!(exp(y), 0.0, "exp {y:e}");
        }
        // Below 1 for every negative argument (a shape term stays in [0, 1]).
        assert!(ys.iter().filter(|&&y| y < 0.0).all(|&y| exp(y) <= 1.0 && exp(y) >= 0.0));
    }

    /// The shape terms, rounded to `f32` as the engine keeps them, against `libm`'s through
    /// `profile`: at most one `f32` unit of 1 apart (the scale a shape multiplies the relief by).
    #[test]
    fn shapes_are_within_an_f32_unit_of_the_profile_functions() {
        let ws = scatter(0.0, 1.0, 200_000);
        let mut worst = 0.0f64;
        for (i, &w) in ws.iter().chain(&[0.0, 1.0]).enumerate() {
            let s = [0.3, -0.7, 2.5, -4.0, 0.0, 15.0, -30.0][i % 7];
            let (l, want_l) = (shape_log(w, s), crate::profile::shape_log(w, s));
            assert!(f32_ulps(l, want_l) <= 1, "log at w {w} s {s}: {l} against {want_l}");
            let got = shape_from_log(w, l, s) as f32;
            let want = crate::profile::shape_from_log(w, want_l, s) as f32;
            assert!((0.0..=1.0).contains(&got), "shape {got} at w {w} s {s}");
            worst = worst.max(f64::from((got - want).abs()));
        }
        assert!(worst <= f64::from(f32::EPSILON), "worst difference {worst:e}");
    }
}
