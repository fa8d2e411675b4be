//! Reports as JSON objects, the form `penctl` prints and programs read (schema in docs/penctl.md).
//! Positions and lengths are in millimetres, times in microseconds.

use pen_protocol::{Config, DeviceInfo, Filter, Message, NO_ARRIVAL, PenReport, Quality, Status, TofReport};
use serde_json::{Value, json};

/// Tenths as a decimal number, exactly (123 → 12.3), without f32 rounding noise.
fn tenths(v: impl Into<f64>) -> f64 {
    v.into() / 10.0
}

fn quality(q: Quality) -> Value {
    json!({
        "receivers_used": q.receivers_used,
        "residual_mm": tenths(q.residual),
        "dop": tenths(q.dop),
    })
}

/// A pen report: `report_id`, switches, position in mm, sequence, timestamp, quality.
pub fn pen_json(r: &PenReport) -> Value {
    json!({
        "report_id": pen_protocol::ReportId::Pen as u8,
        "report": "pen",
        "sw1": r.sw1,
        "sw2": r.sw2,
        "sw3": r.sw3,
        "in_range": r.in_range,
        "display_frame": r.display_frame,
        "x_mm": tenths(r.position.x),
        "y_mm": tenths(r.position.y),
        "z_mm": tenths(r.position.z),
        "seq": r.seq,
        "timestamp_us": r.timestamp_us,
        "quality": quality(r.quality),
    })
}

fn tof_json(r: &TofReport) -> Value {
    let tof: Vec<Value> = r.tof_ns[..r.receiver_count as usize]
        .iter()
        .map(|&t| {
            if t == NO_ARRIVAL {
                Value::Null
            } else {
                json!(t as f64 / 1000.0)
            }
        })
        .collect();
    let used: Vec<bool> = (0..r.receiver_count).map(|i| r.used_mask & (1 << i) != 0).collect();
    json!({
        "seq": r.seq,
        "timestamp_us": r.timestamp_us,
        "tof_us": tof,
        "used": used,
        "speed_of_sound_m_s": r.speed_of_sound_m_s,
    })
}

fn info_json(r: &DeviceInfo) -> Value {
    json!({
        "protocol": r.protocol.to_string(),
        "firmware": r.firmware.to_string(),
        "receiver_count": r.receiver_count,
        "max_receivers": r.max_receivers,
        "fix_rate_hz": r.fix_rate_hz,
        "unique_id": crate::hex::to_hex(&r.unique_id),
    })
}

fn config_json(c: &Config) -> Value {
    let n = c.receiver_count as usize;
    let filter = match c.filter {
        Filter::Off => json!({"kind": "off"}),
        Filter::OneEuro {
            min_cutoff_hz,
            beta,
            d_cutoff_hz,
        } => {
            json!({"kind": "one_euro", "min_cutoff_hz": min_cutoff_hz, "beta": beta, "d_cutoff_hz": d_cutoff_hz})
        }
    };
    let display = c
        .display
        .map(|d| json!({"rotation_wxyz": d.rotation, "translation_mm": d.translation_mm, "scale": d.scale}));
    json!({
        "receiver_count": c.receiver_count,
        "receivers_mm": &c.receivers_mm[..n],
        "transducer_delay_us": &c.transducer_delay_us[..n],
        "temperature_c": c.temperature_c,
        "speed_of_sound_m_s": c.speed_of_sound_m_s,
        "report_rate_hz": c.report_rate_hz,
        "filter": filter,
        "debounce_ms": c.debounce_ms,
        "display": display,
        "report_display_frame": c.report_display_frame,
        "stream_tof": c.stream_tof,
    })
}

fn status_json(s: &Status) -> Value {
    json!({
        "request": s.request,
        "code": format!("{:?}", s.code),
        "field": s.config_field().map(|f| f.to_string()),
        "message": s.to_string(),
    })
}

/// Any report as one JSON object with `report_id` and `report` (its name) first.
pub fn message_json(m: &Message) -> Value {
    let body = match m {
        Message::Pen(r) => return pen_json(r),
        Message::Tof(r) => tof_json(r),
        Message::DeviceInfo(r) => info_json(r),
        Message::Config(r) => config_json(r),
        Message::Status(r) => status_json(r),
        Message::Command(c) => json!({"command": format!("{c:?}")}),
        Message::GetFeature(g) => json!({"feature_report_id": g.report as u8, "feature_report": g.report.name()}),
    };
    let mut out = serde_json::Map::new();
    out.insert("report_id".into(), json!(m.id() as u8));
    out.insert("report".into(), json!(m.id().name()));
    if let Value::Object(fields) = body {
        out.extend(fields);
    }
    Value::Object(out)
}
