//! The pivot: where the pen's tip is, seen from its emitter, in the display frame.
//!
//! The emitter sits a few millimetres up the pen from its tip. The fit of the targets
//! ([`super::fit`]) takes the emitter's positions for the tip's, so its translation takes in
//! the emitter-to-tip vector of a pen held as during the touches: right for the pen, which is
//! held that way, and wrong by that vector for anything else the same map carries — the tracked
//! glasses' emitter (issue 16), whose position is the emitter's own.
//!
//! To tell that vector apart from the display's pose, the user holds the tip on one target and
//! tilts the pen about it, its top circling (the tool-tip "pivot calibration" of optical
//! trackers). The emitter then sweeps part of a sphere about the tip: a least-squares sphere
//! through its fixes has the tip at its centre (tracker frame) and the emitter's distance from
//! the tip as its radius. The fit calibration maps that centre to the target plus the vector it
//! took in, so the vector is the mapped centre less the target.
//!
//! The sphere is fitted algebraically first (linear in the centre and r² − |c|²), then by
//! Gauss–Newton on the distances themselves: the algebraic fit of a cap (the pen tilts over tens
//! of degrees, not all round) is pulled towards its chord by the noise — with 0.3 mm of noise on
//! a cap between 12° and 48° of lean, 0.7 mm along the pen's axis (a simulation of 300 pivots
//! of 400 fixes) — the geometric one is not.

use glam::{DMat4, DVec2, DVec3, DVec4};
use thiserror::Error;

use super::fit::Calibration;

/// Fixes a pivot needs.
pub const MIN_FIXES: usize = 100;
/// The least tilt a pivot must sweep, degrees: the widest angle between two of the emitter's
/// directions from the tip. Less, and the sphere is hardly curved over its fixes.
pub const MIN_TILT_DEG: f64 = 20.0;
/// Emitter distances from the tip a pen can have, mm.
pub const RADIUS_MM: std::ops::RangeInclusive<f64> = 2.0..=60.0;
/// The most the fixes may stray from the sphere, mm RMS: more, and the tip slid.
pub const MAX_RMS_MM: f64 = 1.5;

/// A pivot's sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pivot {
    /// The tip, tracker frame, mm (the sphere's centre).
    pub tip_mm: DVec3,
    /// The emitter's distance from the tip, mm (the sphere's radius).
    pub radius_mm: f64,
    /// How far the fixes are from the sphere, RMS, mm.
    pub rms_mm: f64,
    /// The widest angle between two of the emitter's directions from the tip, degrees.
    pub tilt_deg: f64,
    /// Fixes fitted.
    pub fixes: usize,
}

/// Why a pivot is refused.
#[derive(Debug, Error, PartialEq)]
pub enum PivotError {
    /// Too short.
    #[error("the pivot took {got} fixes, it needs {MIN_FIXES}: hold the tip down while tilting the pen")]
    TooFewFixes {
        /// Fixes taken.
        got: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("pivot fix {index} is not finite")]
    NotFinite {
        /// Which.
        index: usize,
    },
    /// The fixes do not determine a sphere (all on one plane, or one circle).
    #[error("the pivot's fixes do not determine the tip: tilt the pen through different leans as its top circles")]
    Degenerate,
    /// The pen was hardly tilted.
    #[error("the pen tilted through only {deg:.0}° about its tip, it needs {MIN_TILT_DEG:.0}°: circle its top wider")]
    TooLittleTilt {
        /// The widest angle swept.
        deg: f64,
    },
    /// The sphere is not a pen's.
    #[error("the emitter came out {mm:.1} mm from the tip, not a pen's (2–60 mm): keep the tip still on the target")]
    Radius {
        /// The sphere's radius.
        mm: f64,
    },
    /// The fixes stray from the sphere.
    #[error(
        "the fixes stray {rms_mm:.2} mm RMS from a sphere (at most {MAX_RMS_MM} mm): keep the tip still on the target"
    )]
    Unsteady {
        /// RMS distance from the sphere.
        rms_mm: f64,
    },
}

