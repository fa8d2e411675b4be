//! The tracking gate: a fix must be where a hand could have moved the pen since the last one.
//!
//! The solver judges each cycle on its own; a bad range can still fit a wrong point when few
//! receivers are redundant (four receivers leave one degree of freedom). A pen held in a hand
//! moves at most a few metres per second, so a fix far from the previous one is held back
//! rather than reported. The first fix after a gap has nothing to be checked against: it is held
//! until the next fix confirms it, one cycle later. A held fix that the next one confirms starts
//! a new track, so a wrong track cannot persist.

use crate::math::Vec3;
use crate::solve::NoFix;

/// The fastest the pen is taken to move between two fixes, mm per µs (1.5 m/s). A faster move
/// costs a cycle: the first fix after it is held back and the next one confirms it.
pub const MAX_SPEED_MM_PER_US: f32 = 0.0015;
/// Added to the distance the pen can move, for noise, mm.
pub const GATE_MARGIN_MM: f32 = 10.0;
/// A fix older than this no longer gates nor hints, µs.
pub const TRACK_TIMEOUT_US: u64 = 30_000;

/// The last accepted fix and the candidate that may start a new track.
#[derive(Debug, Clone, Copy)]
pub struct Track {
    last: Option<(u64, Vec3)>,
    candidate: Option<(u64, Vec3)>,
    /// How long a fix gates and hints, µs.
    timeout_us: u64,
    /// The fastest the emitter moves, mm/µs.
    max_speed: f32,
}

impl Default for Track {
    fn default() -> Self {
        Track::new()
    }
}

impl Track {
    /// No history, with the pen's limits.
    pub const fn new() -> Track {
        Track::with_limits(TRACK_TIMEOUT_US, MAX_SPEED_MM_PER_US)
    }

    /// No history, for an emitter fixed at most every `timeout_us` µs and moving at most
    /// `max_speed` mm/µs (the head's slots are further apart than the pen's cycles).
    pub const fn with_limits(timeout_us: u64, max_speed: f32) -> Track {
        Track {
            last: None,
            candidate: None,
            timeout_us,
            max_speed,
        }
    }

    fn reachable(&self, from: Option<(u64, Vec3)>, t_us: u64, p: Vec3) -> bool {
        match from {
            Some((t0, q)) if t_us >= t0 && t_us - t0 <= self.timeout_us => {
                (p - q).length() <= self.max_speed * (t_us - t0) as f32 + GATE_MARGIN_MM
            }
            _ => false,
        }
    }

    /// The last accepted fix if it is recent: where the emitter probably is at `t_us`.
    pub fn hint(&self, t_us: u64) -> Option<Vec3> {
        match self.last {
            Some((t0, p)) if t_us >= t0 && t_us - t0 <= self.timeout_us => Some(p),
            _ => None,
        }
    }

    /// Accepts the fix `p` at `t_us` or says why it is held back.
    pub fn gate(&mut self, t_us: u64, p: Vec3) -> Result<(), NoFix> {
        if self.reachable(self.last, t_us, p) || self.reachable(self.candidate, t_us, p) {
            self.last = Some((t_us, p));
            self.candidate = None;
            return Ok(());
        }
        let tracking = self.hint(t_us).is_some();
        self.candidate = Some((t_us, p));
        Err(if tracking { NoFix::Jump } else { NoFix::Acquiring })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acquire_track_reject_jump_and_recover() {
        let mut t = Track::new();
        let a = Vec3::new(100.0, 100.0, 50.0);
        assert_eq!(t.gate(0, a), Err(NoFix::Acquiring));
        assert_eq!(t.gate(6_500, a + Vec3::new(2.0, 0.0, 0.0)), Ok(()));
        // 6.5 ms later: up to 1.5 mm/ms · 6.5 ms + 10 mm = 19.75 mm away is reachable.
        assert_eq!(t.gate(13_000, a + Vec3::new(19.0, 0.0, 0.0)), Ok(()));
        // A wild fix is held back, and the track continues past it.
        assert_eq!(t.gate(19_500, a + Vec3::new(300.0, 0.0, 0.0)), Err(NoFix::Jump));
        assert_eq!(t.gate(26_000, a + Vec3::new(20.0, 0.0, 0.0)), Ok(()));
        // Two agreeing fixes far from the track start a new one (the old track was wrong).
        assert_eq!(t.gate(32_500, Vec3::new(500.0, 0.0, 0.0)), Err(NoFix::Jump));
        assert_eq!(t.gate(39_000, Vec3::new(501.0, 0.0, 0.0)), Ok(()));
        assert_eq!(t.hint(39_000), Some(Vec3::new(501.0, 0.0, 0.0)));
        // After a gap, acquisition again.
        assert_eq!(t.hint(39_000 + TRACK_TIMEOUT_US + 1), None);
        assert_eq!(t.gate(100_000, a), Err(NoFix::Acquiring));
    }
}
