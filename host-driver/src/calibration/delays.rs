//! Each receiver's transducer delay, measured from a pen held at known points
//! (`penctl delays`, docs/hardware/bring-up.md).
//!
//! A receiver's capture comes some tens of µs after the sound reaches it: the transmitter needs
//! a few periods to ring up, and the amplifier, envelope detector and comparator add their own
//! lag. The firmware subtracts a configured delay per receiver (`transducer_delay_us`); this
//! module measures it. The pen's emitter is held still at surveyed points `p_k` (tracker frame)
//! with SW1 pressed while the device streams its time-of-flight reports. Receiver `i` at
//! `r_i` then hears, per cycle,
//!
//! ```text
//! t_ik = |p_k − r_i| / c + d_i + noise        (t: the report's ToF plus the delay it subtracted)
//! ```
//!
//! Per point and receiver the median over the held cycles stands for `t_ik` (a median, so that
//! a late echo or two do not move it). The least-squares `d_i` minimises
//! `Σ_k (t_ik − |p_k − r_i|/c − d_i)²`, which is the mean of `t_ik − |p_k − r_i|/c` over the
//! points the receiver heard; what is left, the residual, shows a point or a receiver position
//! surveyed wrongly (1 µs is 0.34 mm). The speed of sound `c` is the one the device solved
//! each cycle with (its configured temperature): set `temperature_c` first.

use std::time::{Duration, Instant};

use glam::{DMat3, DVec3};
use pen_protocol::{Config, MAX_RECEIVERS, Message, NO_ARRIVAL, ReportId, StatusCode, limits};
use thiserror::Error;

use crate::device::{Device, DeviceEvent};
use crate::transport::TransportError;

pub mod cli;

/// Cycles skipped after SW1 closes, µs of device time (the pen settling in its seat).
pub const SETTLE_US: u64 = 100_000;
/// How long a hold is measured, µs of device time.
pub const MEASURE_US: u64 = 500_000;
/// Cycles a hold needs; a receiver that heard fewer at a point is left out there.
pub const MIN_CYCLES: usize = 30;
/// Points the fit needs: with fewer there is nothing to check a delay against.
pub const MIN_POINTS: usize = 3;
/// Points closer together than this do not count as different points, mm.
pub const MIN_SPACING_MM: f64 = 50.0;

/// What the procedure tells the user as it goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Prompt {
    /// Hold the emitter at point `index` (of `count`) and press SW1.
    Hold {
        /// From 0.
        index: usize,
        /// Points in all.
        count: usize,
        /// Where, tracker frame, mm.
        point_mm: DVec3,
    },
    /// Release SW1 first.
    Lift,
    /// The hold was too short: hold again.
    Again {
        /// Cycles taken.
        cycles: usize,
    },
    /// Point taken.
    Taken {
        /// Cycles measured.
        cycles: usize,
    },
}

/// Why the measurement stopped or cannot be fitted.
#[derive(Debug, Error)]
pub enum DelayError {
    /// No device, it went away, or it refused.
    #[error("{0}")]
    Device(String),
    /// A request failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// The pen was not held at a point in time.
    #[error("no hold within {0:?}")]
    Timeout(Duration),
    /// The points cannot give delays.
    #[error("{0}")]
    Points(String),
    /// A receiver heard nothing usable at any point.
    #[error(
        "receiver {0} heard the pen at none of the points: check its cable, amplifier and comparator (docs/hardware/bring-up.md)"
    )]
    Deaf(usize),
}

/// One held point: the median time per receiver, delay included.
#[derive(Debug, Clone, PartialEq)]
pub struct Held {
    /// The surveyed point, tracker frame, mm.
    pub point_mm: DVec3,
    /// Per configured receiver: the median arrival after the burst, µs (the report's time of
    /// flight plus the delay the device subtracted), or `None` if it heard too few cycles.
    pub arrival_us: Vec<Option<f64>>,
    /// The speed of sound the device solved with (median), m/s.
    pub speed_m_s: f64,
    /// Cycles measured.
    pub cycles: usize,
}

/// The fitted delays.
#[derive(Debug, Clone, PartialEq)]
pub struct DelayFit {
    /// Per receiver, µs.
    pub delays_us: Vec<f64>,
    /// Per point, per receiver: measured minus modelled arrival, µs (`None`: not heard).
    pub residuals_us: Vec<Vec<Option<f64>>>,
    /// Per point: the geometry's dilution of precision there (position error ≈ DOP × range
    /// error), `√trace((JᵀJ)⁻¹)` over the receivers that heard it.
    pub dop: Vec<f64>,
}

