//! The calibration procedure: lead the user through the targets, take the tip's position at each
//! press of SW1, fit.
//!
//! For each target the pen must first be lifted (SW1 open), then pressed on the target. While
//! SW1 stays closed the tracker-frame positions are averaged, skipping the first 80 ms (the tip
//! settling) and stopping after 300 ms; a touch with fewer than 10 fixes is refused and the user
//! asked again. Then the pivot ([`collect_pivot`]): one press on the display's centre while the
//! pen tilts about its tip, every fix from 80 ms after the press to the release kept for
//! [`super::pivot`]'s sphere. During the procedure the device reports raw tracker-frame positions: its
//! display pose is removed (its tip constraint would project onto an uncalibrated plane) and put
//! back — or replaced by the new calibration — afterwards.

use std::time::{Duration, Instant};

use glam::{DVec2, DVec3};
use pen_protocol::{Config, Message, ReportId};
use thiserror::Error;

use crate::device::{Device, DeviceEvent};
use crate::transport::TransportError;

/// Fixes skipped at the start of a touch, µs of device time.
const SETTLE_US: u64 = 80_000;
/// Fixes averaged per touch at most, µs of device time.
const AVERAGE_US: u64 = 300_000;
/// Fixes a touch needs.
const MIN_FIXES: usize = 10;
/// The longest a pivot is taken, µs of device time (it ends when the pen is lifted).
const PIVOT_MAX_US: u64 = 10_000_000;
/// Fixes a pivot needs: the sphere's fit's least.
const MIN_PIVOT_FIXES: usize = super::pivot::MIN_FIXES;

/// What the procedure tells the user, as it goes.
#[derive(Debug, Clone, PartialEq)]
pub enum Prompt {
    /// Touch target `index` (of `count`) at `target_mm` and press.
    Touch {
        /// From 0.
        index: usize,
        /// Targets in all.
        count: usize,
        /// Where, on the display.
        target_mm: DVec2,
    },
    /// Lift the pen first.
    Lift,
    /// The touch or the pivot was too short: press again.
    Again {
        /// Fixes taken.
        fixes: usize,
    },
    /// Where the pen is now, for a picture of the procedure (every sample in range).
    Pen {
        /// The tip, tracker frame, mm.
        position_mm: DVec3,
        /// SW1 (the tip) is pressed.
        pressed: bool,
        /// Device clock, µs.
        device_us: u64,
    },
    /// Hold the tip on `at_mm` and tilt the pen about it, its top circling once, then lift
    /// ([`collect_pivot`]).
    Pivot {
        /// Where, on the display.
        at_mm: DVec2,
    },
    /// The pivot's fixes made no sphere: it is asked again ([`super::run::calibrate`]).
    PivotAgain {
        /// Why.
        why: String,
    },
    /// The pivot was taken.
    Pivoted {
        /// Fixes taken.
        fixes: usize,
    },
    /// Target taken.
    Taken {
        /// Where the pen was, tracker frame.
        touched_mm: DVec3,
        /// Fixes averaged.
        fixes: usize,
    },
}

impl Prompt {
    /// What a terminal says for this step (`penctl calibrate`, `penmodel calibrate` headless);
    /// `None` for the pen's moves.
    pub fn says(&self) -> Option<String> {
        Some(match self {
            Prompt::Touch {
                index,
                count,
                target_mm,
            } => format!(
                "target {}/{count}: touch ({:.0}, {:.0}) mm from the display's lower-left corner, and press",
                index + 1,
                target_mm.x,
                target_mm.y
            ),
            Prompt::Pivot { at_mm } => format!(
                "pivot: hold the tip on ({:.0}, {:.0}) mm and press; keep it there while you tilt the pen, its top \
                 circling once, leaning it more and less (about 3 s); then lift",
                at_mm.x, at_mm.y
            ),
            Prompt::PivotAgain { why } => format!("  {why}"),
            Prompt::Pen { .. } => return None,
            Prompt::Lift => "  lift the pen first".to_string(),
            // After a touch or the pivot alike.
            Prompt::Again { fixes } => format!("  too short ({fixes} fixes): press again and hold it longer"),
            Prompt::Taken { fixes, .. } | Prompt::Pivoted { fixes } => format!("  taken ({fixes} fixes)"),
        })
    }
}

/// Why the procedure stopped.
#[derive(Debug, Error)]
pub enum CalibrateError {
    /// No device, or it went away.
    #[error("{0}")]
    Device(String),
    /// The device refused or failed a request.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// The user did not touch a target in time.
    #[error("no touch within {0:?}")]
    Timeout(Duration),
    /// The pivot's fixes did not make a sphere, try after try.
    #[error("the pivot failed {tries} times; the last: {why}")]
    Pivot {
        /// Tries made.
        tries: usize,
        /// The last one's reason.
        why: super::pivot::PivotError,
    },
}

/// Attaches to the device within `timeout`.
pub fn attach(device: &mut Device, timeout: Duration) -> Result<(), CalibrateError> {
    let end = Instant::now() + timeout;
    while device.transport().is_none() {
        if Instant::now() > end {
            let why = device.last_error().unwrap_or("no device");
            return Err(CalibrateError::Device(format!("cannot attach: {why}")));
        }
        device.next(Duration::from_millis(100));
    }
    Ok(())
}

