//! The calibration file (TOML, docs/calibration.md): written atomically, read with every
//! problem named by its key.

use std::path::Path;

use glam::{DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::fit::compact;
use super::{Calibration, CalibrationError, DeviceId, DisplaySize, FitKind, TargetResidual, Transform};

/// The calibration file's format version: 3 may record the pen's emitter-to-tip vector
/// (`[pen]`, from the pivot); 2, still read, records the base station (`[device]`) as 3 does.
pub const FILE_VERSION: u32 = 3;
/// The format that recorded the base station but not the pen: read as 3 without `[pen]`.
pub const FILE_VERSION_BOUND: u32 = 2;
/// The longest emitter-to-tip vector a file may give, mm: a pen's emitter is in its nose.
const TIP_OFFSET_MAX_MM: f64 = 100.0;
/// The format before the base station was recorded: still read, and applied to any base station
/// with a warning ([`Calibration::unbound_warning`]), so that an existing calibration keeps
/// working until the user calibrates again.
pub const FILE_VERSION_UNBOUND: u32 = 1;

// The file format (docs/calibration.md), with every field optional so that a missing key is
// reported by name rather than by the parser's position.
#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileDisplay {
    width_mm: Option<f64>,
    height_mm: Option<f64>,
    width_px: Option<u32>,
    height_px: Option<u32>,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileDevice {
    unique_id: Option<String>,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileTransform {
    kind: Option<FitKind>,
    rotation_wxyz: Option<[f64; 4]>,
    translation_mm: Option<[f64; 3]>,
    scale: Option<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileTarget {
    display_mm: [f64; 2],
    touched_mm: [f64; 3],
    residual_mm: f64,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileFit {
    rms_mm: Option<f64>,
    max_mm: Option<f64>,
    #[serde(default)]
    targets: Vec<FileTarget>,
}

#[derive(Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FilePen {
    tip_offset_mm: Option<[f64; 3]>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    version: Option<u32>,
    device: Option<FileDevice>,
    pen: Option<FilePen>,
    display: Option<FileDisplay>,
    transform: Option<FileTransform>,
    fit: Option<FileFit>,
}

impl Calibration {
    /// The calibration as the text of a TOML file: version 3 with the base station it belongs
    /// to (and the pen's emitter-to-tip vector when the pivot measured it), or version 1 when it
    /// records no base station (and then no pen: version 1 has no place for it).
    pub fn to_toml(&self) -> String {
        let q = self.transform.rotation;
        let t = self.transform.translation_mm;
        let file = File {
            version: Some(if self.device.is_some() {
                FILE_VERSION
            } else {
                FILE_VERSION_UNBOUND
            }),
            device: self.device.map(|d| FileDevice {
                unique_id: Some(d.to_hex()),
            }),
            pen: self.device.and(self.tip_offset_mm).map(|t| FilePen {
                tip_offset_mm: Some(t.to_array()),
            }),
            display: Some(FileDisplay {
                width_mm: Some(self.display.width_mm),
                height_mm: Some(self.display.height_mm),
                width_px: Some(self.display.width_px),
                height_px: Some(self.display.height_px),
            }),
            transform: Some(FileTransform {
                kind: Some(self.kind),
                rotation_wxyz: Some([q.w, q.x, q.y, q.z]),
                translation_mm: Some(t.to_array()),
                scale: Some(self.transform.scale),
            }),
            fit: Some(FileFit {
                rms_mm: Some(self.rms_mm()),
                max_mm: Some(self.max_mm()),
                targets: self
                    .residuals
                    .iter()
                    .map(|r| FileTarget {
                        display_mm: r.target_mm.to_array(),
                        touched_mm: r.touched_mm.to_array(),
                        residual_mm: r.residual_mm,
                    })
                    .collect(),
            }),
        };
        let body = toml::to_string_pretty(&file).unwrap_or_default();
        let whose = match self.device {
            Some(d) if d.is_simulated() => " of the simulated pen",
            _ => "",
        };
        format!("# penscape calibration{whose}: tracker frame → display frame (docs/calibration.md)\n{body}")
    }

    /// Parses a calibration file's text; `path` names it in errors.
    pub fn from_toml(text: &str, path: &str) -> Result<Calibration, CalibrationError> {
        let file: File = toml::from_str(text).map_err(|e| CalibrationError::File {
            path: path.into(),
            message: e.to_string(),
        })?;
        let bad = |key: &str, problem: &str| CalibrationError::BadValue {
            path: path.into(),
            key: key.into(),
            problem: problem.into(),
        };
        let missing = |key: &str| bad(key, "is missing");
        let bound = |d: FileDevice| -> Result<Option<DeviceId>, CalibrationError> {
            let id = d.unique_id.ok_or_else(|| missing("device.unique_id"))?;
            let id = DeviceId::from_hex(&id).ok_or_else(|| {
                bad(
                    "device.unique_id",
                    "must be the base station's 24 hex digits, as `penctl info` shows them",
                )
            })?;
            Ok(Some(id))
        };
        let device = match (file.version, file.device) {
            (Some(FILE_VERSION | FILE_VERSION_BOUND), Some(d)) => bound(d)?,
            (Some(FILE_VERSION | FILE_VERSION_BOUND), None) => return Err(missing("device")),
            (Some(FILE_VERSION_UNBOUND), None) => None,
            (Some(FILE_VERSION_UNBOUND), Some(_)) => {
                return Err(bad("device", "is new in version 2: set `version = 2`"));
            }
            (Some(v), _) => {
                return Err(bad(
                    "version",
                    &format!("is {v}; this program reads versions {FILE_VERSION_UNBOUND} to {FILE_VERSION}"),
                ));
            }
            (None, _) => return Err(missing("version")),
        };
        let tip_offset_mm = match (file.version, file.pen) {
            (_, None) => None,
            (Some(FILE_VERSION), Some(pen)) => {
                let t = pen.tip_offset_mm.ok_or_else(|| missing("pen.tip_offset_mm"))?;
                if t.iter().any(|v| !v.is_finite()) || DVec3::from_array(t).length() > TIP_OFFSET_MAX_MM {
                    return Err(bad(
                        "pen.tip_offset_mm",
                        &format!("must be three finite numbers, at most {TIP_OFFSET_MAX_MM} mm long"),
                    ));
                }
                Some(DVec3::from_array(t))
            }
            (_, Some(_)) => {
                return Err(bad(
                    "pen",
                    &format!("is new in version {FILE_VERSION}: set `version = {FILE_VERSION}`"),
                ));
            }
        };
        let d = file.display.ok_or_else(|| missing("display"))?;
        let display = DisplaySize {
            width_mm: d.width_mm.ok_or_else(|| missing("display.width_mm"))?,
            height_mm: d.height_mm.ok_or_else(|| missing("display.height_mm"))?,
            width_px: d.width_px.ok_or_else(|| missing("display.width_px"))?,
            height_px: d.height_px.ok_or_else(|| missing("display.height_px"))?,
        };
        display.check().map_err(|e| match e {
            CalibrationError::Display { key, problem } => bad(&format!("display.{key}"), &problem),
            other => other,
        })?;
        let t = file.transform.ok_or_else(|| missing("transform"))?;
        let kind = t.kind.ok_or_else(|| missing("transform.kind"))?;
        let q = t.rotation_wxyz.ok_or_else(|| missing("transform.rotation_wxyz"))?;
        let quat = DQuat::from_xyzw(q[1], q[2], q[3], q[0]);
        if !quat.is_finite() || (quat.length() - 1.0).abs() > 1e-3 {
            return Err(bad("transform.rotation_wxyz", "must be a unit quaternion [w, x, y, z]"));
        }
        let tr = t.translation_mm.ok_or_else(|| missing("transform.translation_mm"))?;
        if tr.iter().any(|v| !v.is_finite() || v.abs() > 10_000.0) {
            return Err(bad(
                "transform.translation_mm",
                "must be three finite numbers within ±10 m",
            ));
        }
        let scale = match t.scale {
            Some(s) if s.is_finite() && (0.5..=2.0).contains(&s) => s,
            Some(s) => {
                return Err(bad(
                    "transform.scale",
                    &format!("must be between 0.5 and 2, is {}", compact(s)),
                ));
            }
            None => return Err(missing("transform.scale")),
        };
        if kind == FitKind::Rigid && scale != 1.0 {
            return Err(bad("transform.scale", "must be 1 for a rigid transform"));
        }
        let residuals = file
            .fit
            .map(|f| f.targets)
            .unwrap_or_default()
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                let finite =
                    t.display_mm.iter().chain(&t.touched_mm).all(|v| v.is_finite()) && t.residual_mm.is_finite();
                if finite {
                    Ok(TargetResidual {
                        target_mm: DVec2::from_array(t.display_mm),
                        touched_mm: DVec3::from_array(t.touched_mm),
                        residual_mm: t.residual_mm,
                    })
                } else {
                    Err(bad(&format!("fit.targets[{i}]"), "must hold finite numbers"))
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        // A quaternion written by this program is already of unit length: keep its exact bits.
        let rotation = if (quat.length() - 1.0).abs() > 1e-12 {
            quat.normalize()
        } else {
            quat
        };
        Ok(Calibration {
            transform: Transform {
                rotation,
                translation_mm: DVec3::from_array(tr),
                scale,
            },
            kind,
            display,
            residuals,
            device,
            tip_offset_mm,
        })
    }

    /// Reads a calibration file.
    pub fn load(path: &Path) -> Result<Calibration, CalibrationError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| CalibrationError::File {
            path: name.clone(),
            message: e.to_string(),
        })?;
        Calibration::from_toml(&text, &name)
    }

    /// Writes the calibration file atomically: a temporary file beside it, synced, renamed over
    /// it, the directory synced; the file keeps the mode and owner of the one it replaces.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        use std::io::Write;
        let mut file = atomic_write_file::AtomicWriteFile::open(path)?;
        file.write_all(self.to_toml().as_bytes())?;
        file.commit()
    }
}
