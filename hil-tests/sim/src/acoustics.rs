//! Sound from the pen to the receivers: flight times from the true distances and the air
//! temperature, the receivers' delays, timing jitter, the capture timers' quantisation, late
//! echoes and dropouts.

use glam::DVec3;
use pen_core::LISTEN_US;
use pen_core::ranging::speed_of_sound_m_s;
use pen_core::ranging::{FAST_TIMER_HZ, SLOW_TIMER_HZ, ns_per_tick, ticks_to_ns};
use pen_protocol::MAX_RECEIVERS;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Exp, Normal};

use crate::rig::Rig;

/// The air: a base temperature, a slow drift and an optional step (a door opening).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Air {
    /// Temperature at t = 0, °C.
    pub base_c: f64,
    /// Amplitude of a slow sinusoidal drift, °C.
    pub drift_c: f64,
    /// Its period, s.
    pub drift_period_s: f64,
    /// A step of `.1` °C at time `.0` s.
    pub step: Option<(f64, f64)>,
}

impl Air {
    /// Room air: 21 °C drifting ±0.5 °C over 20 minutes.
    pub fn room() -> Air {
        Air {
            base_c: 21.0,
            drift_c: 0.5,
            drift_period_s: 1200.0,
            step: None,
        }
    }

    /// The temperature at `t_s`.
    pub fn temperature_c(&self, t_s: f64) -> f64 {
        let drift = self.drift_c * (std::f64::consts::TAU * t_s / self.drift_period_s).sin();
        let step = match self.step {
            Some((at, delta)) if t_s >= at => delta,
            _ => 0.0,
        };
        self.base_c + drift + step
    }

    /// The speed of sound at `t_s`, m/s (the same law the firmware uses).
    pub fn speed_m_s(&self, t_s: f64) -> f64 {
        speed_of_sound_m_s(self.temperature_c(t_s) as f32) as f64
    }
}

/// What makes the measurement imperfect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Acoustics {
    /// Standard deviation of each arrival's timing jitter, µs.
    pub sigma_t_us: f64,
    /// Probability per receiver and cycle that the first arrival is a late echo (the direct
    /// path blocked, the sound arriving round an obstacle or off a surface).
    pub echo_rate: f64,
    /// An echo's extra path: at least this, mm…
    pub echo_min_mm: f64,
    /// …plus an exponentially distributed part with this mean, mm.
    pub echo_mean_extra_mm: f64,
    /// Probability per receiver and cycle that nothing arrives (the hand occluding it).
    pub dropout_rate: f64,
    /// Receivers that hear nothing at all (bit i: receiver i), a broken cable.
    pub dead_mask: u8,
    /// A burst of echoes: from `.0` s to `.1` s the echo rate is `.2`.
    pub echo_burst: Option<(f64, f64, f64)>,
    /// Probability per receiver and burst that the room sends back a reflection of the burst
    /// strong enough to trigger the receiver after the direct sound (reverberation). It matters
    /// only when the next burst comes before it has died away: the head's short slots.
    pub reverb_rate: f64,
    /// The reflection's path beyond the direct one: uniform up to this, mm (515 mm is the 1.5 ms
    /// of die-away the pen-only cycle waits for).
    pub reverb_tail_mm: f64,
    /// The air.
    pub air: Air,
}

impl Acoustics {
    /// Timing jitter of 2 µs, room air, no echoes or dropouts.
    pub fn clean() -> Acoustics {
        Acoustics {
            sigma_t_us: 2.0,
            echo_rate: 0.0,
            echo_min_mm: 30.0,
            echo_mean_extra_mm: 120.0,
            dropout_rate: 0.0,
            dead_mask: 0,
            echo_burst: None,
            reverb_rate: 0.0,
            reverb_tail_mm: 515.0,
            air: Air::room(),
        }
    }

    /// As [`clean`](Self::clean) with late echoes and dropouts at the given rates.
    pub fn with_echoes(echo_rate: f64, dropout_rate: f64) -> Acoustics {
        Acoustics {
            echo_rate,
            dropout_rate,
            ..Acoustics::clean()
        }
    }
}

/// One cycle as the receivers heard it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Heard {
    /// What the capture timers report: ns after the burst, quantised as the board quantises.
    pub arrival_ns: [Option<u32>; MAX_RECEIVERS],
    /// The flight time each receiver measured (arrival minus its true delay), µs.
    pub tof_us: [Option<f64>; MAX_RECEIVERS],
    /// Which arrivals were late echoes.
    pub echo: [bool; MAX_RECEIVERS],
}

impl Acoustics {
    /// The arrivals of a burst from `emitter` at `t_s`, within the pen-only cycle's listening
    /// window.
    pub fn hear(&self, rig: &Rig, emitter: DVec3, t_s: f64, rng: &mut ChaCha8Rng) -> Heard {
        self.hear_slot(rig, emitter, t_s, LISTEN_US, 0, [None; MAX_RECEIVERS], rng)
    }