/// The device's configuration, and the same without its display pose (raw tracker frame).
pub fn prepare(device: &mut Device) -> Result<Config, CalibrateError> {
    let transport = device
        .transport()
        .ok_or_else(|| CalibrateError::Device("device detached".into()))?;
    let Message::Config(config) = transport.get_feature(ReportId::Config)? else {
        return Err(CalibrateError::Device(
            "the device did not send its configuration".into(),
        ));
    };
    let raw = Config {
        display: None,
        report_display_frame: false,
        ..config
    };
    let status = transport.set_feature(&Message::Config(raw))?;
    if status.code != pen_protocol::StatusCode::Ok {
        return Err(CalibrateError::Device(format!(
            "the device refused the calibration settings: {status}"
        )));
    }
    Ok(config)
}

/// Takes one touch per target; `tell` hears each prompt. Gives up on a target after `patience`.
pub fn collect_touches(
    device: &mut Device,
    targets: &[DVec2],
    patience: Duration,
    mut tell: impl FnMut(&Prompt),
) -> Result<Vec<DVec3>, CalibrateError> {
    let mut touched = Vec::new();
    for (index, &target_mm) in targets.iter().enumerate() {
        tell(&Prompt::Touch {
            index,
            count: targets.len(),
            target_mm,
        });
        let fixes = press(device, patience, &mut tell, Press::TOUCH)?;
        let mean = fixes.iter().sum::<DVec3>() / fixes.len() as f64;
        tell(&Prompt::Taken {
            touched_mm: mean,
            fixes: fixes.len(),
        });
        touched.push(mean);
        wait_for_lift(device, patience)?;
    }
    Ok(touched)
}

/// The pivot ([`super::pivot`]): the tip held on `at_mm` while the pen tilts about it, its top
/// circling, SW1 pressed throughout. Returns the emitter's fixes (tracker frame), from
/// [`SETTLE_US`] after the press to the release (at most [`PIVOT_MAX_US`]).
pub fn collect_pivot(
    device: &mut Device,
    at_mm: DVec2,
    patience: Duration,
    mut tell: impl FnMut(&Prompt),
) -> Result<Vec<DVec3>, CalibrateError> {
    tell(&Prompt::Pivot { at_mm });
    let fixes = press(device, patience, &mut tell, Press::PIVOT)?;
    tell(&Prompt::Pivoted { fixes: fixes.len() });
    wait_for_lift(device, patience)?;
    Ok(fixes)
}

/// What one press takes: fixes from [`SETTLE_US`] after it for at most `hold_us`, and the
/// fewest it needs (fewer, and the user is asked again).
struct Press {
    hold_us: u64,
    min_fixes: usize,
}

impl Press {
    const TOUCH: Press = Press {
        hold_us: AVERAGE_US,
        min_fixes: MIN_FIXES,
    };
    const PIVOT: Press = Press {
        hold_us: PIVOT_MAX_US,
        min_fixes: MIN_PIVOT_FIXES,
    };
}

/// The fixes of one press of SW1 after a lift: the pen must first be lifted, then pressed; the
/// press ends at its release or after `press.hold_us`. Gives up after `patience`.
fn press(
    device: &mut Device,
    patience: Duration,
    tell: &mut impl FnMut(&Prompt),
    press: Press,
) -> Result<Vec<DVec3>, CalibrateError> {
    let deadline = Instant::now() + patience;
    let mut lifted = false;
    let mut told_lift = false;
    let mut fixes: Vec<DVec3> = Vec::new();
    let mut pressed_at: Option<u64> = None;
    loop {
        if Instant::now() > deadline {
            return Err(CalibrateError::Timeout(patience));
        }
        let Some(event) = device.next(Duration::from_millis(50)) else {
            continue;
        };
        let s = match event {
            DeviceEvent::Sample(s, _) => s,
            DeviceEvent::Lost(why) => return Err(CalibrateError::Device(format!("device lost: {why}"))),
            _ => continue,
        };
        if s.in_range {
            tell(&Prompt::Pen {
                position_mm: s.position_mm,
                pressed: s.sw[0],
                device_us: s.device_us,
            });
        }
        if !s.sw[0] {
            if pressed_at.take().is_some() {
                if fixes.len() >= press.min_fixes {
                    return Ok(fixes);
                }
                tell(&Prompt::Again { fixes: fixes.len() });
                fixes.clear();
            }
            lifted = true;
            continue;
        }
        if !lifted {
            if !told_lift {
                tell(&Prompt::Lift);
                told_lift = true;
            }
            continue;
        }
        let start = *pressed_at.get_or_insert(s.device_us);
        let held = s.device_us.saturating_sub(start);
        // Only fresh fixes: a held position (in range, no receivers used) would weigh the
        // last fix again.
        if held >= SETTLE_US && s.in_range && s.quality.receivers_used > 0 {
            fixes.push(s.position_mm);
        }
        if held >= SETTLE_US + press.hold_us && fixes.len() >= press.min_fixes {
            return Ok(fixes);
        }
    }
}

/// Waits until the pen is off the surface (SW1 open), so the next prompt is shown once the pen
/// has left this one; at most `patience`.
fn wait_for_lift(device: &mut Device, patience: Duration) -> Result<(), CalibrateError> {
    let deadline = Instant::now() + patience;
    while Instant::now() < deadline {
        match device.next(Duration::from_millis(50)) {
            Some(DeviceEvent::Sample(s, _)) if !s.sw[0] => break,
            Some(DeviceEvent::Lost(why)) => return Err(CalibrateError::Device(format!("device lost: {why}"))),
            _ => {}
        }
    }
    Ok(())
}
