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

/// A sample as `penctl monitor --json` prints it: `seq`, `x_mm`, `y_mm`, `z_mm`, `sw1`…`sw3`,
/// `in_range`, `quality`, device and host times, and the reports lost just before it.
pub fn sample_json(s: &crate::sample::Sample, lost: u64) -> Value {
    let r = |v: f64| (v * 10.0).round() / 10.0;
    json!({
        "seq": s.seq,
        "device_us": s.device_us,
        "host_us": s.host_us,
        "in_range": s.in_range,
        "display_frame": s.display_frame,
        "x_mm": r(s.position_mm.x),
        "y_mm": r(s.position_mm.y),
        "z_mm": r(s.position_mm.z),
        "sw1": s.sw[0],
        "sw2": s.sw[1],
        "sw3": s.sw[2],
        "quality": quality(s.quality),
        "lost": lost,
    })
}

/// The configuration as `penctl config get --json` prints it (the form [`config_from_json`]
/// reads back).
pub fn config_value(c: &Config) -> Value {
    config_json(c)
}

/// Why a JSON configuration is not one.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("`{key}`: {problem}")]
pub struct ConfigJsonError {
    /// The key, e.g. `receivers_mm[2]`.
    pub key: String,
    /// What is wrong.
    pub problem: String,
}

/// Reads a configuration in the form [`config_value`] writes, over `base`: keys that are absent
/// keep `base`'s values. Errors name the key.
pub fn config_from_json(v: &Value, base: &Config) -> Result<Config, ConfigJsonError> {
    use pen_protocol::{DisplayPose, MAX_RECEIVERS};
    let err = |key: &str, problem: &str| ConfigJsonError {
        key: key.into(),
        problem: problem.into(),
    };
    let obj = v
        .as_object()
        .ok_or_else(|| err("(top level)", "must be a JSON object"))?;
    let num = |key: &str, v: &Value| {
        v.as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| err(key, "must be a number"))
    };
    let int = |key: &str, v: &Value, max: u64| {
        v.as_u64()
            .filter(|&x| x <= max)
            .ok_or_else(|| err(key, &format!("must be a whole number from 0 to {max}")))
    };
    let triple = |key: &str, v: &Value| -> Result<[f32; 3], ConfigJsonError> {
        let a = v
            .as_array()
            .filter(|a| a.len() == 3)
            .ok_or_else(|| err(key, "must be [x, y, z]"))?;
        Ok([
            num(key, &a[0])? as f32,
            num(key, &a[1])? as f32,
            num(key, &a[2])? as f32,
        ])
    };
    let mut c = *base;
    for (key, value) in obj {
        match key.as_str() {
            "receiver_count" => c.receiver_count = int(key, value, MAX_RECEIVERS as u64)? as u8,
            "receivers_mm" => {
                let a = value
                    .as_array()
                    .filter(|a| a.len() <= MAX_RECEIVERS)
                    .ok_or_else(|| err(key, "must be a list of up to 8 [x, y, z]"))?;
                c.receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
                for (i, r) in a.iter().enumerate() {
                    c.receivers_mm[i] = triple(&format!("receivers_mm[{i}]"), r)?;
                }
            }
            "transducer_delay_us" => {
                let a = value
                    .as_array()
                    .filter(|a| a.len() <= MAX_RECEIVERS)
                    .ok_or_else(|| err(key, "must be a list of up to 8 numbers"))?;
                c.transducer_delay_us = [0.0; MAX_RECEIVERS];
                for (i, d) in a.iter().enumerate() {
                    c.transducer_delay_us[i] = num(&format!("transducer_delay_us[{i}]"), d)? as f32;
                }
            }
            "temperature_c" => c.temperature_c = num(key, value)? as f32,
            "speed_of_sound_m_s" => {
                c.speed_of_sound_m_s = if value.is_null() {
                    None
                } else {
                    Some(num(key, value)? as f32)
                }
            }
            "report_rate_hz" => c.report_rate_hz = int(key, value, u16::MAX as u64)? as u16,
            "debounce_ms" => c.debounce_ms = int(key, value, u8::MAX as u64)? as u8,
            "report_display_frame" => {
                c.report_display_frame = value.as_bool().ok_or_else(|| err(key, "must be true or false"))?
            }
            "stream_tof" => c.stream_tof = value.as_bool().ok_or_else(|| err(key, "must be true or false"))?,
            "filter" => {
                let f = value
                    .as_object()
                    .ok_or_else(|| err(key, "must be an object with a kind"))?;
                c.filter = match f.get("kind").and_then(Value::as_str) {
                    Some("off") => Filter::Off,
                    Some("one_euro") => {
                        let p = |k: &str| {
                            let key = format!("filter.{k}");
                            f.get(k)
                                .ok_or_else(|| err(&key, "is missing"))
                                .and_then(|v| num(&key, v))
                                .map(|x| x as f32)
                        };
                        Filter::OneEuro {
                            min_cutoff_hz: p("min_cutoff_hz")?,
                            beta: p("beta")?,
                            d_cutoff_hz: p("d_cutoff_hz")?,
                        }
                    }
                    _ => return Err(err("filter.kind", "must be \"off\" or \"one_euro\"")),
                };
            }
            "display" => {
                c.display = if value.is_null() {
                    None
                } else {
                    let d = value.as_object().ok_or_else(|| err(key, "must be null or an object"))?;
                    let field = |k: &str| d.get(k).ok_or_else(|| err(&format!("display.{k}"), "is missing"));
                    let q = field("rotation_wxyz")?
                        .as_array()
                        .filter(|a| a.len() == 4)
                        .ok_or_else(|| err("display.rotation_wxyz", "must be [w, x, y, z]"))?;
                    let mut rotation = [0.0f32; 4];
                    for (i, x) in q.iter().enumerate() {
                        rotation[i] = num("display.rotation_wxyz", x)? as f32;
                    }
                    Some(DisplayPose {
                        rotation,
                        translation_mm: triple("display.translation_mm", field("translation_mm")?)?,
                        scale: num("display.scale", field("scale")?)? as f32,
                    })
                }
            }
            other => return Err(err(other, "is not a configuration key")),
        }
    }
    Ok(c)
}
