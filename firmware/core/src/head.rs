//! The tracked head: a second emitter on the viewer's shutter glasses, fired by the same base
//! station in its own time slots between the pen's bursts, with a filter that predicts.
//!
//! **Schedule.** The receivers cannot tell two emitters apart, so the emitters take turns: a
//! slot is one burst and its listening window. With the head fitted every slot is as long as
//! 1.5 m of flight at the running speed of sound plus the slowest receiver's delay (4.40 ms at
//! 21 °C) and a short guard, instead of the pen-only cycle's fixed 6.5 ms, and the slots follow
//! a pattern of `pen` pen slots to `head` head slots spread evenly. 5:2 is what the simulator
//! chose (`pen-sim head`, docs/firmware.md, *Head tracking*): 1:1 leaves the pen at 113 fixes/s
//! and 3:1 the head at 57; 2:1 gives 150.6 and 75.3 at 21 °C but the pen drops below 150 in
//! colder air (longer slots) or with echoes (149.0); 5:2 gives 161.4 and 64.5, and keeps both
//! targets down to −10 °C (153 and 61).
//!
//! **Filter.** A seated viewer's head moves slowly and smoothly (sway, leaning in), so an
//! alpha-beta (constant-velocity) filter suits it: it smooths the fix noise and estimates the
//! velocity that the prediction extrapolates. The report carries the position predicted
//! `prediction_ms` ahead of the burst, so a host drawing that long after it shows the eyes where
//! they are when the frame is seen (the InterSense IS-900 predicts up to 50 ms).

use crate::math::Vec3;

/// Which emitter a slot fires.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Emitter {
    /// The pen's.
    Pen,
    /// The head's, on the shutter glasses.
    Head,
}

/// The farthest an emitter is heard from a receiver in the workspace, mm.
pub const WORKSPACE_MM: f32 = 1_500.0;
/// Silence after the listening window before the next slot's burst, µs. Short: the next burst
/// is the other emitter's or the same one's, and a late echo of the previous burst that lands in
/// the next window is one bad range among four or more, which the solver and the tracking gate
/// already reject (the simulator's `reverb` models them).
pub const MUX_GUARD_US: u64 = 20;
/// How long a head track lasts without a fix, µs: two missed head slots at 2:1 (40 ms) keep it.
pub const HEAD_TRACK_TIMEOUT_US: u64 = 60_000;
/// The fastest a seated viewer's head is taken to move, mm per µs (1 m/s).
pub const HEAD_MAX_SPEED_MM_PER_US: f32 = 0.001;
/// After a gap this long the head filter restarts from the next fix, µs.
pub const HEAD_RESTART_GAP_US: u64 = 200_000;

/// The slot pattern: `pen` pen slots to `head` head slots, spread evenly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Schedule {
    /// Pen slots per frame.
    pub pen: u8,
    /// Head slots per frame.
    pub head: u8,
}

impl Schedule {
    /// The chosen schedule, 5:2 (P P P H P P H).
    pub const CHOSEN: Schedule = Schedule { pen: 5, head: 2 };

    /// The emitter of slot `n` (counting from 0): head slots where `n · head / (pen + head)`
    /// steps up, so they are spread as evenly as the ratio allows (2:1 is P P H).
    pub fn emitter(&self, n: u32) -> Emitter {
        let total = (self.pen as u64 + self.head as u64).max(1);
        let k = n as u64 % total;
        let head = self.head as u64;
        if (k + 1) * head / total > k * head / total {
            Emitter::Head
        } else {
            Emitter::Pen
        }
    }

    /// Slots per frame.
    pub fn slots(&self) -> u32 {
        self.pen as u32 + self.head as u32
    }
}

/// How long to listen after a multiplexed burst, µs: [`WORKSPACE_MM`] of flight at `speed_m_s`
/// plus the slowest receiver's delay, rounded up.
pub fn mux_listen_us(speed_m_s: f32, max_delay_ns: u32) -> u64 {
    // mm / (m/s) = ms; ×1000 = µs.
    let flight_us = WORKSPACE_MM / speed_m_s * 1000.0;
    let us = flight_us + max_delay_ns as f32 * 1e-3;
    // Round up to the next whole µs; the cast saturates and the speed is validated (300…400 m/s).
    (us as u64) + 1
}