impl DelayFit {
    /// The RMS residual of receiver `i` over the points it heard, µs.
    pub fn rms_us(&self, i: usize) -> f64 {
        let r: Vec<f64> = self.residuals_us.iter().filter_map(|p| p[i]).collect();
        (r.iter().map(|x| x * x).sum::<f64>() / r.len().max(1) as f64).sqrt()
    }

    /// The largest residual, µs.
    pub fn max_abs_us(&self) -> f64 {
        self.residuals_us
            .iter()
            .flatten()
            .flatten()
            .fold(0.0, |m: f64, r| m.max(r.abs()))
    }
}

/// Checks the points before the user holds the pen at any: enough of them, finite, inside the
/// device's coordinate limits and apart.
pub fn check_points(points_mm: &[DVec3]) -> Result<(), DelayError> {
    if points_mm.len() < MIN_POINTS {
        return Err(DelayError::Points(format!(
            "{} point(s) given, {MIN_POINTS} needed at least (spread over the workspace, at several heights)",
            points_mm.len()
        )));
    }
    let max = limits::MAX_COORDINATE_MM as f64;
    for (k, p) in points_mm.iter().enumerate() {
        if !p.is_finite() || p.abs().max_element() > max {
            return Err(DelayError::Points(format!(
                "point {} ({}, {}, {}) is not a finite coordinate within ±{max} mm",
                k + 1,
                p.x,
                p.y,
                p.z
            )));
        }
        for (j, q) in points_mm[..k].iter().enumerate() {
            if p.distance(*q) < MIN_SPACING_MM {
                return Err(DelayError::Points(format!(
                    "points {} and {} are {:.0} mm apart: give points at least {MIN_SPACING_MM} mm apart",
                    j + 1,
                    k + 1,
                    p.distance(*q)
                )));
            }
        }
    }
    Ok(())
}

/// The device's configuration, read before measuring: its receivers and the delays it subtracts.
pub fn read_config(device: &mut Device) -> Result<Config, DelayError> {
    let t = device
        .transport()
        .ok_or_else(|| DelayError::Device("device detached".into()))?;
    match t.get_feature(ReportId::Config)? {
        Message::Config(c) => Ok(c),
        other => Err(DelayError::Device(format!(
            "the device answered with a {} report",
            other.id()
        ))),
    }
}

/// Sends a configuration; fails unless the device takes it.
pub fn write_config(device: &mut Device, config: &Config) -> Result<(), DelayError> {
    config
        .validate()
        .map_err(|e| DelayError::Device(format!("not sent: {e}")))?;
    let t = device
        .transport()
        .ok_or_else(|| DelayError::Device("device detached".into()))?;
    let status = t.set_feature(&Message::Config(*config))?;
    if status.code != StatusCode::Ok {
        return Err(DelayError::Device(format!("the device refused: {status}")));
    }
    Ok(())
}

/// The median of `v` (not empty).
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Leads the user through the points, with the device streaming time-of-flight reports
/// (`original`, its configuration, is put back afterwards, whatever happens). `tell` hears each
/// prompt; a point not held within `patience` ends it.
pub fn collect(
    device: &mut Device,
    original: &Config,
    points_mm: &[DVec3],
    patience: Duration,
    mut tell: impl FnMut(&Prompt),
) -> Result<Vec<Held>, DelayError> {
    write_config(
        device,
        &Config {
            stream_tof: true,
            ..*original
        },
    )?;
    let result = collect_streaming(device, original, points_mm, patience, &mut tell);
    // Streaming off again (or as it was), even when a hold failed.
    let restored = write_config(device, original);
    let held = result?;
    restored?;
    Ok(held)
}

