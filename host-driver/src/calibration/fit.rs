//! The fit: the transform from the tracker frame to the display frame, from touched targets.
//!
//! The user touches targets at known positions on the display; each touch gives the pen's
//! position in the tracker frame. The best similarity (or rigid) transform mapping the touches
//! onto the targets is found in closed form by Horn's quaternion method (J. Opt. Soc. Am. A 4,
//! 1987): the rotation is the eigenvector of the largest eigenvalue of a symmetric 4×4 matrix
//! built from the point pairs, found here by Jacobi rotations. The display frame has `u` along
//! the display's width and `v` along its height, both from its lower-left corner, and `h` above
//! the surface along its normal; pixels follow from the display's size.
//!
//! The pen's emitter is a few millimetres from its tip. Held at the same angle for every touch,
//! that offset is the same vector each time and the fit's translation absorbs it: calibrated
//! positions are then the tip's, for a pen held as during calibration.

use glam::{DMat3, DQuat, DVec2, DVec3};
use pen_protocol::DisplayPose;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::device::DeviceId;
use crate::events::DisplayPoint;

/// The fewest targets a calibration takes.
pub const MIN_TARGETS: usize = 4;

/// Why a fit or a calibration file is refused.
#[derive(Debug, Error, PartialEq)]
#[allow(missing_docs)]
pub enum CalibrationError {
    /// Fewer than [`MIN_TARGETS`] points, or unequal lists.
    #[error("calibration needs at least {MIN_TARGETS} touched targets, got {0}")]
    TooFewPoints(usize),
    /// A coordinate is NaN or infinite.
    #[error("point {index} is not finite")]
    NotFinite { index: usize },
    /// The points lie (nearly) on one line: the rotation about it is undetermined.
    #[error(
        "the {which} points lie on one line (at most {spread_mm:.1} mm off it); spread the targets over the display"
    )]
    Collinear {
        /// "target" or "touched".
        which: &'static str,
        /// The largest distance from the line, mm.
        spread_mm: f64,
    },
    /// The fit does not determine the rotation.
    #[error("the points do not determine the rotation")]
    Degenerate,
    /// A calibration file could not be read or parsed.
    #[error("{path}: {message}")]
    File { path: String, message: String },
    /// The display's size is out of range.
    #[error("`display.{key}` {problem}")]
    Display {
        /// `width_mm`, `height_mm`, `width_px` or `height_px`.
        key: &'static str,
        problem: String,
    },
    /// The calibration belongs to another base station.
    #[error(
        "the calibration is for base station {calibrated}, not for the one attached, {attached}: \
         calibrate this one with `penctl calibrate` (or give its own file with --calibration FILE)"
    )]
    WrongDevice { calibrated: DeviceId, attached: DeviceId },
    /// The attached base station did not say which it is.
    #[error(
        "the calibration is for base station {calibrated}, and the one attached does not say which it is \
         ({why}); check it with `penctl info`"
    )]
    DeviceUnknown { calibrated: DeviceId, why: String },
    /// A calibration file has a bad value.
    #[error("{path}: `{key}` {problem}")]
    BadValue {
        path: String,
        /// The key, e.g. `transform.scale`.
        key: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// Rigid (rotation and translation) or similarity (and a uniform scale).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FitKind {
    /// Rotation and translation.
    Rigid,
    /// Rotation, translation and scale: absorbs a speed-of-sound error.
    Similarity,
}

/// The display's size, for pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplaySize {
    /// Width of the active area, mm.
    pub width_mm: f64,
    /// Height, mm.
    pub height_mm: f64,
    /// Width, pixels.
    pub width_px: u32,
    /// Height, pixels.
    pub height_px: u32,
}

impl DisplaySize {
    /// The reference build's display: 600 × 340 mm, 2560 × 1440 pixels.
    pub const REFERENCE: DisplaySize = DisplaySize {
        width_mm: 600.0,
        height_mm: 340.0,
        width_px: 2560,
        height_px: 1440,
    };

    /// Display sizes a calibration accepts, mm: from a small tablet to a wall.
    pub const MM_RANGE: std::ops::RangeInclusive<f64> = 20.0..=10_000.0;
    /// Pixel counts a calibration accepts along either side.
    pub const PX_RANGE: std::ops::RangeInclusive<u32> = 16..=65_536;

