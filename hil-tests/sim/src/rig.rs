//! The physical set-up: where the receivers and the display really are, how late each receiver's
//! electronics trigger, and what the device is told about all that.

use glam::{DQuat, DVec3};
use pen_core::default_config;
use pen_protocol::{Config, DisplayPose, MAX_RECEIVERS};

/// The true geometry and electronics of a base station and its display.
#[derive(Debug, Clone, PartialEq)]
pub struct Rig {
    /// Receiver positions in the tracker frame, mm.
    pub receivers_mm: Vec<DVec3>,
    /// Each receiver's transducer and detector delay, µs.
    pub delays_us: Vec<f64>,
    /// Where the display really is: tracker → display rotation.
    pub display_rotation: DQuat,
    /// Tracker → display translation, mm (applied after the rotation).
    pub display_translation_mm: DVec3,
    /// The emitter's distance from the pen tip along the pen, mm.
    pub emitter_offset_mm: f64,
    /// Errors in what the device is told: added to each receiver's surveyed position, mm.
    pub survey_error_mm: Vec<DVec3>,
    /// Errors in the calibrated delays the device is told, µs.
    pub delay_error_us: Vec<f64>,
}

/// Delays of the reference build's receivers, µs: amplifier, envelope detector and comparator
/// trigger some tens of microseconds after the sound arrives, each a little differently.
const REFERENCE_DELAYS_US: [f64; MAX_RECEIVERS] = [38.0, 41.5, 36.2, 40.1, 39.3, 37.7, 40.8, 38.9];

impl Rig {
    /// The reference build (docs/hardware.md): four receivers at the display's corners, a
    /// diagonal pair raised, display frame = tracker frame, surveyed and calibrated exactly.
    pub fn reference() -> Rig {
        let config = default_config();
        let receivers_mm: Vec<DVec3> = config.receivers_mm[..config.receiver_count as usize]
            .iter()
            .map(|r| DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64))
            .collect();
        Rig::with_receivers(receivers_mm)
    }

    /// The reference build with a fifth receiver on a 300 mm post at the bottom-right corner,
    /// above receiver 1 (docs/hardware.md).
    pub fn reference_five() -> Rig {
        let mut rig = Rig::reference();
        rig.receivers_mm.push(DVec3::new(640.0, -40.0, 300.0));
        Rig::with_receivers(rig.receivers_mm)
    }

    /// The six-receiver build: posts at all four corners, with a receiver at the top of each and
    /// at the foot of the bottom-right and top-left ones. Any one receiver can be left out and
    /// the other five still place the pen well, so late echoes can be rejected.
    pub fn reference_six() -> Rig {
        let mut rig = Rig::reference_five();
        rig.receivers_mm.push(DVec3::new(-40.0, 380.0, 300.0));
        Rig::with_receivers(rig.receivers_mm)
    }

    /// Receivers at `receivers_mm`, everything else as in the reference build.
    pub fn with_receivers(receivers_mm: Vec<DVec3>) -> Rig {
        let n = receivers_mm.len().min(MAX_RECEIVERS);
        Rig {
            delays_us: REFERENCE_DELAYS_US[..n].to_vec(),
            survey_error_mm: vec![DVec3::ZERO; n],
            delay_error_us: vec![0.0; n],
            receivers_mm: receivers_mm[..n].to_vec(),
            display_rotation: DQuat::IDENTITY,
            display_translation_mm: DVec3::ZERO,
            emitter_offset_mm: 8.0,
        }
    }

    /// This rig with the display somewhere else: `rotation` and `translation_mm` map the tracker
    /// frame to the display frame.
    pub fn with_display_pose(mut self, rotation: DQuat, translation_mm: DVec3) -> Rig {
        self.display_rotation = rotation;
        self.display_translation_mm = translation_mm;
        self
    }

    /// The reference build with its display set up by hand, a little off where the tracker
    /// frame puts it: turned 1.2° about a tilted axis and shifted by about a centimetre. What a
    /// calibration has to find (the modeler's demo, `penctl calibrate --sim`).
    pub fn hand_placed_display() -> Rig {
        let axis = DVec3::new(0.2, -0.3, 1.0).normalize();
        Rig::reference().with_display_pose(
            DQuat::from_axis_angle(axis, 1.2f64.to_radians()),
            DVec3::new(9.0, -6.0, 2.5),
        )
    }

    /// A display-frame point (u, v on the surface, h above it) in the tracker frame.
    pub fn display_to_tracker(&self, p: DVec3) -> DVec3 {
        self.display_rotation.inverse() * (p - self.display_translation_mm)
    }

    /// The display's normal in the tracker frame.
    pub fn display_normal(&self) -> DVec3 {
        self.display_rotation.inverse() * DVec3::Z
    }

    /// The configuration the device runs: the surveyed receivers and calibrated delays (true
    /// values plus the errors above), the display pose, the air temperature the operator set.
    pub fn config(&self, temperature_c: f64) -> Config {
        let mut c = default_config();
        c.receiver_count = self.receivers_mm.len() as u8;
        c.receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
        c.transducer_delay_us = [0.0; MAX_RECEIVERS];
        for (i, r) in self.receivers_mm.iter().enumerate() {
            let surveyed = *r + self.survey_error_mm[i];
            c.receivers_mm[i] = [surveyed.x as f32, surveyed.y as f32, surveyed.z as f32];
            c.transducer_delay_us[i] = (self.delays_us[i] + self.delay_error_us[i]) as f32;
        }
        c.temperature_c = temperature_c as f32;
        let q = self.display_rotation;
        let t = self.display_translation_mm;
        c.display = Some(DisplayPose {
            rotation: [q.w as f32, q.x as f32, q.y as f32, q.z as f32],
            translation_mm: [t.x as f32, t.y as f32, t.z as f32],
            scale: 1.0,
            // Not calibrated to a display: the OS's pen stays out of range (the host's own
            // reports carry the pen).
            size_mm: [0.0; 2],
        });
        c
    }
}
