//! How well the tracked head is followed, and what multiplexing its emitter costs the pen: the
//! head's fix rate, the RMS error of its raw fixes, of its filtered estimate and of the pose it
//! reports predicted ahead (against where the head then really is), beside the pen's figures
//! with and without the head (`pen-sim head`).

use glam::DVec3;
use pen_core::Emitter;
use serde::Serialize;

use pen_sim::sim::{CycleRecord, Scenario, Simulation};
use pen_sim::viewer::Viewer;

/// The head's figures of one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeadMetrics {
    /// Head slots.
    pub slots: usize,
    /// Head slots with a fix.
    pub fixes: usize,
    /// Head fixes per second of simulated time.
    pub fix_rate_hz: f64,
    /// RMS distance of the raw fixes from the true emitter at the burst, mm.
    pub raw_rmse_mm: f64,
    /// RMS distance of the reported (predicted) pose from the true emitter `prediction_ms`
    /// after the burst, mm: what a host drawing then sees.
    pub predicted_rmse_mm: f64,
    /// The same without prediction: the error of holding the raw fix for `prediction_ms`, mm.
    pub held_rmse_mm: f64,
    /// The prediction, ms.
    pub prediction_ms: u8,
    /// Fraction of head slots in which the head shadowed at least one receiver.
    pub shadowed_fraction: f64,
    /// Head reports flagged no-fix.
    pub no_fix_reports: usize,
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// The head's figures from `records` of `scenario` whose viewer was `viewer`.
pub fn evaluate(scenario: &Scenario, viewer: &Viewer, records: &[CycleRecord]) -> HeadMetrics {
    let rig = &scenario.rig;
    let prediction_ms = scenario.head.map_or(0, |h| h.prediction_ms);
    let ahead_s = prediction_ms as f64 * 1e-3;
    let (mut raw, mut predicted, mut held) = (Vec::new(), Vec::new(), Vec::new());
    let (mut slots, mut shadowed, mut no_fix) = (0, 0, 0);
    for r in records.iter().filter(|r| r.emitter == Emitter::Head) {
        slots += 1;
        let t_s = r.t0_us as f64 * 1e-6;
        if viewer.shadowed(rig, t_s) != 0 {
            shadowed += 1;
        }
        let later = viewer.emitter(rig, t_s + ahead_s);
        if let Ok(fix) = r.result.fix {
            let p = DVec3::new(fix.position.x as f64, fix.position.y as f64, fix.position.z as f64);
            raw.push((p - r.truth_mm).length());
            held.push((p - later).length());
        }
        match r.head_report {
            Some(h) if !h.no_fix => {
                let [x, y, z] = h.position.to_mm();
                let mut p = DVec3::new(x as f64, y as f64, z as f64);
                if h.display_frame {
                    p = rig.display_to_tracker(p);
                }
                predicted.push((p - later).length());
            }
            Some(_) => no_fix += 1,
            None => {}
        }
    }
    let seconds = records.last().map_or(0.0, |r| r.t0_us as f64 * 1e-6);
    HeadMetrics {
        slots,
        fixes: raw.len(),
        fix_rate_hz: raw.len() as f64 / seconds.max(1e-9),
        raw_rmse_mm: rms(&raw),
        predicted_rmse_mm: rms(&predicted),
        held_rmse_mm: rms(&held),
        prediction_ms,
        shadowed_fraction: shadowed as f64 / slots.max(1) as f64,
        no_fix_reports: no_fix,
    }
}

/// The pen's and the head's figures of one run of `scenario`, for `seconds` (the scenario's
/// length when `None`; it loops).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Run {
    /// The pen's figures (pen slots only).
    pub pen: crate::accuracy::Metrics,
    /// The head's, when the scenario has a viewer.
    pub head: Option<HeadMetrics>,
}

/// Runs `scenario` with `seed` for `seconds` and evaluates the pen and the head.
pub fn run(scenario: &Scenario, seed: u64, seconds: f64) -> Run {
    let mut sim = Simulation::looping(scenario, seed);
    let records = sim.run_for(seconds);
    let pen = crate::accuracy::evaluate(scenario, &records);
    let head = sim.viewer().map(|v| evaluate(scenario, &v, &records));
    Run { pen, head }
}

/// Reads a schedule written `PEN:HEAD` (`2:1`): both 1…20.
pub fn parse_ratio(s: &str) -> Result<pen_core::Schedule, String> {
    let bad = || format!("a ratio is PEN:HEAD with both 1…20 (like 2:1), not {s:?}");
    let (pen, head) = s.split_once(':').ok_or_else(bad)?;
    let pen: u8 = pen.trim().parse().map_err(|_| bad())?;
    let head: u8 = head.trim().parse().map_err(|_| bad())?;
    if !(1..=20).contains(&pen) || !(1..=20).contains(&head) {
        return Err(bad());
    }
    Ok(pen_core::Schedule { pen, head })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratios_parse_or_say_why_not() {
        assert_eq!(parse_ratio("2:1"), Ok(pen_core::Schedule { pen: 2, head: 1 }));
        assert_eq!(parse_ratio(" 5 : 2"), Ok(pen_core::Schedule { pen: 5, head: 2 }));
        for bad in ["2", "0:1", "2:x", "21:1", ""] {
            let e = parse_ratio(bad).expect_err(bad);
            assert!(e.contains("PEN:HEAD"), "{e}");
        }
    }
}
