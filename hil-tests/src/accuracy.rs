//! How well the simulated pen is tracked: position errors of the raw fixes against the truth
//! and against the Cramér–Rao bound of the geometry and the timing jitter, the fix rate, and
//! switch transitions reported against those the hand made.

use glam::{DMat3, DVec3};
use pen_core::ranging::{FAST_TIMER_HZ, SLOW_TIMER_HZ};
use pen_protocol::{PenReport, Report, ReportId};
use serde::Serialize;

use pen_sim::script::SwitchEvent;
use pen_sim::sim::{CycleRecord, Scenario};

/// A reported switch transition matches an intended one this soon after it, s.
pub const SWITCH_MATCH_WINDOW_S: f64 = 0.020;

/// The figures of one scenario run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// The scenario.
    pub name: String,
    /// Simulated time, s.
    pub seconds: f64,
    /// Measurement cycles.
    pub cycles: usize,
    /// Cycles with a fix.
    pub fixes: usize,
    /// RMS distance of the raw fixes (before smoothing) from the true emitter position, mm.
    pub rmse_mm: f64,
    /// The Cramér–Rao bound for the same fixes: √mean(σ_r² · trace((JᵀJ)⁻¹)) at the true
    /// position over the receivers each fix used, σ_r the range noise of the timing jitter and
    /// the timers' quantisation, mm.
    pub crlb_mm: f64,
    /// Median error, mm.
    pub p50_mm: f64,
    /// 99th-percentile error, mm.
    pub p99_mm: f64,
    /// Largest error, mm.
    pub max_mm: f64,
    /// Fixes per second of simulated time.
    pub fix_rate_hz: f64,
    /// Switch transitions reported that the hand did not make (bounce getting through).
    pub false_switch_events: usize,
    /// Switch transitions the hand made that were not reported within the match window.
    pub missed_switch_events: usize,
}

/// The Cramér–Rao bound's variance (mm²) for a fix at `truth` from `receivers` with range
/// variances `var` (mm²): trace of (Jᵀ W J)⁻¹ with W = diag(1/var).
pub fn crlb_variance(truth: DVec3, receivers: &[DVec3], var: &[f64]) -> Option<f64> {
    let mut m = DMat3::ZERO;
    for (r, v) in receivers.iter().zip(var) {
        let u = (truth - *r).normalize_or_zero();
        m += DMat3::from_cols(u * u.x, u * u.y, u * u.z) * (1.0 / v);
    }
    let det = m.determinant();
    (det.abs() > 1e-12).then(|| {
        let inv = m.inverse();
        inv.x_axis.x + inv.y_axis.y + inv.z_axis.z
    })
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p / 100.0) * (sorted.len() - 1) as f64).round() as usize;
    sorted[rank.min(sorted.len() - 1)]
}

/// Switch transitions in the reports: (time s, switch, pressed), from consecutive pen reports.
pub fn reported_transitions(records: &[CycleRecord]) -> Vec<SwitchEvent> {
    let mut out = Vec::new();
    let mut last = [false; 3];
    for sent in records.iter().flat_map(|r| &r.sent) {
        if sent.bytes.first() != Some(&(ReportId::Pen as u8)) {
            continue;
        }
        let Ok(report) = PenReport::decode(&sent.bytes) else {
            continue;
        };
        let now = [report.sw1, report.sw2, report.sw3];
        for (switch, (&was, &is)) in last.iter().zip(&now).enumerate() {
            if was != is {
                out.push(SwitchEvent {
                    t_s: sent.t_us as f64 * 1e-6,
                    switch,
                    pressed: is,
                });
            }
        }
        last = now;
    }
    out
}

/// Matches reported transitions to intended ones: (false, missed).
pub fn switch_errors(intended: &[SwitchEvent], reported: &[SwitchEvent], until_s: f64) -> (usize, usize) {
    let mut used = vec![false; reported.len()];
    let mut missed = 0;
    for e in intended.iter().filter(|e| e.t_s + SWITCH_MATCH_WINDOW_S <= until_s) {
        let found = reported.iter().enumerate().find(|(i, r)| {
            !used[*i]
                && r.switch == e.switch
                && r.pressed == e.pressed
                && r.t_s >= e.t_s
                && r.t_s <= e.t_s + SWITCH_MATCH_WINDOW_S
        });
        match found {
            Some((i, _)) => used[i] = true,
            None => missed += 1,
        }
    }
    let false_events = used.iter().filter(|u| !**u).count();
    (false_events, missed)
}

