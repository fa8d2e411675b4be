//! The running configuration and what is derived from it once, when it is applied: receiver
//! positions as vectors, delays in ns, the speed of sound, the display frame.

use pen_protocol::{Config, ConfigError, DisplayPose, Filter, MAX_RECEIVERS};

use crate::math::Vec3;
use crate::ranging::speed_of_sound_m_s;

/// The reference build's configuration (docs/hardware.md): a display of 600 × 340 mm with its
/// lower-left corner at the origin, x along the bottom edge, y up the surface, z out of it
/// towards the user; a receiver beside each corner, the bottom-left and top-right ones on
/// 300 mm posts. Four receivers in one plane would leave every point a mirror image; raising a
/// diagonal pair makes the solution unique and keeps the dilution of precision between 1.5 and
/// 2.4 over the workspace (1.8 on average; a flat rectangle of receivers reaches 27 near the
/// surface).
pub fn default_config() -> Config {
    let mut receivers_mm = [[0.0; 3]; MAX_RECEIVERS];
    receivers_mm[..4].copy_from_slice(&[
        [-40.0, -40.0, 300.0],
        [640.0, -40.0, 0.0],
        [-40.0, 380.0, 0.0],
        [640.0, 380.0, 300.0],
    ]);
    Config {
        receiver_count: 4,
        receivers_mm,
        transducer_delay_us: [0.0; MAX_RECEIVERS],
        temperature_c: 20.0,
        speed_of_sound_m_s: None,
        report_rate_hz: 0,
        filter: Filter::OneEuro {
            min_cutoff_hz: 0.5,
            beta: 0.1,
            d_cutoff_hz: 1.0,
        },
        debounce_ms: 5,
        display: Some(DisplayPose {
            rotation: [1.0, 0.0, 0.0, 0.0],
            translation_mm: [0.0; 3],
            scale: 1.0,
            // Unknown until a calibration says: the OS's pen stays out of range until then.
            size_mm: [0.0; 2],
        }),
        report_display_frame: false,
        stream_tof: false,
    }
}

/// The display surface in the tracker frame, from the configuration's similarity transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayFrame {
    /// Rows of R (tracker → display rotation).
    rows: [Vec3; 3],
    scale: f32,
    translation: Vec3,
}

impl DisplayFrame {
    /// From a validated pose; the quaternion is normalised here.
    pub fn new(pose: &DisplayPose) -> DisplayFrame {
        let [w, x, y, z] = pose.rotation;
        let n = crate::math::sqrt(w * w + x * x + y * y + z * z);
        let (w, x, y, z) = (w / n, x / n, y / n, z / n);
        let rows = [
            Vec3::new(
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ),
            Vec3::new(
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ),
            Vec3::new(
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ),
        ];
        DisplayFrame {
            rows,
            scale: pose.scale,
            translation: Vec3::from_array(pose.translation_mm),
        }
    }

    /// A tracker-frame point in the display frame: (u, v, h) = s·R·p + t.
    pub fn to_display(&self, p: Vec3) -> Vec3 {
        let r = Vec3::new(self.rows[0].dot(p), self.rows[1].dot(p), self.rows[2].dot(p));
        r * self.scale + self.translation
    }

    /// The surface normal in the tracker frame (towards the user).
    pub fn normal(&self) -> Vec3 {
        // The third row of R maps tracker vectors onto the display's h axis.
        self.rows[2]
    }

    /// Height above the surface along its normal, in tracker millimetres.
    pub fn height(&self, p: Vec3) -> f32 {
        self.rows[2].dot(p) + self.translation.z / self.scale
    }

    /// The point of the surface nearest to `p` (the tip-contact constraint).
    pub fn onto_surface(&self, p: Vec3) -> Vec3 {
        p - self.normal() * self.height(p)
    }
}

/// A validated configuration with everything the hot path needs precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// The configuration as the host wrote it.
    pub config: Config,
    /// Speed of sound, m/s.
    pub speed_m_s: f32,
    /// Receiver positions, mm; the first `count` are used.
    pub receivers: [Vec3; MAX_RECEIVERS],
    /// Receivers in use.
    pub count: usize,
    /// Transducer delays, ns.
    pub delays_ns: [u32; MAX_RECEIVERS],
    /// The display surface, when configured.
    pub display: Option<DisplayFrame>,
    /// Debounce time, µs.
    pub debounce_us: u64,
    /// Interval between reports, µs; `None` for one report per cycle.
    pub report_interval_us: Option<u64>,
}

impl Settings {
    /// Validates `config` and derives the settings; the error names the offending field.
    pub fn new(config: Config) -> Result<Settings, ConfigError> {
        config.validate()?;
        let count = config.receiver_count as usize;
        let mut receivers = [Vec3::ZERO; MAX_RECEIVERS];
        let mut delays_ns = [0; MAX_RECEIVERS];
        for i in 0..count {
            receivers[i] = Vec3::from_array(config.receivers_mm[i]);
            // Validated to 0…1000 µs, so the product fits a u32 exactly enough (1 ns steps).
            delays_ns[i] = (config.transducer_delay_us[i] * 1000.0 + 0.5) as u32;
        }
        Ok(Settings {
            config,
            speed_m_s: config
                .speed_of_sound_m_s
                .unwrap_or_else(|| speed_of_sound_m_s(config.temperature_c)),
            receivers,
            count,
            delays_ns,
            display: config.display.as_ref().map(DisplayFrame::new),
            debounce_us: config.debounce_ms as u64 * 1000,
            report_interval_us: match config.report_rate_hz {
                0 => None,
                hz => Some(1_000_000 / hz as u64),
            },
        })
    }

    /// The direction "in front of the display" (towards the user): the display normal, or the
    /// tracker's +z without a display pose.
    pub fn front(&self) -> Vec3 {
        self.display.map_or(Vec3::Z, |d| d.normal())
    }

    /// Signed distance of `p` in front of the display, mm. Without a display pose the display
    /// is taken to lie in the plane z = the lowest receiver's z, facing +z: receivers are mounted
    /// on or above the display's surface.
    pub fn height(&self, p: Vec3) -> f32 {
        match &self.display {
            Some(d) => d.height(p),
            None => {
                let lowest = self.receivers[..self.count]
                    .iter()
                    .map(|r| r.z)
                    .fold(f32::INFINITY, f32::min);
                p.z - lowest
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_config_is_valid() {
        let s = Settings::new(default_config()).expect("valid");
        assert_eq!(s.count, 4);
        assert!((s.speed_m_s - 343.2).abs() < 0.05);
        assert_eq!(s.report_interval_us, None);
    }

    #[test]
    fn display_frame_of_a_rotated_scaled_pose() {
        // 90° about z: tracker x becomes display v; then scale 2 and shift.
        let h = core::f32::consts::FRAC_1_SQRT_2;
        let pose = DisplayPose {
            rotation: [h, 0.0, 0.0, h],
            translation_mm: [10.0, 20.0, 30.0],
            scale: 2.0,
            size_mm: [0.0; 2],
        };
        let d = DisplayFrame::new(&pose);
        let p = d.to_display(Vec3::new(1.0, 0.0, 5.0));
        assert!((p - Vec3::new(10.0, 22.0, 40.0)).length() < 1e-5, "{p:?}");
        // h = 2·5 + 30 = 40 display mm, i.e. 20 tracker mm above the surface.
        assert!((d.height(Vec3::new(1.0, 0.0, 5.0)) - 20.0).abs() < 1e-5);
        let on = d.onto_surface(Vec3::new(1.0, 0.0, 5.0));
        assert!(d.to_display(on).z.abs() < 1e-5);
    }
}
