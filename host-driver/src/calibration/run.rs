//! The whole calibration as `penctl calibrate` and `penmodel calibrate` run it, on a device
//! attached: the device put in its raw tracker frame, a touch per target and the pivot
//! ([`super::procedure`]), the fit, and the device's configuration given back (or the new
//! calibration written to it). What the user is told, and where the file goes, is the caller's:
//! the terminal's prompts, or the modeler's targets on the display.

use std::time::Duration;

use anyhow::{Context, Result, bail};
use glam::DVec2;
use pen_protocol::{Config, Message, StatusCode};

use super::pivot::{self, Pivot};
use super::procedure::{self, CalibrateError, Prompt};
use super::{Calibration, DeviceId, DisplaySize, FitKind};
use crate::device::Device;
#[cfg(feature = "sim")]
use crate::source::Source;

/// What to calibrate.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The display's size.
    pub display: DisplaySize,
    /// The targets, in the order they are touched.
    pub targets: Vec<DVec2>,
    /// The transform to fit.
    pub kind: FitKind,
    /// Where the pivot is taken, or `None` to skip it.
    pub pivot_at: Option<DVec2>,
    /// How long each touch is waited for.
    pub patience: Duration,
    /// Write the new calibration to the device (it then reports display coordinates).
    pub write_device: bool,
}

impl Plan {
    /// `count` targets (4, 5 or 9) on `display`, a similarity fit, the pivot taken.
    pub fn new(display: DisplaySize, count: usize, patience: Duration) -> Plan {
        Plan {
            display,
            targets: display.targets(count),
            kind: FitKind::Similarity,
            pivot_at: Some(display.pivot_target()),
            patience,
            write_device: false,
        }
    }
}

/// What the calibration found.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The fit, with its base station's ID and, after a pivot, the pen's emitter-to-tip vector.
    pub calibration: Calibration,
    /// The pivot's sphere, when it was taken.
    pub pivot: Option<Pivot>,
}

/// The simulated pen touching `targets` (and pivoting at `pivot`), `speed` device seconds a
/// second: the source `--source sim` calibrates.
#[cfg(feature = "sim")]
pub fn sim_source(targets: &[DVec2], pivot: Option<DVec2>, speed: f64) -> Source {
    let rig = pen_sim::rig::Rig::hand_placed_display();
    Source::Sim(crate::transport::sim::SimOptions {
        scenario: pen_sim::scenarios::calibration(targets, pivot, rig),
        seed: 1,
        speed,
        plug: Default::default(),
    })
}

/// The base station's ID, which the calibration records (it is refused for any other).
pub fn device_id(device: &mut Device) -> Result<DeviceId> {
    match device.info() {
        Ok(info) => Ok(DeviceId::of(info)),
        Err(why) => bail!("cannot read the base station's unique ID, which the calibration records: {why}"),
    }
}

/// Calibrates the attached `device` by `plan`, telling `tell` each step; a pivot whose fixes
/// make no sphere is asked again up to three times ([`Prompt::PivotAgain`]). Whatever happens
/// the device gets its configuration back — or, with `plan.write_device`, the new calibration.
pub fn calibrate(device: &mut Device, plan: &Plan, mut tell: impl FnMut(&Prompt)) -> Result<Outcome> {
    let id = device_id(device)?;
    let original = procedure::prepare(device)?;
    let taken = procedure::collect_touches(device, &plan.targets, plan.patience, &mut tell).and_then(|touched| {
        let pivot = match plan.pivot_at {
            Some(at) => Some(take_pivot(device, at, plan.patience, &mut tell)?),
            None => None,
        };
        Ok((touched, pivot))
    });
    let (touched, pivot) = match taken {
        Ok(t) => t,
        Err(e) => {
            // Leave the device as it was.
            if let Some(t) = device.transport() {
                let _ = t.set_feature(&Message::Config(original));
            }
            return Err(e.into());
        }
    };
    let fitted = super::fit(&plan.targets, &touched, plan.kind, plan.display);
    let mut calibration = match fitted {
        Ok(c) => c,
        Err(e) => {
            if let Some(t) = device.transport() {
                let _ = t.set_feature(&Message::Config(original));
            }
            return Err(e.into());
        }
    };
    calibration.device = Some(id);
    if let (Some(p), Some(at)) = (&pivot, plan.pivot_at) {
        calibration.tip_offset_mm = Some(pivot::tip_offset(&calibration, p, at));
    }
    let restored = if plan.write_device {
        Config {
            display: Some(calibration.to_device()),
            report_display_frame: true,
            ..original
        }
    } else {
        original
    };
    let t = device.transport().context("the device went away")?;
    let status = t.set_feature(&Message::Config(restored))?;
    if status.code != StatusCode::Ok {
        bail!("the device refused: {status}");
    }
    Ok(Outcome { calibration, pivot })
}

/// The pivot's sphere: asked again (up to three times) while its fixes do not make one, with
/// the reason.
fn take_pivot(
    device: &mut Device,
    at: DVec2,
    patience: Duration,
    tell: &mut impl FnMut(&Prompt),
) -> Result<Pivot, CalibrateError> {
    const TRIES: usize = 3;
    let mut tries = 0;
    loop {
        let fixes = procedure::collect_pivot(device, at, patience, &mut *tell)?;
        tries += 1;
        match pivot::fit_pivot(&fixes) {
            Ok(p) => return Ok(p),
            Err(why) if tries >= TRIES => return Err(CalibrateError::Pivot { tries, why }),
            Err(why) => tell(&Prompt::PivotAgain { why: why.to_string() }),
        }
    }
}