    /// Checks the sizes against [`MM_RANGE`](Self::MM_RANGE) and [`PX_RANGE`](Self::PX_RANGE):
    /// a size outside them is a mistake (metres for millimetres, a stray exponent), and one near
    /// zero would make every pixel coordinate infinite. The error names the key.
    pub fn check(&self) -> Result<(), CalibrationError> {
        let mm = |key, v: f64| {
            if Self::MM_RANGE.contains(&v) {
                Ok(())
            } else {
                Err(CalibrationError::Display {
                    key,
                    problem: format!(
                        "must be between {} and {} mm, is {}",
                        Self::MM_RANGE.start(),
                        Self::MM_RANGE.end(),
                        compact(v)
                    ),
                })
            }
        };
        let px = |key, v: u32| {
            if Self::PX_RANGE.contains(&v) {
                Ok(())
            } else {
                Err(CalibrationError::Display {
                    key,
                    problem: format!(
                        "must be between {} and {} pixels, is {v}",
                        Self::PX_RANGE.start(),
                        Self::PX_RANGE.end()
                    ),
                })
            }
        };
        mm("width_mm", self.width_mm)?;
        mm("height_mm", self.height_mm)?;
        px("width_px", self.width_px)?;
        px("height_px", self.height_px)
    }

    /// `n` target positions: 4 corners inset by 10 % (with the centre for 5), or a 3 × 3 grid at
    /// 10, 50 and 90 % for 9.
    pub fn targets(&self, n: usize) -> Vec<DVec2> {
        let at = |fx: f64, fy: f64| DVec2::new(fx * self.width_mm, fy * self.height_mm);
        let corners = [at(0.1, 0.1), at(0.9, 0.1), at(0.9, 0.9), at(0.1, 0.9)];
        match n {
            ..=4 => corners.to_vec(),
            5..=8 => [&corners[..], &[at(0.5, 0.5)]].concat(),
            _ => [0.1, 0.5, 0.9]
                .iter()
                .flat_map(|&fy| [0.1, 0.5, 0.9].map(|fx| at(fx, fy)))
                .collect(),
        }
    }

    /// Where the pivot is taken ([`super::pivot`]): the display's centre.
    pub fn pivot_target(&self) -> DVec2 {
        DVec2::new(0.5 * self.width_mm, 0.5 * self.height_mm)
    }
}

/// A fitted transform, tracker frame → display frame: `p_d = scale · R · p_t + translation`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs)]
pub struct Transform {
    pub rotation: DQuat,
    /// The translation, mm.
    pub translation_mm: DVec3,
    pub scale: f64,
}

impl Transform {
    /// The identity: the tracker frame is the display frame.
    pub const IDENTITY: Transform = Transform {
        rotation: DQuat::IDENTITY,
        translation_mm: DVec3::ZERO,
        scale: 1.0,
    };

    /// A tracker-frame point in the display frame.
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p * self.scale + self.translation_mm
    }

    /// The pose the device takes to report display coordinates itself, for a display of
    /// `size_mm` (width, height; the OS's pen collection spans it).
    pub fn to_device(&self, size_mm: [f64; 2]) -> DisplayPose {
        let (q, t) = (self.rotation, self.translation_mm);
        DisplayPose {
            rotation: [q.w as f32, q.x as f32, q.y as f32, q.z as f32],
            translation_mm: [t.x as f32, t.y as f32, t.z as f32],
            scale: self.scale as f32,
            size_mm: size_mm.map(|v| v as f32),
        }
    }
}

/// One target of a fit and how well it came out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetResidual {
    /// The target on the display, mm.
    pub target_mm: DVec2,
    /// Where the pen was when it touched it, tracker frame, mm.
    pub touched_mm: DVec3,
    /// The distance between the target and the fitted touch, mm (in the display plane and
    /// along its normal).
    pub residual_mm: f64,
}

