//! Seed 000's equations 1–4 (thesis chapter 4), as pure functions of one cell's numbers.
//!
//! The engine evaluates them per cell; they are public so the rules can be read and tested on
//! their own. These are the seed's equations with `libm`'s `ln`, `exp` and `powf`; the engine
//! takes eq. 2's logarithm and exponential from [`crate::fastmath`] instead (its polynomials,
//! vectorised; within 2⁻⁴⁶ relative of these, see there for the measured errors).

use crate::distance::UNREACHABLE;

/// Eq. 1, the weight of a cell for one figure: `w = df / (df + dp)`, and `w = 1` on the figure
/// (`dp = 0`, even where `df = 0`). A cell the figure cannot reach (`dp` = [`UNREACHABLE`]) has
/// `w = 0`.
pub fn weight(df: u32, dp: u32) -> f64 {
    weight_real(f64::from(df), real(dp))
}

/// A taxicab distance as a real one: [`UNREACHABLE`] is infinite.
fn real(d: u32) -> f64 {
    if d == UNREACHABLE { f64::INFINITY } else { f64::from(d) }
}

/// Eq. 1 for distances of either metric (`dp` infinite where the figure cannot reach): the same
/// numbers as [`weight`] on whole distances.
#[inline]
pub fn weight_real(df: f64, dp: f64) -> f64 {
    if dp == 0.0 {
        1.0
    } else if dp == f64::INFINITY {
        0.0
    } else {
        df / (df + dp)
    }
}

/// Eq. 2 divided by the relief `H`: the share of `H` a cell of weight `w` gets with slope `s`.
/// `s ≥ 0`: `1 − (1 − w)^(1+s)` (bell-shaped for s > 0); `s < 0`: `w^(1−s)` (sharp).
/// Both are 0 at `w = 0`, 1 at `w = 1`, and linear (`w`) at `s = 0`.
pub fn shape(w: f64, s: f64) -> f64 {
    if s == 0.0 {
        w
    } else if s > 0.0 {
        1.0 - (1.0 - w).powf(1.0 + s)
    } else {
        w.powf(1.0 - s)
    }
}

/// The logarithm eq. 2's power takes for a weight `w` and the sign of the slope `s`, rounded to
/// `f32`: `ln(1 − w)` for `s > 0`, `ln(w)` for `s < 0` (0 for `s = 0`, where it is not used).
/// The terrain engine keeps it per cell, so that a slope change costs one `exp` per cell
/// ([`shape_from_log`]).
pub fn shape_log(w: f64, s: f64) -> f32 {
    if s > 0.0 {
        (1.0 - w).ln() as f32
    } else if s < 0.0 {
        w.ln() as f32
    } else {
        0.0
    }
}

/// Eq. 2 divided by the relief as the terrain engine evaluates it, from [`shape_log`]'s `l` for
/// the same sign of `s`: `1 − e^((1+s)·l)` for `s > 0`, `e^((1−s)·l)` for `s < 0`, `w` for
/// `s = 0`. It differs from [`shape`] by less than an `f32` unit at 1: the rounding of `l`
/// moves the power by `|p·ln x|·2⁻²⁴` relative, and `x^p·|p·ln x| ≤ 1/e`.
pub fn shape_from_log(w: f64, l: f32, s: f64) -> f64 {
    if s == 0.0 {
        w
    } else if s > 0.0 {
        1.0 - ((1.0 + s) * f64::from(l)).exp()
    } else {
        ((1.0 - s) * f64::from(l)).exp()
    }
}

/// Eq. 2: the height of a cell of weight `w` for a figure of relief `h` and slope `s`.
pub fn profile(h: f64, w: f64, s: f64) -> f64 {
    h * shape(w, s)
}

/// Eq. 4, the slope a nested figure uses at a cell of weight `w`: `(s1 + s0)·w − s0`, where `s1`
/// is the figure's slope and `s0` the enclosing closed figure's. It is `−s0` at the nested
/// region's edge, mirroring the parent's slope there so the two slopes join, and `s1` on the figure.
#[inline]
pub fn nested_slope(s1: f64, s0: f64, w: f64) -> f64 {
    (s1 + s0) * w - s0
}

/// Eq. 3's inverse-distance weight of a figure at distance `dp ≥ 1` (0 when unreachable).
pub fn inverse_distance(dp: u32) -> f64 {
    inverse_distance_real(real(dp))
}

/// Eq. 3's weight for a distance of either metric: `1/dp`, 0 when infinite.
#[inline]
pub fn inverse_distance_real(dp: f64) -> f64 {
    1.0 / dp
}

/// Eq. 3: the relief of a cell from each figure's `(dp, relief)`. A cell on one or more figures
/// (`dp = 0`) takes their mean relief; elsewhere `Σ(h_k / dp_k) / Σ(1 / dp_k)`. Figures that
/// cannot reach the cell weigh nothing; a cell none reaches has relief 0.
pub fn blend(figures: &[(u32, f64)]) -> f64 {
    let on: Vec<f64> = figures.iter().filter(|(dp, _)| *dp == 0).map(|&(_, h)| h).collect();
    if !on.is_empty() {
        return on.iter().sum::<f64>() / on.len() as f64;
    }
    let (num, den) = figures.iter().fold((0.0, 0.0), |(n, d), &(dp, h)| {
        let k = inverse_distance(dp);
        (n + h * k, d + k)
    });
    if den == 0.0 { 0.0 } else { num / den }
}