/// The sphere through the emitter's fixes of a pivot (tracker frame, mm).
pub fn fit_pivot(points: &[DVec3]) -> Result<Pivot, PivotError> {
    if points.len() < MIN_FIXES {
        return Err(PivotError::TooFewFixes { got: points.len() });
    }
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(PivotError::NotFinite { index });
    }
    // Centred on the mean, so the normal equations are well scaled.
    let mean = points.iter().sum::<DVec3>() / points.len() as f64;
    let (mut centre, mut radius) = algebraic(points, mean).ok_or(PivotError::Degenerate)?;
    for _ in 0..GAUSS_NEWTON_STEPS {
        let step = geometric_step(points, mean + centre, radius).ok_or(PivotError::Degenerate)?;
        centre += step.truncate();
        radius += step.w;
        if step.length() < 1e-9 {
            break;
        }
    }
    let tip_mm = mean + centre;
    if !tip_mm.is_finite() || !radius.is_finite() {
        return Err(PivotError::Degenerate);
    }
    if !RADIUS_MM.contains(&radius) {
        return Err(PivotError::Radius { mm: radius });
    }
    let rms_mm = (points
        .iter()
        .map(|p| (p.distance(tip_mm) - radius).powi(2))
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    if rms_mm > MAX_RMS_MM {
        return Err(PivotError::Unsteady { rms_mm });
    }
    let tilt_deg = widest_angle(points, tip_mm);
    if tilt_deg < MIN_TILT_DEG {
        return Err(PivotError::TooLittleTilt { deg: tilt_deg });
    }
    Ok(Pivot {
        tip_mm,
        radius_mm: radius,
        rms_mm,
        tilt_deg,
        fixes: points.len(),
    })
}

/// The emitter-to-tip vector, display frame, mm, that `calibration`'s translation took in: the
/// pivot's tip as the calibration maps it, less the target it was held on (`at_mm`, on the
/// surface).
pub fn tip_offset(calibration: &Calibration, pivot: &Pivot, at_mm: DVec2) -> DVec3 {
    calibration.transform.apply(pivot.tip_mm) - at_mm.extend(0.0)
}

const GAUSS_NEWTON_STEPS: usize = 50;

/// The algebraic sphere: |q|² = 2 c·q + k over q = p − `mean`, least squares; (c, r).
fn algebraic(points: &[DVec3], mean: DVec3) -> Option<(DVec3, f64)> {
    let rows = points.iter().map(|p| {
        let q = *p - mean;
        ((2.0 * q).extend(1.0), q.length_squared())
    });
    let x = least_squares(rows)?;
    let c = x.truncate();
    let r2 = x.w + c.length_squared();
    (r2 > 0.0).then(|| (c, r2.sqrt()))
}

/// One Gauss–Newton step for the distances |p − c| − r: (Δc, Δr).
fn geometric_step(points: &[DVec3], centre: DVec3, radius: f64) -> Option<DVec4> {
    let mut rows = Vec::with_capacity(points.len());
    for p in points {
        let d = *p - centre;
        let len = d.length();
        if len <= 0.0 {
            return None;
        }
        // ∂(|p − c| − r)/∂(c, r) = (−u, −1); the step solves J·Δ = −residual.
        rows.push(((-d / len).extend(-1.0), radius - len));
    }
    least_squares(rows)
}

/// The least-squares solution of the rows (jᵀ·x = b) through the normal equations; `None`
/// when they are (nearly) singular: the fixes do not determine the unknowns.
fn least_squares(rows: impl IntoIterator<Item = (DVec4, f64)>) -> Option<DVec4> {
    let (mut a, mut b) = (DMat4::ZERO, DVec4::ZERO);
    for (j, rhs) in rows {
        a += DMat4::from_cols(j * j.x, j * j.y, j * j.z, j * j.w);
        b += j * rhs;
    }
    // Relative to the matrix's size: a circle's fixes leave one direction exactly unmeasured.
    let size = a.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let det = a.determinant();
    if !det.is_finite() || det.abs() <= 1e-12 * size.powi(4) {
        return None;
    }
    let x = a.inverse() * b;
    x.is_finite().then_some(x)
}

