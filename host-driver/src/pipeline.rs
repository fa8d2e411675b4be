//! From a device to pen events: samples through the calibration into the event detector.
//!
//! A calibration that records its base station is checked against each device as it attaches
//! (or reattaches: another base station may have been plugged in meanwhile); a device it does
//! not belong to is refused — let go and tried again later — with a `device_lost` event saying
//! why and what to do, and none of its samples become events.

use std::time::Duration;

use crate::calibration::Calibration;
use crate::device::{Device, DeviceEvent};
use crate::events::{DisplayPoint, EventDetector, PenEvent};
use crate::head::HeadTracker;
use crate::sample::{Sample, now_us};
use crate::source::Source;

/// How long a refused device is left alone before it is tried again: long enough not to fill
/// a log, short enough to take the right base station soon after it is plugged in.
pub const REFUSED_RETRY: Duration = Duration::from_secs(2);

/// A device, its calibration, and the pen's state.
pub struct Pipeline {
    device: Device,
    calibration: Calibration,
    detector: EventDetector,
    head: HeadTracker,
    lost: u64,
    refused: Option<String>,
    notice: Option<String>,
    /// Whether the glasses were told to lack the pen's vector (once per pipeline).
    told_no_pivot: bool,
}

impl Pipeline {
    /// A pipeline on `source` with `calibration`.
    pub fn new(source: Source, calibration: Calibration) -> Pipeline {
        Pipeline::with_device(Device::new(source), calibration)
    }

    /// A pipeline on a device session already under way (after a calibration, say).
    pub fn with_device(mut device: Device, calibration: Calibration) -> Pipeline {
        // A device attached already gave its `Found` to someone else: let it go so that it
        // attaches again through the check below, which says why it is refused.
        if device.transport().is_some() && calibration.check_device(device.info()).is_err() {
            device.detach(Duration::ZERO);
        }
        Pipeline {
            device,
            calibration,
            detector: EventDetector::new(),
            head: HeadTracker::new(),
            lost: 0,
            refused: None,
            notice: None,
            told_no_pivot: false,
        }
    }

    /// Why the last device attached was refused (its calibration is another's), while it is.
    pub fn refused(&self) -> Option<&str> {
        self.refused.as_deref()
    }

    /// What the device session last said while it waits for a device
    /// ([`DeviceEvent::Waiting`]), or that a fitted calibration without the pivot's vector
    /// carries the glasses' positions, once: every tool shows it as it is.
    pub fn take_notice(&mut self) -> Option<String> {
        self.notice.take()
    }

    /// The device session, for requests.
    pub fn device(&mut self) -> &mut Device {
        &mut self.device
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// Uses `calibration` from the next sample on (pend reloads its file at SIGHUP). One for
    /// another base station than the one attached is refused, the one in use kept: taking it
    /// would mean letting the device go mid-stroke.
    pub fn set_calibration(&mut self, calibration: Calibration) -> Result<(), String> {
        if self.device.transport().is_some()
            && let Err(e) = calibration.check_device(self.device.info())
        {
            return Err(e.to_string());
        }
        self.calibration = calibration;
        self.told_no_pivot = false;
        Ok(())
    }

    /// Reports lost (sequence gaps) since the pipeline started.
    pub fn lost(&self) -> u64 {
        self.lost
    }

    /// Where a sample is on the display: calibrated here, or as the device reported it when the
    /// device applies a calibration itself.
    pub fn point(&self, s: &Sample) -> DisplayPoint {
        self.display_point(s.position_mm, s.display_frame)
    }

    fn display_point(&self, position_mm: glam::DVec3, display_frame: bool) -> DisplayPoint {
        if display_frame {
            self.calibration.point(position_mm)
        } else {
            self.calibration.to_display(position_mm)
        }
    }

    /// The tracked head: its last good pose and the reports refused.
    pub fn head(&self) -> &HeadTracker {
        &self.head
    }

    /// Waits at most `timeout` for the device; appends the resulting events to `out` and returns
    /// the sample, if one came.
    pub fn poll(&mut self, timeout: Duration, out: &mut Vec<PenEvent>) -> Option<Sample> {
        match self.device.next(timeout)? {
            DeviceEvent::Sample(s, lost) => {
                self.lost += lost;
                let point = self.point(&s);
                self.detector.on_sample(&s, point, out);
                Some(s)
            }
            DeviceEvent::Found(name) => {
                if let Err(e) = self.calibration.check_device(self.device.info()) {
                    self.device.detach(REFUSED_RETRY);
                    let why = format!("{name} refused: {e}");
                    // Said once per refusal, not at every retry.
                    if self.refused.as_deref() != Some(why.as_str()) {
                        self.detector.on_device_lost(now_us(), &why, out);
                        self.refused = Some(why);
                    }
                    return None;
                }
                self.refused = None;
                self.detector.on_device_found(now_us(), &name, out);
                None
            }
            DeviceEvent::Lost(why) => {
                self.detector.on_device_lost(now_us(), &why, out);
                None
            }
            DeviceEvent::Waiting(notice) => {
                self.notice = Some(notice);
                None
            }
            DeviceEvent::Head(h) => {
                // Only a device the calibration belongs to gets here (a refused one is detached).
                // The glasses' own emitter: without the pen's emitter-to-tip vector.
                let point = self.calibration.head_to_display(h.position_mm, h.display_frame);
                let fitted = !self.calibration.residuals.is_empty();
                if fitted && self.calibration.tip_offset_mm.is_none() && !self.told_no_pivot {
                    self.told_no_pivot = true;
                    self.notice = Some(
                        "the calibration has no pen vector (calibrated with --no-pivot, or a file before version 3): \
                         the glasses' positions are off by the pen's emitter-to-tip vector, about 8 mm; run \
                         `penctl calibrate` again to take the pivot"
                            .into(),
                    );
                }
                out.push(self.head.on_sample(&h, point, now_us()));
                None
            }
            DeviceEvent::Tof(_) => None,
        }
    }
}
