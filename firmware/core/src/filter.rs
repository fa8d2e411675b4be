//! Position smoothing: the 1€ filter (Casiez, Roussel, Vogel, CHI 2012).
//!
//! A first-order low-pass whose cutoff rises with speed: `fc = min_cutoff + beta·|v|`, where v is
//! the low-passed velocity. At rest the cutoff is low and jitter is smoothed away; in motion it
//! rises and the lag shrinks. This is the vector form: one cutoff from the speed, applied to all
//! three axes, so the filter does not depend on how the tracker frame is oriented.
//!
//! Only +, −, ×, ÷ are used, so the host and the board compute bit-identical results.

use crate::math::Vec3;

/// After a gap this long without fixes the filter restarts from the next fix instead of gliding
/// from a stale position, µs.
pub const RESTART_GAP_US: u64 = 100_000;

/// 1€ filter parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneEuroParams {
    /// Cutoff at rest, Hz.
    pub min_cutoff_hz: f32,
    /// Cutoff increase per mm/s of speed, Hz·s/mm.
    pub beta: f32,
    /// Cutoff of the velocity estimate, Hz.
    pub d_cutoff_hz: f32,
}

/// The smoothing factor of a first-order low-pass at `cutoff_hz` for a step of `dt_s`.
fn alpha(cutoff_hz: f32, dt_s: f32) -> f32 {
    let tau = 1.0 / (2.0 * core::f32::consts::PI * cutoff_hz);
    1.0 / (1.0 + tau / dt_s)
}

#[derive(Debug, Clone, Copy)]
struct State {
    t_us: u64,
    raw: Vec3,
    smoothed: Vec3,
    velocity: Vec3,
}

/// The filter, or a pass-through when `params` is `None`.
#[derive(Debug, Clone, Copy)]
pub struct Smoother {
    params: Option<OneEuroParams>,
    state: Option<State>,
}

impl Smoother {
    /// A filter with no history.
    pub fn new(params: Option<OneEuroParams>) -> Smoother {
        Smoother { params, state: None }
    }

    /// Forgets the history: the next fix passes through unchanged.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Filters the fix `x` measured at `t_us`.
    pub fn filter(&mut self, t_us: u64, x: Vec3) -> Vec3 {
        let Some(p) = self.params else { return x };
        let fresh = State {
            t_us,
            raw: x,
            smoothed: x,
            velocity: Vec3::ZERO,
        };
        let prev = match self.state {
            Some(s) if t_us > s.t_us && t_us - s.t_us < RESTART_GAP_US => s,
            Some(s) if t_us == s.t_us => return s.smoothed,
            _ => {
                self.state = Some(fresh);
                return x;
            }
        };
        let dt = (t_us - prev.t_us) as f32 * 1e-6;
        let raw_velocity = (x - prev.raw) * (1.0 / dt);
        let a_d = alpha(p.d_cutoff_hz, dt);
        let velocity = prev.velocity + (raw_velocity - prev.velocity) * a_d;
        let cutoff = p.min_cutoff_hz + p.beta * velocity.length();
        let a = alpha(cutoff, dt);
        let smoothed = prev.smoothed + (x - prev.smoothed) * a;
        self.state = Some(State {
            t_us,
            raw: x,
            smoothed,
            velocity,
        });
        smoothed
    }
}
