//! IFS tree species: the maps `ω_i = Trans(0, y_i, 0)·Rot_y(θy_i)·Rot_z(−θz_i)·Scale(s_i)` and
//! the seed's Table 3.1 (its two species, Sample 3.1 and Sample 3.2) with three other presets.
//!
//! A tree's own unit: the trunk grows from the origin up +Y to the highest branching point
//! (`max y_i`); every map places a scaled copy of the whole tree on the trunk, so the tree is
//! the trunk and every composition of maps applied to it. `λ` is the mean scale, which the
//! seed's data-volume law `N ≈ (M/(M−1))·Q^(ln M / ln λ)` uses.

use glam::{DAffine3, DVec3};

use crate::document::IfsMap;

/// The most maps a species may have: more make a tree of millions of branches before its
/// branches reach 2 % of its height.
pub const MAX_MAPS: usize = 8;

/// A named preset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// The seed's Table 3.1, Sample 3.1 (M = 5, λ = 0.46): a broadleaf with a leaning leader.
    Table31,
    /// The seed's Table 3.1, Sample 3.2 (M = 6, λ = 0.45): a denser crown of six limbs, every one
    /// turned off the trunk's axis.
    Sample32,
    /// A columnar conifer (Italian cypress): a strong vertical leader, steep short side shoots.
    Cypress,
    /// A broad deciduous crown (oak): four wide-spreading limbs from a short trunk, no leader.
    Oak,
    /// A spruce or fir: a long leader with a whorl of five near-horizontal branches.
    Fir,
}

impl Preset {
    /// Every preset, in the order the documentation lists them.
    pub const ALL: [Preset; 5] = [
        Preset::Table31,
        Preset::Sample32,
        Preset::Cypress,
        Preset::Oak,
        Preset::Fir,
    ];

    /// The name documents and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Table31 => "table-3.1",
            Preset::Sample32 => "sample-3.2",
            Preset::Cypress => "cypress",
            Preset::Oak => "oak",
            Preset::Fir => "fir",
        }
    }

    /// The preset called `name`.
    pub fn named(name: &str) -> Option<Preset> {
        Preset::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The names of every preset, for messages (`table-3.1, sample-3.2, cypress, oak, fir`).
    pub fn names() -> String {
        Preset::ALL.map(Preset::name).join(", ")
    }

    /// The preset's maps.
    pub fn maps(self) -> Vec<IfsMap> {
        // (y, s, θz, θy) per map.
        let table: &[(f64, f64, f64, f64)] = match self {
            Preset::Table31 => &[
                (0.40, 0.60, 10.0, 0.0),
                (0.24, 0.55, 40.0, 60.0),
                (0.16, 0.45, -40.0, 120.0),
                (0.08, 0.40, 50.0, 180.0),
                (0.08, 0.30, -60.0, 50.0),
            ],
            // Table 3.1's second block; its trunk (OS = 0.52) is its largest y, as for Sample 3.1.
            Preset::Sample32 => &[
                (0.52, 0.52, -32.6, 40.2),
                (0.44, 0.52, 33.9, 40.5),
                (0.44, 0.38, 7.3, 45.0),
                (0.40, 0.47, 56.4, 45.2),
                (0.52, 0.28, 62.8, 180.0),
                (0.36, 0.55, -59.3, 134.8),
            ],
            Preset::Cypress => &[
                (0.40, 0.72, 0.0, 0.0),
                (0.30, 0.33, 22.0, 0.0),
                (0.25, 0.33, 22.0, 90.0),
                (0.20, 0.30, 24.0, 180.0),
                (0.15, 0.30, 24.0, 270.0),
            ],
            // Scales kept so its dimension is near Table 3.1's (2.2): larger ones make a bushier
            // crown of many more branches.
            Preset::Oak => &[
                (0.30, 0.58, 30.0, 0.0),
                (0.30, 0.55, 40.0, 100.0),
                (0.26, 0.52, 45.0, 200.0),
                (0.22, 0.48, 50.0, 290.0),
            ],
            Preset::Fir => &[
                (0.45, 0.74, 0.0, 0.0),
                (0.30, 0.34, 75.0, 0.0),
                (0.30, 0.34, 75.0, 72.0),
                (0.30, 0.34, 75.0, 144.0),
                (0.30, 0.34, 75.0, 216.0),
                (0.30, 0.34, 75.0, 288.0),
            ],
        };
        table
            .iter()
            .map(|&(y, s, theta_z, theta_y)| IfsMap { y, s, theta_z, theta_y })
            .collect()
    }
}

/// A species: its maps (each a contraction, `0 < s < 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct Species {
    /// The maps `ω_1 … ω_M`.
    pub maps: Vec<IfsMap>,
}

impl Species {
    /// The species of a preset.
    pub fn preset(p: Preset) -> Species {
        Species { maps: p.maps() }
    }

    /// `M`, the number of maps.
    pub fn m(&self) -> usize {
        self.maps.len()
    }

    /// `λ`, the mean scale of the maps (Table 3.1: 0.46).
    pub fn lambda(&self) -> f64 {
        if self.maps.is_empty() {
            return 0.0;
        }
        self.maps.iter().map(|m| m.s).sum::<f64>() / self.maps.len() as f64
    }

    /// The trunk's length in the tree's unit: up to the highest branching point.
    pub fn trunk(&self) -> f64 {
        self.maps.iter().map(|m| m.y).fold(0.0, f64::max)
    }

    /// The law's exponent `ln M / ln λ` (Table 3.1: −2.07).
    pub fn law_exponent(&self) -> f64 {
        (self.m() as f64).ln() / self.lambda().ln()
    }

    /// The similarity dimension `D`: `Σ s_i^D = 1` (Moran's equation), by bisection. The node
    /// count of unequal scales grows as `Q^−D` (Table 3.1: 2.16), where the law's `λ` is a mean.
    pub fn dimension(&self) -> f64 {
        let sum = |d: f64| self.maps.iter().map(|m| m.s.abs().powf(d)).sum::<f64>();
        let (mut lo, mut hi) = (0.0, 64.0);
        if self.maps.is_empty() || sum(hi) > 1.0 {
            return f64::NAN;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if sum(mid) > 1.0 { lo = mid } else { hi = mid }
        }
        0.5 * (lo + hi)
    }

    /// A bound on every point of the tree's distance from its base, in the tree's unit:
    /// `R = max(trunk, max_i y_i / (1 − s_i))`, since `|ω_i(p)| ≤ y_i + s_i·|p| ≤ R` when
    /// `|p| ≤ R`.
    pub fn reach(&self) -> f64 {
        self.maps
            .iter()
            .map(|m| m.y.abs() / (1.0 - m.s.abs()))
            .fold(self.trunk(), f64::max)
    }
}

impl IfsMap {
    /// The map as an affine transform: `Trans(0, y, 0)·Rot_y(θy)·Rot_z(−θz)·Scale(s)`.
    pub fn affine(&self) -> DAffine3 {
        DAffine3::from_translation(DVec3::new(0.0, self.y, 0.0))
            * DAffine3::from_rotation_y(self.theta_y.to_radians())
            * DAffine3::from_rotation_z(-self.theta_z.to_radians())
            * DAffine3::from_scale(DVec3::splat(self.s))
    }
}