    /// The reflections of the previous burst, from `previous` fired `since_us` before this one,
    /// that reach each receiver after this burst: µs after it, or `None`. Draws nothing while
    /// [`reverb_rate`](Self::reverb_rate) is 0, so runs without reverberation are unchanged.
    pub fn tails(
        &self,
        rig: &Rig,
        previous: DVec3,
        t_s: f64,
        since_us: f64,
        rng: &mut ChaCha8Rng,
    ) -> [Option<f64>; MAX_RECEIVERS] {
        let mut out = [None; MAX_RECEIVERS];
        if self.reverb_rate <= 0.0 {
            return out;
        }
        let c_mm_per_us = self.air.speed_m_s(t_s) * 1e-3;
        for (i, receiver) in rig.receivers_mm.iter().enumerate().take(MAX_RECEIVERS) {
            let reflected = rng.random_bool(self.reverb_rate.clamp(0.0, 1.0));
            let extra = rng.random_range(0.0..self.reverb_tail_mm.max(1e-9));
            if !reflected {
                continue;
            }
            let path = (previous - *receiver).length() + extra;
            let after_us = path / c_mm_per_us + rig.delays_us[i] - since_us;
            if after_us > 0.0 {
                out[i] = Some(after_us);
            }
        }
        out
    }

    /// The arrivals of a burst from `emitter` at `t_s` that come within `listen_us` of it,
    /// with the receivers in `blocked` (bit i: receiver i) shadowed (the viewer's own head) and
    /// the previous burst's `tails` ([`tails`](Self::tails)) triggering any receiver they reach
    /// before the direct sound.
    #[allow(clippy::too_many_arguments)]
    pub fn hear_slot(
        &self,
        rig: &Rig,
        emitter: DVec3,
        t_s: f64,
        listen_us: u64,
        blocked: u8,
        tails: [Option<f64>; MAX_RECEIVERS],
        rng: &mut ChaCha8Rng,
    ) -> Heard {
        let mut heard = Heard {
            arrival_ns: [None; MAX_RECEIVERS],
            tof_us: [None; MAX_RECEIVERS],
            echo: [false; 8],
        };
        let c_mm_per_us = self.air.speed_m_s(t_s) * 1e-3;
        let jitter = Normal::new(0.0, self.sigma_t_us.max(0.0)).unwrap_or_else(|_| unreachable!("σ ≥ 0"));
        let extra = Exp::new(1.0 / self.echo_mean_extra_mm.max(1e-9)).unwrap_or_else(|_| unreachable!("mean > 0"));
        let echo_rate = match self.echo_burst {
            Some((from, to, rate)) if (from..to).contains(&t_s) => rate,
            _ => self.echo_rate,
        };
        for (i, receiver) in rig.receivers_mm.iter().enumerate().take(MAX_RECEIVERS) {
            // Draw both chances every time, so that one receiver's fate does not shift the
            // random sequence of the others.
            let dropped = rng.random_bool(self.dropout_rate.clamp(0.0, 1.0));
            let echo = rng.random_bool(echo_rate.clamp(0.0, 1.0));
            let dead = self.dead_mask & (1 << i) != 0;
            let tail = tails[i].filter(|_| !dead);
            let direct = if dropped || dead || blocked & (1 << i) != 0 {
                None
            } else {
                let mut path = (emitter - *receiver).length();
                if echo {
                    path += self.echo_min_mm + extra.sample(rng);
                    heard.echo[i] = true;
                }
                Some(path / c_mm_per_us + jitter.sample(rng) + rig.delays_us[i])
            };
            // The capture takes whichever triggers first: this burst, or the last one's tail.
            let arrival_us = match (direct, tail) {
                (Some(d), Some(t)) if t < d => {
                    heard.echo[i] = true;
                    t
                }
                (Some(d), _) => d,
                (None, Some(t)) => {
                    heard.echo[i] = true;
                    t
                }
                (None, None) => continue,
            };
            let tof_us = arrival_us - rig.delays_us[i];
            if arrival_us <= 0.0 || arrival_us >= listen_us as f64 {
                continue;
            }
            // The capture timer counts whole ticks; the board converts them to ns.
            let clock_hz = if i < 4 { FAST_TIMER_HZ } else { SLOW_TIMER_HZ };
            let ticks = (arrival_us * 1e-6 * clock_hz as f64).floor() as u32;
            heard.arrival_ns[i] = Some(ticks_to_ns(ticks, ns_per_tick(clock_hz)));
            heard.tof_us[i] = Some(tof_us);
        }
        heard
    }
}
