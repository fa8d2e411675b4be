//! The structuring element's level at a course sample (the seed gives no formula; this is ours).
//!
//! - The **maximum level** grows with the river's cross-section (the seed's volume, width ×
//!   depth): `n_max = clamp(1 + ⌊volume_gain · √(width · depth) / cell_size⌋, 1, 6)`.
//! - The **drive** of a sample grows with the bend's sharpness (curvature × width), the flow
//!   (width × depth × water, against `flow_reference`) and softer ground (÷ hardness):
//!   `drive = curvature_gain · κ · width · (width · depth · water / flow_reference) / hardness`.
//! - The **level** is `1 + round((n_max − 1) · (1 − e^(−drive)))`: 1 (no change) on a straight
//!   course, `n_max` on the sharpest bends.
//!
//! Each factor enters through a non-decreasing function, so the level never falls when the
//! curvature, the water, the width or the depth grows, or when the hardness falls.

use super::morph::MAX_LEVEL;
use crate::document::River;

/// The constants of the level formula (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constants {
    /// Levels per cell of `√(width · depth)`.
    pub volume_gain: f64,
    /// How fast the drive saturates.
    pub curvature_gain: f64,
    /// The flow (m² × water) that counts as 1: `modeler/examples/rivers/omega.json`'s river,
    /// 3 m × 1.5 m × 60. Ours, not the seed's: its example is width 6, depth 5, water 60 in
    /// voxels of an unstated size, which do not carry over to metres.
    pub flow_reference: f64,
}

impl Default for Constants {
    fn default() -> Constants {
        Constants {
            volume_gain: 1.0,
            curvature_gain: 4.0,
            flow_reference: 270.0,
        }
    }
}

/// `n_max` of a river on cells of `cell_size` metres.
pub fn max_level(river: &River, cell_size: f64, c: &Constants) -> u8 {
    let n = 1.0 + (c.volume_gain * (river.width * river.depth).max(0.0).sqrt() / cell_size).floor();
    n.clamp(1.0, f64::from(MAX_LEVEL)) as u8
}

/// The level at a sample of curvature `kappa` (1/m).
pub fn level(kappa: f64, river: &River, cell_size: f64, c: &Constants) -> u8 {
    Levels::new(river, cell_size, c).at(kappa)
}

/// [`level`] of one river at many samples: its terms that do not depend on the curvature worked
/// out once.
#[derive(Debug, Clone, Copy)]
pub struct Levels {
    n_max: u8,
    flow: f64,
    curvature_gain: f64,
    width: f64,
    hardness: f64,
}

impl Levels {
    /// The levels of `river` on cells of `cell_size` metres.
    pub fn new(river: &River, cell_size: f64, c: &Constants) -> Levels {
        Levels {
            n_max: max_level(river, cell_size, c),
            flow: river.width * river.depth * river.water / c.flow_reference,
            curvature_gain: c.curvature_gain,
            width: river.width,
            hardness: river.hardness,
        }
    }

    /// The level at a sample of curvature `kappa` (1/m).
    pub fn at(&self, kappa: f64) -> u8 {
        let drive = self.curvature_gain * kappa * self.width * self.flow / self.hardness;
        let grow = 1.0 - (-drive.max(0.0)).exp();
        let n = 1.0 + (f64::from(self.n_max - 1) * grow).round();
        n.clamp(1.0, f64::from(self.n_max)) as u8
    }
}
