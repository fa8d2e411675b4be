//! Traces as JSON lines: a header describing the set-up, then one line per measurement cycle
//! (format in docs/simulator.md).

use pen_core::NoFix;
use serde_json::{Value, json};

use pen_sim::sim::{CycleRecord, Simulation};

fn round(v: f64, decimals: i32) -> f64 {
    let f = 10f64.powi(decimals);
    (v * f).round() / f
}

fn xyz(v: [f64; 3]) -> Value {
    json!([round(v[0], 3), round(v[1], 3), round(v[2], 3)])
}

/// The header line: the receivers, the noise, the air, the delays.
pub fn header(sim: &Simulation) -> Value {
    let s = sim.scenario();
    let air = &s.acoustics.air;
    json!({
        "scenario": s.name,
        "receivers_mm": s.rig.receivers_mm.iter().map(|r| xyz(r.to_array())).collect::<Vec<_>>(),
        "sigma_t_us": s.acoustics.sigma_t_us,
        "temperature_c": air.temperature_c(0.0),
        "speed_of_sound_m_s": round(air.speed_m_s(0.0), 4),
        "transducer_delay_us": s.rig.delays_us,
        "echo_rate": s.acoustics.echo_rate,
        "dropout_rate": s.acoustics.dropout_rate,
    })
}

fn no_fix_reason(e: NoFix) -> &'static str {
    match e {
        NoFix::TooFewRanges => "too_few_ranges",
        NoFix::Inconsistent => "inconsistent",
        NoFix::Behind => "behind",
        NoFix::Degenerate => "degenerate",
        NoFix::Ambiguous => "ambiguous",
        NoFix::Jump => "jump",
        NoFix::Acquiring => "acquiring",
        NoFix::PoorGeometry => "poor_geometry",
    }
}

/// One cycle's line, for a rig of `receivers` receivers.
pub fn line(r: &CycleRecord, receivers: usize) -> Value {
    let raw = r
        .result
        .fix
        .ok()
        .map(|f| xyz([f.position.x as f64, f.position.y as f64, f.position.z as f64]));
    let report = r.report;
    let fix = report.filter(|p| p.in_range).map(|p| {
        let mm = p.position.to_mm();
        xyz([mm[0] as f64, mm[1] as f64, mm[2] as f64])
    });
    let quality = report.map(|p| {
        json!({
            "receivers_used": p.quality.receivers_used,
            "residual_mm": p.quality.residual as f64 / 10.0,
            "dop": p.quality.dop as f64 / 10.0,
        })
    });
    let n = receivers.min(r.heard.tof_us.len());
    let tof: Vec<Value> = r.heard.tof_us[..n]
        .iter()
        .map(|t| t.map_or(Value::Null, |t| json!(round(t, 4))))
        .collect();
    json!({
        "t_s": round(r.t0_us as f64 * 1e-6, 6),
        "truth_mm": xyz(r.truth_mm.to_array()),
        "tof_us": tof,
        "raw_fix_mm": raw,
        "fix_mm": fix,
        "quality": quality,
        "sw": report.map(|p| [p.sw1, p.sw2, p.sw3]),
        "sw_true": r.intended_switches,
        "no_fix": r.result.fix.err().map(no_fix_reason),
        "echo": &r.heard.echo[..n],
    })
}
