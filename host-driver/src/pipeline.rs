//! From a device to pen events: samples through the calibration into the event detector.

use std::time::Duration;

use crate::calibration::Calibration;
use crate::device::{Device, DeviceEvent};
use crate::events::{DisplayPoint, EventDetector, PenEvent};
use crate::sample::{Sample, now_us};
use crate::source::Source;

/// A device, its calibration, and the pen's state.
pub struct Pipeline {
    device: Device,
    calibration: Calibration,
    detector: EventDetector,
    lost: u64,
}

impl Pipeline {
    /// A pipeline on `source` with `calibration`.
    pub fn new(source: Source, calibration: Calibration) -> Pipeline {
        Pipeline::with_device(Device::new(source), calibration)
    }

    /// A pipeline on a device session already under way (after a calibration, say).
    pub fn with_device(device: Device, calibration: Calibration) -> Pipeline {
        Pipeline {
            device,
            calibration,
            detector: EventDetector::new(),
            lost: 0,
        }
    }

    /// The device session, for requests.
    pub fn device(&mut self) -> &mut Device {
        &mut self.device
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// Reports lost (sequence gaps) since the pipeline started.
    pub fn lost(&self) -> u64 {
        self.lost
    }

    /// Where a sample is on the display: calibrated here, or as the device reported it when the
    /// device applies a calibration itself.
    pub fn point(&self, s: &Sample) -> DisplayPoint {
        if s.display_frame {
            self.calibration.point(s.position_mm)
        } else {
            self.calibration.to_display(s.position_mm)
        }
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
                self.detector.on_device_found(now_us(), &name, out);
                None
            }
            DeviceEvent::Lost(why) => {
                self.detector.on_device_lost(now_us(), &why, out);
                None
            }
            DeviceEvent::Tof(_) => None,
        }
    }
}
