//! The modeler's own settings file: `$XDG_CONFIG_HOME/penscape/modeler.toml`
//! (`~/.config/penscape/modeler.toml`), beside the host driver's calibration. Only what a user
//! may want otherwise than the defaults is in it; a missing file is the defaults. Today it holds
//! the mouse's mapping (`docs/modeler.md`, Mouse):
//!
//! ```toml
//! [mouse]
//! left = "sw1"      # the tip on the surface
//! right = "sw2"
//! middle = "sw3"    # Space too
//! wheel_mm = 5.0    # the pen's height per wheel notch; negative turns the wheel round
//! ```
//!
//! A button may be `"sw1"`, `"sw2"`, `"sw3"` or `"none"`. A key the file does not know, or a
//! value out of range, is refused naming the file and the key.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::mouse::{MouseMap, Switch, WHEEL_MM};

/// The file's name in the configuration folder.
pub const FILE_NAME: &str = "modeler.toml";

/// The most a wheel notch may lift the pen, mm (either way).
pub const MAX_WHEEL_MM: f64 = 100.0;

/// The modeler's settings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Config {
    /// The mouse's buttons and wheel as the pen.
    pub mouse: MouseMap,
}

/// The settings file could not be read or says something the modeler cannot take.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {why}")]
pub struct ConfigError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong, naming the key.
    pub why: String,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct File {
    #[serde(default)]
    mouse: Option<MouseFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MouseFile {
    left: Option<Switch>,
    right: Option<Switch>,
    middle: Option<Switch>,
    wheel_mm: Option<f64>,
}

/// Where the settings are read from: `$XDG_CONFIG_HOME/penscape/modeler.toml`, or under
/// `$HOME/.config`; `None` when neither variable is set.
pub fn default_path() -> Option<PathBuf> {
    Some(pen_host::calibration::device::config_dir()?.join(FILE_NAME))
}

/// The settings in the default file ([`default_path`]); the defaults when there is none.
pub fn load() -> Result<Config, ConfigError> {
    match default_path() {
        Some(path) => load_from(&path),
        None => Ok(Config::default()),
    }
}

/// The settings in `path`; the defaults when it does not exist.
pub fn load_from(path: &Path) -> Result<Config, ConfigError> {
    let error = |why: String| ConfigError {
        path: path.to_path_buf(),
        why,
    };
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Config::default()),
        Err(e) => return Err(error(format!("cannot read it: {e}"))),
    };
    parse(&text).map_err(error)
}

/// The settings in a file's `text`.
pub fn parse(text: &str) -> Result<Config, String> {
    let file: File = toml::from_str(text).map_err(|e| e.message().to_string() + &at(&e, text))?;
    let mut config = Config::default();
    if let Some(m) = file.mouse {
        let map = &mut config.mouse;
        for (slot, given) in map.buttons.iter_mut().zip([m.left, m.right, m.middle]) {
            if let Some(s) = given {
                *slot = s;
            }
        }
        if let Some(mm) = m.wheel_mm {
            if !mm.is_finite() || mm == 0.0 || mm.abs() > MAX_WHEEL_MM {
                return Err(format!(
                    "mouse.wheel_mm = {mm}: the height a wheel notch gives, mm, must be from -{MAX_WHEEL_MM} to \
                     {MAX_WHEEL_MM} and not 0 (default {WHEEL_MM})"
                ));
            }
            map.wheel_mm = mm;
        }
    }
    Ok(config)
}

/// Where in `text` a TOML error is, as ` (line L)`.
fn at(e: &toml::de::Error, text: &str) -> String {
    e.span()
        .map(|s| format!(" (line {})", text[..s.start.min(text.len())].lines().count().max(1)))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_file_and_an_empty_file_are_the_defaults() {
        let dir = tempfile::tempdir().expect("tempdir");
        let none = load_from(&dir.path().join("modeler.toml")).expect("defaults");
        assert_eq!(none, Config::default());
        assert_eq!(parse("").expect("empty"), Config::default());
        let m = Config::default().mouse;
        assert_eq!(m.buttons, [Switch::Sw1, Switch::Sw2, Switch::Sw3]);
        assert_eq!(m.wheel_mm, WHEEL_MM);
    }

    #[test]
    fn the_mouse_mapping_is_read_key_by_key() {
        let c = parse("[mouse]\nleft = \"sw1\"\nright = \"sw3\"\nmiddle = \"sw2\"\nwheel_mm = -2.5\n").expect("parses");
        assert_eq!(c.mouse.buttons, [Switch::Sw1, Switch::Sw3, Switch::Sw2]);
        assert_eq!(c.mouse.wheel_mm, -2.5);
        // Keys left out keep their defaults.
        let c = parse("[mouse]\nmiddle = \"none\"\n").expect("parses");
        assert_eq!(c.mouse.buttons, [Switch::Sw1, Switch::Sw2, Switch::None]);
    }

    #[test]
    fn a_bad_key_or_value_is_refused_naming_it() {
        let err = parse("[mouse]\nleft = \"sw4\"\n").expect_err("no sw4");
        assert!(err.contains("sw4") && err.contains("line 2"), "{err}");
        let err = parse("[mouse]\nleft_button = \"sw1\"\n").expect_err("unknown key");
        assert!(err.contains("left_button"), "{err}");
        for bad in ["0.0", "500.0", "nan"] {
            let err = parse(&format!("[mouse]\nwheel_mm = {bad}\n")).expect_err(bad);
            assert!(err.contains("mouse.wheel_mm"), "{err}");
        }
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("modeler.toml");
        std::fs::write(&path, "[mouse]\nwheel_mm = \"far\"\n").expect("write");
        let err = load_from(&path).expect_err("not a number").to_string();
        assert!(err.starts_with(&path.display().to_string()), "{err}");
    }
}
