//! The hand that holds the pen: the scripted motion plus what a real hand adds — physiological
//! tremor, a tilted pen whose emitter sits off the tip, and switch contacts that bounce.

use glam::DVec3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::rig::Rig;
use crate::script::Timeline;

/// RMS amplitude of physiological tremor at the pen tip, mm (8–12 Hz, a few tenths of a mm).
pub const TREMOR_RMS_MM: f64 = 0.15;
/// How far the pen leans from the display's normal, degrees.
pub const TILT_DEG: f64 = 35.0;
/// A pivot's mean lean and how far it swings about it, degrees (three swings per turn).
const PIVOT_LEAN_DEG: f64 = 30.0;
const PIVOT_SWING_DEG: f64 = 18.0;
/// The fraction of a pivot at each end spent easing from the held lean into the circle.
const PIVOT_EASE: f64 = 0.12;
/// The longest a contact bounces after a press or release, ms: well inside the firmware's
/// default 5 ms debounce time, as real tact switches bounce for 1–3 ms.
pub const MAX_BOUNCE_MS: f64 = 3.0;

/// One sinusoid of tremor on one axis.
#[derive(Debug, Clone, Copy)]
struct Wave {
    amplitude: f64,
    hz: f64,
    phase: f64,
}

/// A hand playing a timeline.
#[derive(Debug, Clone)]
pub struct Hand {
    timeline: Timeline,
    tremor: [[Wave; 3]; 3],
    /// Each switch's raw edges (time s, level), bounces included, in time order.
    edges: [Vec<(f64, bool)>; 3],
    /// Slow wobble of the pen's lean: amplitude (rad) and frequency (Hz).
    wobble: (f64, f64),
    /// The timeline's length, s.
    period: f64,
    /// Whether the timeline repeats.
    looping: bool,
}

impl Hand {
    /// A hand for `timeline`; `rng` draws its tremor and its switches' bounces.
    pub fn new(timeline: Timeline, rng: &mut ChaCha8Rng) -> Hand {
        // Three sinusoids of amplitude a per axis between 8 and 12 Hz: RMS a·√(3/2) per axis,
        // a·3/√2 over the three axes.
        let amplitude = TREMOR_RMS_MM * 2f64.sqrt() / 3.0;
        let mut tremor = [[Wave {
            amplitude: 0.0,
            hz: 0.0,
            phase: 0.0,
        }; 3]; 3];
        for axis in tremor.iter_mut() {
            for w in axis.iter_mut() {
                *w = Wave {
                    amplitude,
                    hz: rng.random_range(8.0..12.0),
                    phase: rng.random_range(0.0..std::f64::consts::TAU),
                };
            }
        }
        let mut edges: [Vec<(f64, bool)>; 3] = Default::default();
        for e in timeline.events() {
            let list = &mut edges[e.switch];
            let mut t = e.t_s;
            list.push((t, e.pressed));
            // Contact bounce: a few brief reversals, all within MAX_BOUNCE_MS.
            let bounces = rng.random_range(0..=4usize);
            let end = e.t_s + MAX_BOUNCE_MS * 1e-3;
            for _ in 0..bounces {
                let open = t + rng.random_range(0.05e-3..0.4e-3);
                let close = open + rng.random_range(0.02e-3..0.3e-3);
                if close >= end {
                    break;
                }
                list.push((open, !e.pressed));
                list.push((close, e.pressed));
                t = close;
            }
        }
        for list in edges.iter_mut() {
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        let period = timeline.duration_s();
        Hand {
            timeline,
            tremor,
            edges,
            wobble: (rng.random_range(0.02..0.06), rng.random_range(0.1..0.3)),
            period,
            looping: false,
        }
    }

    /// The same hand repeating its timeline forever (for a pen that runs until stopped).
    pub fn looping(mut self) -> Hand {
        self.looping = self.period > 0.0;
        self
    }

    /// Script time at simulation time `t_s`.
    fn script_time(&self, t_s: f64) -> f64 {
        if self.looping { t_s.rem_euclid(self.period) } else { t_s }
    }

    /// The scripted timeline.
    pub fn timeline(&self) -> &Timeline {
        &self.timeline
    }

    /// The intended switch states at `t_s`.
    pub fn intended_switches(&self, t_s: f64) -> [bool; 3] {
        self.timeline.switches(self.script_time(t_s))
    }

    /// The tip in the display frame at `t_s`, tremor included. On the surface the tip cannot
    /// tremble into it or off it: only the tangential tremor remains.
    pub fn tip(&self, t_s: f64) -> DVec3 {
        let intended = self.timeline.tip(self.script_time(t_s));
        let mut tremor = [0.0; 3];
        for (axis, waves) in self.tremor.iter().enumerate() {
            tremor[axis] = waves
                .iter()
                .map(|w| w.amplitude * (std::f64::consts::TAU * w.hz * t_s + w.phase).sin())
                .sum();
        }
        let on_surface = intended.z <= 0.0;
        DVec3::new(
            intended.x + tremor[0],
            intended.y + tremor[1],
            if on_surface { 0.0 } else { intended.z + tremor[2] },
        )
    }

    /// The pen's axis from tip to emitter in the display frame: leaning towards the user (−y)
    /// by [`TILT_DEG`], wobbling slowly; in a pivot ([`crate::script::Script::pivot`]) its top
    /// circles once about the tip at a lean between 12° and 48°, eased in and out of the
    /// held lean so the emitter does not jump.
    pub fn axis(&self, t_s: f64) -> DVec3 {
        let lean = TILT_DEG.to_radians() + self.wobble.0 * (std::f64::consts::TAU * self.wobble.1 * t_s).sin();
        let held = DVec3::new(0.0, -lean.sin(), lean.cos());
        let Some(s) = self.timeline.pivot_at(self.script_time(t_s)) else {
            return held;
        };
        let turn = std::f64::consts::TAU;
        let azimuth = -0.25 * turn + turn * s;
        let lean = (PIVOT_LEAN_DEG + PIVOT_SWING_DEG * (3.0 * turn * s).sin()).to_radians();
        let circling = DVec3::new(lean.sin() * azimuth.cos(), lean.sin() * azimuth.sin(), lean.cos());
        let ease = (s.min(1.0 - s) / PIVOT_EASE).clamp(0.0, 1.0);
        let w = ease * ease * (3.0 - 2.0 * ease);
        (held * (1.0 - w) + circling * w).normalize()
    }

    /// The emitter in the tracker frame at `t_s`.
    pub fn emitter(&self, rig: &Rig, t_s: f64) -> DVec3 {
        let display = self.tip(t_s) + self.axis(t_s) * rig.emitter_offset_mm;
        rig.display_to_tracker(display)
    }

    /// The switches' raw levels at `t_s`, bounce and all.
    pub fn raw_switches(&self, t_s: f64) -> [bool; 3] {
        let t_s = self.script_time(t_s);
        let mut out = [false; 3];
        for (level, edges) in out.iter_mut().zip(&self.edges) {
            let i = edges.partition_point(|e| e.0 <= t_s);
            *level = i > 0 && edges[i - 1].1;
        }
        out
    }
}