fn collect_streaming(
    device: &mut Device,
    config: &Config,
    points_mm: &[DVec3],
    patience: Duration,
    tell: &mut impl FnMut(&Prompt),
) -> Result<Vec<Held>, DelayError> {
    let n = (config.receiver_count as usize).min(MAX_RECEIVERS);
    // The delays the device subtracts, as it rounds them (whole ns).
    let subtracted_us: Vec<f64> = config.transducer_delay_us[..n]
        .iter()
        .map(|d| (d * 1000.0 + 0.5).floor() as f64 / 1000.0)
        .collect();
    let mut held = Vec::new();
    for (index, &point_mm) in points_mm.iter().enumerate() {
        tell(&Prompt::Hold {
            index,
            count: points_mm.len(),
            point_mm,
        });
        let deadline = Instant::now() + patience;
        let mut released = false;
        let mut told_lift = false;
        let mut pressed_at: Option<u64> = None;
        let mut measuring = false;
        let mut arrivals: Vec<Vec<f64>> = vec![Vec::new(); n];
        let mut speeds = Vec::new();
        let mut cycles = 0usize;
        loop {
            if Instant::now() > deadline {
                return Err(DelayError::Timeout(patience));
            }
            let Some(event) = device.next(Duration::from_millis(50)) else {
                continue;
            };
            match event {
                DeviceEvent::Lost(why) => return Err(DelayError::Device(format!("device lost: {why}"))),
                DeviceEvent::Sample(s, _) => {
                    if !s.sw[0] {
                        if pressed_at.take().is_some() {
                            if cycles >= MIN_CYCLES {
                                break;
                            }
                            tell(&Prompt::Again { cycles });
                            arrivals.iter_mut().for_each(Vec::clear);
                            speeds.clear();
                            cycles = 0;
                        }
                        released = true;
                        measuring = false;
                        continue;
                    }
                    if !released {
                        if !told_lift {
                            tell(&Prompt::Lift);
                            told_lift = true;
                        }
                        continue;
                    }
                    let start = *pressed_at.get_or_insert(s.device_us);
                    let held_us = s.device_us.saturating_sub(start);
                    measuring = held_us >= SETTLE_US;
                    if held_us >= SETTLE_US + MEASURE_US && cycles >= MIN_CYCLES {
                        break;
                    }
                }
                DeviceEvent::Tof(t) if measuring => {
                    cycles += 1;
                    speeds.push(t.speed_of_sound_m_s as f64);
                    for (i, a) in arrivals.iter_mut().enumerate() {
                        if t.tof_ns[i] != NO_ARRIVAL {
                            a.push(t.tof_ns[i] as f64 * 1e-3 + subtracted_us[i]);
                        }
                    }
                }
                _ => {}
            }
        }
        tell(&Prompt::Taken { cycles });
        held.push(Held {
            point_mm,
            arrival_us: arrivals
                .iter_mut()
                .map(|a| (a.len() >= MIN_CYCLES).then(|| median(a)))
                .collect(),
            speed_m_s: median(&mut speeds),
            cycles,
        });
        // The next point is shown once SW1 is open.
        while Instant::now() < deadline {
            match device.next(Duration::from_millis(50)) {
                Some(DeviceEvent::Sample(s, _)) if !s.sw[0] => break,
                Some(DeviceEvent::Lost(why)) => return Err(DelayError::Device(format!("device lost: {why}"))),
                _ => {}
            }
        }
    }
    Ok(held)
}

/// The geometry's dilution of precision at `p` for the receivers in `used`.
fn dop(p: DVec3, used: &[DVec3]) -> f64 {
    let mut jtj = DMat3::ZERO;
    for r in used {
        let u = (p - *r).normalize_or_zero();
        jtj += DMat3::from_cols(u * u.x, u * u.y, u * u.z);
    }
    if jtj.determinant().abs() < 1e-12 {
        return f64::INFINITY;
    }
    let inv = jtj.inverse();
    (inv.x_axis.x + inv.y_axis.y + inv.z_axis.z).max(0.0).sqrt()
}

/// The least-squares delays for receivers at `receivers_mm` (the device's surveyed positions)
/// from the held points.
pub fn fit(receivers_mm: &[DVec3], held: &[Held]) -> Result<DelayFit, DelayError> {
    let n = receivers_mm.len();
    // Per point and receiver: arrival minus flight time, the delay plus noise.
    let excess: Vec<Vec<Option<f64>>> = held
        .iter()
        .map(|h| {
            (0..n)
                .map(|i| {
                    let a = h.arrival_us.get(i).copied().flatten()?;
                    // mm / (m/s) = ms; × 1000 → µs.
                    Some(a - h.point_mm.distance(receivers_mm[i]) / h.speed_m_s * 1e3)
                })
                .collect()
        })
        .collect();
    let mut delays_us = Vec::with_capacity(n);
    for i in 0..n {
        let e: Vec<f64> = excess.iter().filter_map(|p| p[i]).collect();
        if e.is_empty() {
            return Err(DelayError::Deaf(i));
        }
        delays_us.push(e.iter().sum::<f64>() / e.len() as f64);
    }
    let residuals_us = excess
        .iter()
        .map(|p| p.iter().zip(&delays_us).map(|(e, d)| e.map(|e| e - d)).collect())
        .collect();
    let dop = held
        .iter()
        .map(|h| {
            let used: Vec<DVec3> = (0..n)
                .filter(|&i| h.arrival_us.get(i).copied().flatten().is_some())
                .map(|i| receivers_mm[i])
                .collect();
            dop(h.point_mm, &used)
        })
        .collect();
    Ok(DelayFit {
        delays_us,
        residuals_us,
        dop,
    })
}