/// The widest angle between two directions from `tip` to the points, degrees: the largest over
/// each point and the one farthest from it in direction (linear in the points twice over, not
/// all pairs; the true widest pair's angle is at most twice this).
fn widest_angle(points: &[DVec3], tip: DVec3) -> f64 {
    let dirs = || points.iter().map(move |p| (*p - tip).normalize_or_zero());
    let mean = dirs().sum::<DVec3>().normalize_or_zero();
    // The direction farthest from the mean, then the one farthest from that.
    let far = |from: DVec3| {
        dirs()
            .min_by(|a, b| a.dot(from).total_cmp(&b.dot(from)))
            .unwrap_or(from)
    };
    let a = far(mean);
    let b = far(a);
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Emitter fixes of a pen `radius` long tilted about `tip`: its top circling once at a lean
    /// between `lean - swing` and `lean + swing` degrees about the axis `up`, with Gaussian-ish
    /// noise of about `noise` mm per axis.
    fn pivot(tip: DVec3, up: DVec3, radius: f64, lean: f64, swing: f64, noise: f64, n: usize) -> Vec<DVec3> {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let up = up.normalize();
        let (x, y) = up.any_orthonormal_pair();
        (0..n)
            .map(|i| {
                let s = i as f64 / n as f64;
                let az = std::f64::consts::TAU * s;
                let l = (lean + swing * (3.0 * std::f64::consts::TAU * s).sin()).to_radians();
                let dir = up * l.cos() + (x * az.cos() + y * az.sin()) * l.sin();
                // The sum of three uniforms: near enough a Gaussian of σ = noise.
                let mut jitter = || (0..3).map(|_| rng.random_range(-1.0..1.0)).sum::<f64>() * noise;
                tip + dir * radius + DVec3::new(jitter(), jitter(), jitter())
            })
            .collect()
    }

    #[test]
    fn the_centre_of_a_noiseless_pivot_is_the_tip() {
        let tip = DVec3::new(120.0, -40.0, 15.0);
        let p = fit_pivot(&pivot(tip, DVec3::new(0.1, 0.2, 1.0), 8.0, 30.0, 18.0, 0.0, 300)).expect("fits");
        assert!(p.tip_mm.distance(tip) < 1e-6, "{:?}", p.tip_mm);
        assert!((p.radius_mm - 8.0).abs() < 1e-6);
        assert!(p.rms_mm < 1e-6);
        // The lean spans 12°..48°, across the circle: the widest angle is 60°–96°.
        assert!(p.tilt_deg > 55.0 && p.tilt_deg <= 97.0, "{}", p.tilt_deg);
    }

    #[test]
    fn noise_does_not_pull_the_centre_towards_the_cap() {
        // 0.3 mm per axis on a cap: the algebraic fit alone would put the tip about 0.7 mm up
        // the pen; the geometric refinement has no such bias (the tolerance is about 3σ of the
        // centre's spread along the axis over such pivots, 0.11 mm in a simulation of 300).
        let tip = DVec3::new(300.0, 170.0, 0.0);
        let points = pivot(tip, DVec3::Z, 8.0, 30.0, 18.0, 0.3, 600);
        let p = fit_pivot(&points).expect("fits");
        assert!(p.tip_mm.distance(tip) < 0.4, "{:?}", p.tip_mm - tip);
        assert!((p.radius_mm - 8.0).abs() < 0.4, "{}", p.radius_mm);
        let mean = points.iter().sum::<DVec3>() / points.len() as f64;
        let (c, _) = algebraic(&points, mean).expect("algebraic");
        assert!(
            (mean + c).z - tip.z > 0.3,
            "the algebraic fit is biased, as said: {}",
            (mean + c).z
        );
    }

    #[test]
    fn a_pen_circled_at_one_lean_is_refused() {
        // All fixes on one circle: any sphere through it fits, the tip is not determined.
        let points = pivot(DVec3::ZERO, DVec3::Z, 8.0, 30.0, 0.0, 0.0, 300);
        assert_eq!(fit_pivot(&points), Err(PivotError::Degenerate));
    }

    #[test]
    fn bad_pivots_are_refused_with_the_reason() {
        let still = vec![DVec3::new(1.0, 2.0, 3.0); 200];
        assert!(fit_pivot(&still).is_err());
        assert_eq!(
            fit_pivot(&pivot(DVec3::ZERO, DVec3::Z, 8.0, 30.0, 18.0, 0.0, 50)),
            Err(PivotError::TooFewFixes { got: 50 })
        );
        let mut points = pivot(DVec3::ZERO, DVec3::Z, 8.0, 30.0, 18.0, 0.0, 300);
        points[17].y = f64::NAN;
        assert_eq!(fit_pivot(&points), Err(PivotError::NotFinite { index: 17 }));
        // A small wobble about 30°: 26°–34° across the circle... the circle is wide, so the
        // tilt check needs a pen that barely moves: 3° of lean, ±2°.
        let small = pivot(DVec3::ZERO, DVec3::Z, 8.0, 3.0, 2.0, 0.0, 300);
        assert!(
            matches!(fit_pivot(&small), Err(PivotError::TooLittleTilt { .. })),
            "{:?}",
            fit_pivot(&small)
        );
        // A tip that slid: 2 mm of noise.
        let slid = pivot(DVec3::ZERO, DVec3::Z, 8.0, 30.0, 18.0, 2.0, 300);
        assert!(
            matches!(
                fit_pivot(&slid),
                Err(PivotError::Unsteady { .. } | PivotError::Radius { .. })
            ),
            "{:?}",
            fit_pivot(&slid)
        );
    }

    #[test]
    fn the_offset_is_the_mapped_tip_less_the_target() {
        // An identity calibration: the tip's tracker position is its display position, so the
        // offset is the tip's distance from the target it was meant to be on.
        let cal = Calibration::identity(super::super::DisplaySize::REFERENCE);
        let p = Pivot {
            tip_mm: DVec3::new(301.0, 169.0, 2.0),
            radius_mm: 8.0,
            rms_mm: 0.1,
            tilt_deg: 60.0,
            fixes: 300,
        };
        assert_eq!(
            tip_offset(&cal, &p, DVec2::new(300.0, 170.0)),
            DVec3::new(1.0, -1.0, 2.0)
        );
    }
}