/// A calibration: the transform, the display's size, and the fit it came from.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs)]
pub struct Calibration {
    /// Tracker → display.
    pub transform: Transform,
    /// Rigid or similarity.
    pub kind: FitKind,
    pub display: DisplaySize,
    /// Per target.
    pub residuals: Vec<TargetResidual>,
    /// The base station it was measured with, and the only one it is applied to; `None` for
    /// any (the identity, a fit not yet saved, a file of format version 1).
    pub device: Option<DeviceId>,
    /// The pen's emitter-to-tip vector in the display frame, mm, as the pen was held for the
    /// touches: the transform's translation took it in, so it is taken out again for the tracked
    /// glasses ([`head_to_display`](Self::head_to_display)). Measured by the pivot
    /// ([`super::pivot`]); `None` without one (older files, `penctl calibrate --no-pivot`).
    pub tip_offset_mm: Option<DVec3>,
}

impl Calibration {
    /// The pose and display size the device takes to report display coordinates itself, and
    /// the operating system's pen to span the display.
    pub fn to_device(&self) -> DisplayPose {
        self.transform
            .to_device([self.display.width_mm, self.display.height_mm])
    }

    /// The uncalibrated pass-through: tracker coordinates taken as display coordinates.
    pub fn identity(display: DisplaySize) -> Calibration {
        Calibration {
            transform: Transform::IDENTITY,
            kind: FitKind::Rigid,
            display,
            residuals: Vec::new(),
            device: None,
            tip_offset_mm: None,
        }
    }

    /// RMS of the residuals, mm; 0 without any (not fitted).
    pub fn rms_mm(&self) -> f64 {
        let n = self.residuals.len().max(1) as f64;
        // A fold from +0, not `sum`: an empty float sum is -0.0 in Rust, and a calibration
        // without targets printed "RMS -0.00 mm".
        (self
            .residuals
            .iter()
            .map(|r| r.residual_mm * r.residual_mm)
            .fold(0.0, |a, b| a + b)
            / n)
            .sqrt()
    }

    /// The largest residual, mm.
    pub fn max_mm(&self) -> f64 {
        self.residuals.iter().map(|r| r.residual_mm).fold(0.0, f64::max)
    }

    /// A display-frame point (u, v, h in mm) with its pixel coordinates.
    pub fn point(&self, display_mm: DVec3) -> DisplayPoint {
        let d = &self.display;
        DisplayPoint {
            u_mm: display_mm.x,
            v_mm: display_mm.y,
            h_mm: display_mm.z,
            u_px: display_mm.x * d.width_px as f64 / d.width_mm,
            v_px: display_mm.y * d.height_px as f64 / d.height_mm,
        }
    }

    /// A tracker-frame point in the display frame.
    pub fn to_display(&self, tracker_mm: DVec3) -> DisplayPoint {
        self.point(self.transform.apply(tracker_mm))
    }

    /// The tracked glasses' emitter in the display frame, from the tracker frame or, with
    /// `display_frame`, from a position the device mapped with this calibration's pose: the
    /// pen's emitter-to-tip vector, which the pose carries for the pen, taken out.
    pub fn head_to_display(&self, position_mm: DVec3, display_frame: bool) -> DisplayPoint {
        let mapped = if display_frame {
            position_mm
        } else {
            self.transform.apply(position_mm)
        };
        self.point(mapped - self.tip_offset_mm.unwrap_or(DVec3::ZERO))
    }
}

/// The largest distance of a point from the line through the two points farthest apart.
fn off_line(points: &[DVec3]) -> f64 {
    let mut far = (0, 0, -1.0);
    for (i, a) in points.iter().enumerate() {
        for (j, b) in points.iter().enumerate().skip(i + 1) {
            let d = a.distance_squared(*b);
            if d > far.2 {
                far = (i, j, d);
            }
        }
    }
    let (a, b) = (points[far.0], points[far.1]);
    let dir = (b - a).normalize_or_zero();
    points.iter().map(|p| (*p - a).cross(dir).length()).fold(0.0, f64::max)
}

