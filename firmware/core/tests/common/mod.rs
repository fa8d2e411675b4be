//! Geometry and noise for the core's tests.
#![allow(dead_code)]

use pen_core::{Cycle, Engine, Vec3};
use pen_protocol::MAX_RECEIVERS;

/// A small deterministic generator (SplitMix64) with Gaussian samples (Box–Muller), so the tests
/// need no dependency and every run sees the same numbers.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// The reference build's receivers (`default_config`).
pub fn reference_receivers() -> Vec<Vec3> {
    vec![
        Vec3::new(-40.0, -40.0, 300.0),
        Vec3::new(640.0, -40.0, 0.0),
        Vec3::new(-40.0, 380.0, 0.0),
        Vec3::new(640.0, 380.0, 300.0),
    ]
}

/// Exact ranges (f64 arithmetic, rounded once) from `p` to each receiver.
pub fn exact_ranges(receivers: &[Vec3], p: Vec3) -> [Option<f32>; MAX_RECEIVERS] {
    let mut r = [None; MAX_RECEIVERS];
    for (slot, q) in r.iter_mut().zip(receivers) {
        let d = [(p.x - q.x) as f64, (p.y - q.y) as f64, (p.z - q.z) as f64];
        *slot = Some((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() as f32);
    }
    r
}

pub fn distance(a: Vec3, b: Vec3) -> f32 {
    (a - b).length()
}

/// The captures an emitter at `p` produces for the engine's configuration: each receiver's
/// flight at the engine's speed of sound plus its transducer delay, to the nearest ns.
pub fn cycle_at(e: &Engine, t0_us: u64, p: Vec3) -> Cycle {
    let s = e.settings();
    let mut arrival_ns = [None; MAX_RECEIVERS];
    for ((slot, r), delay) in arrival_ns.iter_mut().zip(&s.receivers[..s.count]).zip(s.delays_ns) {
        let tof_ns = (p - *r).length() as f64 / (s.speed_m_s as f64 * 1e-6);
        *slot = Some((tof_ns + delay as f64).round() as u32);
    }
    Cycle { t0_us, arrival_ns }
}
