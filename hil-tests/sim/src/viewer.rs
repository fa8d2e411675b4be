//! The viewer wearing the shutter glasses: a seated person's head (slow sway, breathing, leaning
//! in to look closely and back), the glasses' emitter on it, and the head's own shadow over the
//! receivers it faces away from.
//!
//! Positions are in the display frame (u right, v up from the bottom-left corner, h towards the
//! viewer) and turned into the tracker frame through the rig, as the hand's are.

use glam::DVec3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::rig::Rig;

/// Where the glasses' emitter sits: on the bridge, this far in front of the head's centre (the
/// point the head turns about), mm.
pub const EMITTER_FORWARD_MM: f64 = 95.0;
/// The head shadows receivers further than this from the emitter's facing direction, degrees:
/// the emitter faces where the eyes look and radiates over the half-space in front of it (a
/// 40 kHz transducer's beam is wide), and behind the glasses' frame the skull blocks the direct
/// path (a wave 8.6 mm long does not bend round a 150 mm head).
pub const SHADOW_DEG: f64 = 90.0;

/// A seated viewer's head.
#[derive(Debug, Clone)]
pub struct Viewer {
    /// The head's rest position (centre), display frame, mm.
    pub rest_mm: DVec3,
    /// What the eyes look at, display frame, mm (the head turns to face it).
    pub look_at_mm: DVec3,
    /// Sway: per axis, (amplitude mm, Hz, phase) × 2 sinusoids.
    sway: [[(f64, f64, f64); 2]; 3],
    /// Leaning in: every `lean_period_s` the head moves `lean_mm` towards the display over
    /// `lean_ramp_s`, stays `lean_hold_s`, and comes back.
    pub lean_mm: f64,
    /// See [`lean_mm`](Self::lean_mm).
    pub lean_period_s: f64,
    /// See [`lean_mm`](Self::lean_mm).
    pub lean_ramp_s: f64,
    /// See [`lean_mm`](Self::lean_mm).
    pub lean_hold_s: f64,
    /// Where the leaning starts in its period, s.
    lean_phase_s: f64,
}

/// A smooth step 0 → 1 over [0, 1] (zero velocity at both ends: a head eases in and out).
fn smooth(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl Viewer {
    /// A viewer seated 650 mm in front of the middle of a `width` × `height` mm display, eyes a
    /// little above its centre, looking at it; `rng` draws the sway.
    pub fn seated(width_mm: f64, height_mm: f64, rng: &mut ChaCha8Rng) -> Viewer {
        let mut wave = |amplitude: f64, lo: f64, hi: f64| {
            (
                amplitude,
                rng.random_range(lo..hi),
                rng.random_range(0.0..std::f64::consts::TAU),
            )
        };
        // Postural sway of a seated person: tens of mm side to side and fore-aft at 0.1–0.4 Hz,
        // less up and down (breathing).
        let sway = [
            [wave(18.0, 0.1, 0.25), wave(6.0, 0.25, 0.5)],
            [wave(5.0, 0.2, 0.35), wave(2.0, 0.35, 0.6)],
            [wave(15.0, 0.1, 0.2), wave(5.0, 0.2, 0.4)],
        ];
        let lean_phase_s = rng.random_range(0.0..2.0);
        Viewer {
            rest_mm: DVec3::new(width_mm / 2.0, height_mm / 2.0 + 60.0, 650.0),
            look_at_mm: DVec3::new(width_mm / 2.0, height_mm / 2.0, 0.0),
            sway,
            lean_mm: 220.0,
            lean_period_s: 8.0,
            lean_ramp_s: 1.2,
            lean_hold_s: 2.5,
            lean_phase_s,
        }
    }

    /// How far the head has leant in at `t_s`, 0…1.
    fn lean(&self, t_s: f64) -> f64 {
        let t = (t_s + self.lean_phase_s).rem_euclid(self.lean_period_s);
        let (ramp, hold) = (self.lean_ramp_s, self.lean_hold_s);
        if t < ramp {
            smooth(t / ramp)
        } else if t < ramp + hold {
            1.0
        } else {
            1.0 - smooth((t - ramp - hold) / ramp)
        }
    }

    /// The head's centre at `t_s`, display frame, mm.
    pub fn centre(&self, t_s: f64) -> DVec3 {
        let mut p = self.rest_mm;
        for (axis, waves) in self.sway.iter().enumerate() {
            for &(a, hz, phase) in waves {
                p[axis] += a * (std::f64::consts::TAU * hz * t_s + phase).sin();
            }
        }
        // Leaning in: towards the point looked at, most of it along the normal.
        let towards = (self.look_at_mm - p).normalize_or_zero();
        p + towards * self.lean_mm * self.lean(t_s)
    }

    /// The way the glasses face at `t_s` (unit, display frame): at the point looked at.
    pub fn facing(&self, t_s: f64) -> DVec3 {
        (self.look_at_mm - self.centre(t_s)).normalize_or_zero()
    }

    /// The glasses' emitter at `t_s`, display frame, mm.
    pub fn emitter_display(&self, t_s: f64) -> DVec3 {
        self.centre(t_s) + self.facing(t_s) * EMITTER_FORWARD_MM
    }

    /// The glasses' emitter at `t_s`, tracker frame, mm.
    pub fn emitter(&self, rig: &Rig, t_s: f64) -> DVec3 {
        rig.display_to_tracker(self.emitter_display(t_s))
    }

    /// The receivers the head shadows at `t_s` (bit i: receiver i): those further than
    /// [`SHADOW_DEG`] from the way the glasses face.
    pub fn shadowed(&self, rig: &Rig, t_s: f64) -> u8 {
        let emitter = self.emitter(rig, t_s);
        let facing = rig.display_to_tracker(self.emitter_display(t_s) + self.facing(t_s)) - emitter;
        let cos_limit = SHADOW_DEG.to_radians().cos();
        let mut mask = 0u8;
        for (i, r) in rig.receivers_mm.iter().enumerate().take(8) {
            let to = (*r - emitter).normalize_or_zero();
            if to.dot(facing.normalize_or_zero()) < cos_limit {
                mask |= 1 << i;
            }
        }
        mask
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn a_seated_head_moves_slowly_and_leans_in() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let v = Viewer::seated(600.0, 340.0, &mut rng);
        let mut nearest = f64::MAX;
        let mut fastest = 0.0f64;
        let dt = 0.001;
        for k in 0..20_000 {
            let t = k as f64 * dt;
            let p = v.centre(t);
            nearest = nearest.min(p.z);
            fastest = fastest.max((v.centre(t + dt) - p).length() / dt);
        }
        // Leaning brings the head well closer than its rest, and a seated head stays slow.
        assert!(nearest < 650.0 - 150.0, "{nearest}");
        assert!(fastest < 600.0, "{fastest} mm/s");
    }
}