/// Eigen-decomposition of a symmetric 4×4 matrix by cyclic Jacobi rotations: eigenvalues and
/// eigenvectors (columns of `v`).
fn jacobi4(mut a: [[f64; 4]; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
    let mut v = [[0.0; 4]; 4];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..50 {
        let off: f64 = (0..4)
            .flat_map(|i| (0..4).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off < 1e-24 {
            break;
        }
        for p in 0..3 {
            for q in p + 1..4 {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A ← Jᵀ A J: columns p and q, then rows p and q.
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (row_p, row_q) = (a[p], a[q]);
                for (k, (apk, aqk)) in row_p.into_iter().zip(row_q).enumerate() {
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2], a[3][3]], v)
}

/// Fits the transform mapping `touched` (tracker frame) onto `targets` (display surface).
pub fn fit(
    targets: &[DVec2],
    touched: &[DVec3],
    kind: FitKind,
    display: DisplaySize,
) -> Result<Calibration, CalibrationError> {
    display.check()?;
    if targets.len() != touched.len() || targets.len() < MIN_TARGETS {
        return Err(CalibrationError::TooFewPoints(targets.len().min(touched.len())));
    }
    for (index, (t, p)) in targets.iter().zip(touched).enumerate() {
        if !(t.is_finite() && p.is_finite()) {
            return Err(CalibrationError::NotFinite { index });
        }
    }
    let b: Vec<DVec3> = targets.iter().map(|t| t.extend(0.0)).collect();
    let a = touched;
    // A target set must span a plane; 5 % of its size off the line is plenty for a fit.
    for (which, pts) in [("target", &b[..]), ("touched", a)] {
        let span = pts
            .iter()
            .flat_map(|p| pts.iter().map(move |q| p.distance(*q)))
            .fold(0.0, f64::max);
        let spread = off_line(pts);
        if spread < 0.05 * span || spread < 1.0 {
            return Err(CalibrationError::Collinear {
                which,
                spread_mm: spread,
            });
        }
    }
    let n = a.len() as f64;
    let ca = a.iter().sum::<DVec3>() / n;
    let cb = b.iter().sum::<DVec3>() / n;
    // S = Σ a'·b'ᵀ, rows from the touched points, columns from the targets.
    let mut s = DMat3::ZERO;
    for (p, q) in a.iter().zip(&b) {
        let (p, q) = (*p - ca, *q - cb);
        s += DMat3::from_cols(p * q.x, p * q.y, p * q.z);
    }
    let e = |r: usize, c: usize| s.col(c)[r];
    let (sxx, sxy, sxz) = (e(0, 0), e(0, 1), e(0, 2));
    let (syx, syy, syz) = (e(1, 0), e(1, 1), e(1, 2));
    let (szx, szy, szz) = (e(2, 0), e(2, 1), e(2, 2));
    let nmat = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let (values, vectors) = jacobi4(nmat);
    let mut order = [0, 1, 2, 3];
    order.sort_by(|&i, &j| values[j].total_cmp(&values[i]));
    let (best, second) = (values[order[0]], values[order[1]]);
    // The largest eigenvalue must stand clear of the next (a NaN fails this too).
    if (best - second).partial_cmp(&(1e-9 * best.abs().max(1.0))) != Some(std::cmp::Ordering::Greater) {
        return Err(CalibrationError::Degenerate);
    }
    let col = order[0];
    let rotation = DQuat::from_xyzw(vectors[1][col], vectors[2][col], vectors[3][col], vectors[0][col]).normalize();
    let scale = match kind {
        FitKind::Rigid => 1.0,
        FitKind::Similarity => {
            let (mut num, mut den) = (0.0, 0.0);
            for (p, q) in a.iter().zip(&b) {
                num += (*q - cb).dot(rotation * (*p - ca));
                den += (*p - ca).length_squared();
            }
            num / den
        }
    };
    let translation_mm = cb - rotation * ca * scale;
    let transform = Transform {
        rotation,
        translation_mm,
        scale,
    };
    let residuals = targets
        .iter()
        .zip(a)
        .map(|(t, p)| TargetResidual {
            target_mm: *t,
            touched_mm: *p,
            residual_mm: transform.apply(*p).distance(t.extend(0.0)),
        })
        .collect();
    Ok(Calibration {
        transform,
        kind,
        display,
        residuals,
        device: None,
        tip_offset_mm: None,
    })
}

/// A number for a message: as written for everyday sizes, in exponent form otherwise (`1e-300`
/// rather than 300 zeros).
pub(crate) fn compact(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-3..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
