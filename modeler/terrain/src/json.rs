//! The JSON layout documents and journals are written in: objects one key per line, arrays of
//! numbers (points) on one line, lists of points filled up to the line width. serde_json's
//! pretty printer puts every number on its own line, which makes a figure of 50 points 200 lines.

use serde::Serialize;
use serde_json::Value;

const WIDTH: usize = 100;

/// `value` as indented JSON text ending in a newline.
pub fn pretty<T: Serialize>(value: &T) -> String {
    // Serialising our own types to a Value cannot fail: they hold no maps with non-string keys.
    let value = serde_json::to_value(value).unwrap_or(Value::Null);
    let mut out = String::new();
    write(&mut out, &value, 0);
    out.push('\n');
    out
}

fn compact(value: &Value) -> String {
    // Display of a Value is its compact JSON; commas get a space for readability.
    match value {
        Value::Array(items) => format!("[{}]", items.iter().map(compact).collect::<Vec<_>>().join(", ")),
        Value::Object(map) => format!(
            "{{{}}}",
            map.iter()
                .map(|(k, v)| format!("{}: {}", Value::String(k.clone()), compact(v)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        other => other.to_string(),
    }
}

fn is_flat(value: &Value) -> bool {
    match value {
        Value::Array(items) => items.iter().all(|v| !v.is_array() && !v.is_object()),
        Value::Object(map) => map.values().all(|v| !v.is_array() && !v.is_object()),
        _ => true,
    }
}

fn write(out: &mut String, value: &Value, indent: usize) {
    let pad = |n: usize| " ".repeat(n);
    match value {
        Value::Object(map) if !map.is_empty() => {
            let one_line = compact(value);
            if is_flat(value) && indent + one_line.len() <= WIDTH {
                out.push_str(&one_line);
                return;
            }
            out.push_str("{\n");
            for (i, (k, v)) in map.iter().enumerate() {
                out.push_str(&pad(indent + 2));
                out.push_str(&Value::String(k.clone()).to_string());
                out.push_str(": ");
                write(out, v, indent + 2);
                out.push_str(if i + 1 < map.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push('}');
        }
        Value::Array(items) if !items.is_empty() => {
            if items.iter().all(is_flat) && !items.iter().any(Value::is_object) {
                // Points or numbers: fill lines.
                let parts: Vec<String> = items.iter().map(compact).collect();
                let one_line = format!("[{}]", parts.join(", "));
                if indent + one_line.len() <= WIDTH {
                    out.push_str(&one_line);
                    return;
                }
                out.push_str("[\n");
                let mut line = String::new();
                for (i, p) in parts.iter().enumerate() {
                    let piece = if i + 1 < parts.len() {
                        format!("{p},")
                    } else {
                        p.clone()
                    };
                    if !line.is_empty() && indent + 2 + line.len() + 1 + piece.len() > WIDTH {
                        out.push_str(&pad(indent + 2));
                        out.push_str(&line);
                        out.push('\n');
                        line.clear();
                    }
                    if !line.is_empty() {
                        line.push(' ');
                    }
                    line.push_str(&piece);
                }
                out.push_str(&pad(indent + 2));
                out.push_str(&line);
                out.push('\n');
                out.push_str(&pad(indent));
                out.push(']');
                return;
            }
            out.push_str("[\n");
            for (i, v) in items.iter().enumerate() {
                out.push_str(&pad(indent + 2));
                write(out, v, indent + 2);
                out.push_str(if i + 1 < items.len() { ",\n" } else { "\n" });
            }
            out.push_str(&pad(indent));
            out.push(']');
        }
        other => out.push_str(&compact(other)),
    }
}