/// The figures of a run of `scenario` that produced `records`.
pub fn evaluate(scenario: &Scenario, records: &[CycleRecord]) -> Metrics {
    let rig = &scenario.rig;
    let sigma_t = scenario.acoustics.sigma_t_us;
    let (mut errors, mut crlb_sum) = (Vec::new(), 0.0);
    // The pen's cycles only: with the head tracked, the head's slots are not the pen's fixes.
    let pen_cycles: Vec<&CycleRecord> = records.iter().filter(|r| r.emitter == pen_core::Emitter::Pen).collect();
    for r in &pen_cycles {
        let Ok(fix) = r.result.fix else { continue };
        let p = DVec3::new(fix.position.x as f64, fix.position.y as f64, fix.position.z as f64);
        errors.push((p - r.truth_mm).length());
        let c_mm_per_us = scenario.acoustics.air.speed_m_s(r.t0_us as f64 * 1e-6) * 1e-3;
        let (mut used, mut var) = (Vec::new(), Vec::new());
        for (i, receiver) in rig.receivers_mm.iter().enumerate() {
            if fix.used_mask & (1 << i) != 0 {
                // Jitter plus the uniform quantisation of the capture timer (tick² / 12).
                let tick_us = 1e6 / if i < 4 { FAST_TIMER_HZ } else { SLOW_TIMER_HZ } as f64;
                used.push(*receiver);
                var.push((sigma_t * sigma_t + tick_us * tick_us / 12.0) * c_mm_per_us * c_mm_per_us);
            }
        }
        crlb_sum += crlb_variance(r.truth_mm, &used, &var).unwrap_or(f64::NAN);
    }
    let fixes = errors.len();
    let rmse = (errors.iter().map(|e| e * e).sum::<f64>() / fixes.max(1) as f64).sqrt();
    let crlb = (crlb_sum / fixes.max(1) as f64).sqrt();
    errors.sort_by(f64::total_cmp);
    let seconds = records
        .last()
        .map_or(0.0, |r| r.sent.last().map_or(r.t0_us, |s| s.t_us) as f64 / 1e6);
    let (false_switch_events, missed_switch_events) =
        switch_errors(scenario.timeline.events(), &reported_transitions(records), seconds);
    Metrics {
        name: scenario.name.clone(),
        seconds,
        cycles: pen_cycles.len(),
        fixes,
        rmse_mm: rmse,
        crlb_mm: crlb,
        p50_mm: percentile(&errors, 50.0),
        p99_mm: percentile(&errors, 99.0),
        max_mm: errors.last().copied().unwrap_or(f64::NAN),
        fix_rate_hz: fixes as f64 / seconds.max(1e-9),
        false_switch_events,
        missed_switch_events,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crlb_of_a_symmetric_geometry() {
        // Six receivers on the axes at equal distance: JᵀJ = 2·I, so the bound is 3σ²/2.
        let receivers = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z].map(|v| v * 100.0);
        let v = crlb_variance(DVec3::ZERO, &receivers, &[4.0; 6]).expect("regular");
        assert!((v - 6.0).abs() < 1e-9, "{v}");
        assert_eq!(crlb_variance(DVec3::ZERO, &receivers[..2], &[1.0; 2]), None);
    }

    #[test]
    fn switch_matching() {
        let e = |t_s, switch, pressed| SwitchEvent { t_s, switch, pressed };
        let intended = [e(1.0, 0, true), e(2.0, 0, false), e(3.0, 1, true)];
        let reported = [
            e(1.0005, 0, true),
            e(1.002, 0, false),
            e(2.001, 0, false),
            e(3.5, 1, true),
        ];
        // The release at 1.002 s is a bounce that got through; SW2 came too late.
        assert_eq!(switch_errors(&intended, &reported, 10.0), (2, 1));
    }
}
