//! Which base station a calibration belongs to, and where each one's calibration is kept.
//!
//! A calibration is only right for the base station whose receivers it was measured with: it
//! records that station's unique ID (the microcontroller's 96 bits, `penctl info`), and is
//! refused for any other. The simulated pen's calibrations are kept in a file of their own, so
//! that calibrating the simulator never replaces the real device's calibration.

use std::fmt;
use std::path::PathBuf;

use pen_protocol::DeviceInfo;

use super::{Calibration, CalibrationError};
use crate::hex;

/// The unique ID the simulated base station reports (`pen_sim::sim::SIM_UNIQUE_ID`, the QEMU
/// build's too), spelled out here so that a build without the simulator still names it.
pub const SIMULATED_ID: DeviceId = DeviceId(*b"penscape-sim");

/// A base station's unique ID, as its device information report gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DeviceId(pub [u8; 12]);

impl DeviceId {
    /// The ID of the device `info` describes.
    pub fn of(info: &DeviceInfo) -> DeviceId {
        DeviceId(info.unique_id)
    }

    /// The ID from its 24 hex digits, as the file and `penctl info` write it.
    pub fn from_hex(text: &str) -> Option<DeviceId> {
        let bytes = hex::parse_hex(text).ok()?;
        Some(DeviceId(bytes.try_into().ok()?))
    }

    /// The 24 hex digits.
    pub fn to_hex(&self) -> String {
        hex::to_hex(&self.0)
    }

    /// Whether this is the simulated base station.
    pub fn is_simulated(&self) -> bool {
        *self == SIMULATED_ID
    }
}

/// The hex digits, and "(the simulated pen)" for that one: what messages show.
impl fmt::Display for DeviceId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.to_hex())?;
        if self.is_simulated() {
            write!(f, " (the simulated pen)")?;
        }
        Ok(())
    }
}

impl Calibration {
    /// Whether this calibration may be applied to the device `info` describes (`Err`: why its
    /// information could not be read). One that records no device (the identity, or a file of
    /// version 1) goes with any.
    pub fn check_device(&self, info: Result<&DeviceInfo, &str>) -> Result<(), CalibrationError> {
        let Some(calibrated) = self.device else {
            return Ok(());
        };
        let attached = info.map_err(|why| CalibrationError::DeviceUnknown {
            calibrated,
            why: why.to_string(),
        })?;
        let attached = DeviceId::of(attached);
        if attached == calibrated {
            Ok(())
        } else {
            Err(CalibrationError::WrongDevice { calibrated, attached })
        }
    }

    /// What to tell the user about a calibration read from a file that records no device
    /// (format version 1): it is applied to any base station, which is wrong if it came from
    /// the simulated pen (before version 2, `penctl calibrate --sim` wrote the real file).
    pub fn unbound_warning(&self, path: &std::path::Path) -> Option<String> {
        self.device.is_none().then(|| {
            format!(
                "{} records no base station (format version 1), so it is used for any: if it came from \
                 `penctl calibrate --sim`, it is the simulated pen's and wrong for real hardware; run \
                 `penctl calibrate` to calibrate this base station and record it",
                path.display()
            )
        })
    }
}

/// The folder the calibrations are kept in: `$XDG_CONFIG_HOME/penscape`
/// (`~/.config/penscape`); `None` when neither variable is set. The modeler keeps its settings
/// there too.
pub fn config_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|h| !h.is_empty())
                .map(|h| PathBuf::from(h).join(".config"))
        })?;
    Some(base.join("penscape"))
}

/// Where a real base station's calibration is kept by default:
/// `$XDG_CONFIG_HOME/penscape/calibration.toml` (`~/.config/penscape/calibration.toml`);
/// `None` when neither variable is set.
pub fn default_path() -> Option<PathBuf> {
    Some(config_dir()?.join("calibration.toml"))
}

/// Where the simulated pen's calibration is kept by default: `calibration-sim.toml` beside the
/// real one, which it must never replace.
pub fn default_sim_path() -> Option<PathBuf> {
    Some(config_dir()?.join("calibration-sim.toml"))
}

/// The default calibration file for a device: the simulated pen's own when `simulated`.
pub fn default_path_for(simulated: bool) -> Option<PathBuf> {
    if simulated { default_sim_path() } else { default_path() }
}

/// The default calibration file for a source: the simulated pen's own for `--source sim`. A simulated
/// base station reached over a link (`pen-sim serve --pty`) is known only once attached, by
/// its ID: [`default_path_for`].
pub fn default_path_for_source(source: &crate::source::Source) -> Option<PathBuf> {
    #[cfg(feature = "sim")]
    let simulated = matches!(source, crate::source::Source::Sim(_));
    #[cfg(not(feature = "sim"))]
    let simulated = {
        let _ = source;
        false
    };
    default_path_for(simulated)
}