/// The head's settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HeadSettings {
    /// The slot pattern.
    pub schedule: Schedule,
    /// How far ahead of the burst the reported position is predicted, ms (at most
    /// [`pen_protocol::MAX_PREDICTION_MS`]).
    pub prediction_ms: u8,
}

impl Default for HeadSettings {
    fn default() -> Self {
        HeadSettings {
            schedule: Schedule::CHOSEN,
            prediction_ms: 20,
        }
    }
}

/// Alpha-beta gains: how much of a new fix's innovation goes into the position and into the
/// velocity (per slot). Chosen by `pen-sim head` (docs/firmware.md): a head's motion, not the
/// fix noise, dominates the prediction's error, so the gains are fairly high; 0.45–0.5 with
/// β 0.12–0.15 is a flat optimum (0.35/0.05 lags: 1.58 mm against 1.14 at 20 ms).
pub const HEAD_ALPHA: f32 = 0.5;
/// See [`HEAD_ALPHA`].
pub const HEAD_BETA: f32 = 0.15;

/// An alpha-beta (constant-velocity) filter with prediction.
#[derive(Debug, Clone, Copy, Default)]
pub struct HeadFilter {
    state: Option<(u64, Vec3, Vec3)>,
}

impl HeadFilter {
    /// No history.
    pub const fn new() -> HeadFilter {
        HeadFilter { state: None }
    }

    /// Forgets the history.
    pub fn reset(&mut self) {
        self.state = None;
    }

    /// Takes the fix `z` measured at `t_us`; returns the filtered position at `t_us`.
    pub fn update(&mut self, t_us: u64, z: Vec3) -> Vec3 {
        let (t0, x0, v0) = match self.state {
            Some(s) if t_us > s.0 && t_us - s.0 < HEAD_RESTART_GAP_US => s,
            Some(s) if t_us == s.0 => return s.1,
            _ => {
                self.state = Some((t_us, z, Vec3::ZERO));
                return z;
            }
        };
        let dt_s = (t_us - t0) as f32 * 1e-6;
        let predicted = x0 + v0 * dt_s;
        let r = z - predicted;
        let x = predicted + r * HEAD_ALPHA;
        let v = v0 + r * (HEAD_BETA / dt_s);
        self.state = Some((t_us, x, v));
        x
    }

    /// The position predicted `ahead_us` after the last update (constant velocity).
    pub fn predict(&self, ahead_us: u64) -> Option<Vec3> {
        self.state.map(|(_, x, v)| x + v * (ahead_us as f32 * 1e-6))
    }

    /// The estimated velocity, mm/s.
    pub fn velocity(&self) -> Option<Vec3> {
        self.state.map(|(_, _, v)| v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_to_one_is_pen_pen_head() {
        let s = Schedule { pen: 2, head: 1 };
        let got: [Emitter; 6] = core::array::from_fn(|n| s.emitter(n as u32));
        use Emitter::*;
        assert_eq!(got, [Pen, Pen, Head, Pen, Pen, Head]);
        // 5:2 spreads its two head slots apart.
        let s = Schedule::CHOSEN;
        let heads: [bool; 7] = core::array::from_fn(|n| s.emitter(n as u32) == Head);
        assert_eq!(heads.iter().filter(|h| **h).count(), 2);
        assert!(!(0..6).any(|i| heads[i] && heads[i + 1]));
    }

    #[test]
    fn listening_covers_the_workspace() {
        // 1.5 m at 344 m/s is 4360.47 µs, plus 41.5 µs of delay: 4401.97, rounded up.
        assert_eq!(mux_listen_us(344.0, 41_500), 4_402);
    }

    #[test]
    fn a_steady_motion_is_predicted_exactly() {
        // Constant velocity 100 mm/s along x, exact fixes every 13.32 ms: once converged, the
        // prediction 50 ms ahead is where the head then is.
        let mut f = HeadFilter::new();
        let at = |t_us: u64| Vec3::new(100.0 * t_us as f32 * 1e-6, 0.0, 700.0);
        for k in 0..400u64 {
            f.update(k * 13_320, at(k * 13_320));
        }
        let last = 399 * 13_320;
        let p = f.predict(50_000).expect("state");
        assert!((p - at(last + 50_000)).length() < 0.05, "{p:?}");
    }
}