/// The configured receivers' positions, mm.
pub fn receivers(config: &Config) -> Vec<DVec3> {
    let n = (config.receiver_count as usize).min(MAX_RECEIVERS);
    config.receivers_mm[..n]
        .iter()
        .map(|r| DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64))
        .collect()
}

/// `config` with the fitted delays.
pub fn with_delays(config: &Config, fit: &DelayFit) -> Config {
    let mut c = *config;
    for (slot, d) in c.transducer_delay_us.iter_mut().zip(&fit.delays_us) {
        *slot = *d as f32;
    }
    c
}

/// The simulated pen held at `points_mm` by the procedure's scenario (the reference rig,
/// starting with delays of 0 µs): what `penctl delays --source sim` measures.
#[cfg(feature = "sim")]
pub fn sim_source(points_mm: &[DVec3], speed: f64) -> crate::source::Source {
    crate::source::Source::Sim(crate::transport::sim::SimOptions {
        scenario: pen_sim::scenarios::transducer_delays(points_mm),
        seed: 1,
        speed,
        plug: Default::default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn receivers() -> Vec<DVec3> {
        vec![
            DVec3::new(-40.0, -40.0, 300.0),
            DVec3::new(640.0, -40.0, 0.0),
            DVec3::new(-40.0, 380.0, 0.0),
            DVec3::new(640.0, 380.0, 300.0),
        ]
    }

    fn held(points: &[DVec3], delays: &[f64], c: f64) -> Vec<Held> {
        points
            .iter()
            .map(|p| Held {
                point_mm: *p,
                arrival_us: receivers()
                    .iter()
                    .zip(delays)
                    .map(|(r, d)| Some(p.distance(*r) / c * 1e3 + d))
                    .collect(),
                speed_m_s: c,
                cycles: 70,
            })
            .collect()
    }

    #[test]
    fn exact_arrivals_give_the_delays_and_no_residual() {
        let points = [
            DVec3::new(100.0, 60.0, 40.0),
            DVec3::new(500.0, 280.0, 150.0),
            DVec3::new(300.0, 170.0, 250.0),
        ];
        let delays = [38.0, 41.5, 36.2, 40.1];
        let f = fit(&receivers(), &held(&points, &delays, 343.2)).expect("fit");
        for (got, want) in f.delays_us.iter().zip(delays) {
            assert!((got - want).abs() < 1e-9, "{got} vs {want}");
        }
        assert!(f.max_abs_us() < 1e-9);
        assert!(f.dop.iter().all(|d| (1.0..5.0).contains(d)), "{:?}", f.dop);
    }

    #[test]
    fn a_wrong_point_shows_in_the_residuals() {
        let points = [
            DVec3::new(100.0, 60.0, 40.0),
            DVec3::new(500.0, 280.0, 150.0),
            DVec3::new(300.0, 170.0, 250.0),
        ];
        let mut h = held(&points, &[40.0; 4], 343.2);
        // The second point was really 5 mm further along x than surveyed.
        h[1].point_mm.x -= 5.0;
        let f = fit(&receivers(), &h).expect("fit");
        assert!(f.max_abs_us() > 3.0, "{}", f.max_abs_us());
    }

    #[test]
    fn a_deaf_receiver_and_bad_points_are_refused() {
        let points = [
            DVec3::new(100.0, 60.0, 40.0),
            DVec3::new(500.0, 280.0, 150.0),
            DVec3::new(300.0, 170.0, 250.0),
        ];
        let mut h = held(&points, &[40.0; 4], 343.2);
        for p in &mut h {
            p.arrival_us[2] = None;
        }
        assert!(matches!(fit(&receivers(), &h), Err(DelayError::Deaf(2))));
        assert!(check_points(&points).is_ok());
        assert!(check_points(&points[..2]).is_err());
        let close = [points[0], points[1], points[0] + DVec3::new(10.0, 0.0, 0.0)];
        let e = check_points(&close).expect_err("too close").to_string();
        assert!(e.contains("points 1 and 3"), "{e}");
        let nan = [points[0], points[1], DVec3::new(f64::NAN, 0.0, 0.0)];
        assert!(check_points(&nan).is_err());
    }
}
