//! Wind sway (seed 004, §6): generation g leans `θ_g = A_g·sin(2π f_g t) + θ0_g` at its base,
//! about the horizontal axis across the wind, and carries its branches with it, so the sways
//! compose down the hierarchy (a twig moves with its branch, the branch with the trunk).
//! Deterministic in `t`.

use glam::DVec3;

use crate::document::Wind;

/// The largest amplitude or rest lean of a generation, degrees.
pub const MAX_LEAN: f64 = 90.0;

/// The highest sway frequency, hertz.
pub const MAX_FREQUENCY: f64 = 20.0;

/// One moment of a tree's sway: the axis and each generation's angle.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// The unit axis of every lean, in the exports' frame (X = x, Y up, Z = y).
    pub axis: DVec3,
    /// `θ_g` in radians, per generation from the trunk; the last holds for deeper ones.
    pub angles: Vec<f64>,
}

impl Pose {
    /// The lean of generation `g`, radians.
    pub fn angle(&self, g: usize) -> f64 {
        self.angles.get(g).or(self.angles.last()).copied().unwrap_or(0.0)
    }

    /// Whether nothing leans (the rest pose of a still tree).
    pub fn is_still(&self) -> bool {
        self.angles.iter().all(|&a| a == 0.0)
    }
}

/// The axis across a wind blowing towards `direction` degrees (from +x towards +y): a positive
/// lean tips +Y towards the wind's direction.
pub fn axis(direction: f64) -> DVec3 {
    let (s, c) = direction.to_radians().sin_cos();
    // The document's (x, y) is the exports' (X, Z).
    DVec3::Y.cross(DVec3::new(c, 0.0, s)).normalize_or(DVec3::Z)
}

/// `θ_g = A_g·sin(2π f_g t) + θ0_g` for each generation of `wind`, radians.
pub fn angles(wind: &Wind, t: f64) -> Vec<f64> {
    wind.generations
        .iter()
        .map(|g| (g.amplitude * (std::f64::consts::TAU * g.frequency * t).sin() + g.rest).to_radians())
        .collect()
}

/// The pose of `wind` at time `t` seconds.
pub fn pose(wind: &Wind, t: f64) -> Pose {
    Pose {
        axis: axis(wind.direction),
        angles: angles(wind, t),
    }
}
