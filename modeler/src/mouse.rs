//! The mouse (or a graphics tablet's pointer) as the pen, for users without a base station.
//!
//! The window's pointer is turned into the samples a base station in its display-frame mode
//! would send, and those go through the host's own [`EventDetector`], so the interaction sees
//! the events a pen makes and nothing in it knows the difference. The mapping
//! (`docs/modeler.md`, Mouse):
//!
//! | mouse | pen |
//! |---|---|
//! | over the picture | in range, at that point of the display |
//! | left button held | SW1: the tip on the surface |
//! | right button held | SW2 |
//! | middle button or Space held | SW3 |
//! | wheel, with SW2 or SW3 held and the tip up | the pen's height above the surface, [`WHEEL_MM`] a notch |
//!
//! The buttons' switches and the wheel's step are the user's to change ([`MouseMap`], read from
//! the settings file by [`crate::config`]); the table is the default.
//!
//! So a right-drag over a figure grabs it (right held, left pressed and let go), the wheel
//! lifts it, and releasing the right button commits the pull, as lifting the pen and opening
//! SW2 does; Space held with sideways motion sets its slope. The height returns to the surface
//! when SW2 and SW3 are both released.

use glam::DVec3;
use pen_host::events::{DisplayPoint, EventDetector, PenEvent};
use pen_host::sample::Sample;
use pen_protocol::Quality;

/// Height above the surface per wheel notch, mm.
pub const WHEEL_MM: f64 = 5.0;

/// The highest the wheel lifts the pen, mm: about what the pen's tracker reaches above a display.
pub const MAX_HEIGHT_MM: f64 = 300.0;

/// A pen switch a mouse button stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Switch {
    /// The tip switch: the tip on the surface.
    Sw1,
    /// The barrel switch nearer the tip.
    Sw2,
    /// The other barrel switch.
    Sw3,
    /// The button does nothing.
    None,
}

impl Switch {
    /// The switch's index in a report's `[SW1, SW2, SW3]`; `None` for no switch.
    fn index(self) -> Option<usize> {
        match self {
            Switch::Sw1 => Some(0),
            Switch::Sw2 => Some(1),
            Switch::Sw3 => Some(2),
            Switch::None => None,
        }
    }

    /// What the help says the button does.
    fn says(self) -> &'static str {
        match self {
            Switch::Sw1 => "SW1: the tip on the surface",
            Switch::Sw2 => "SW2",
            Switch::Sw3 => "SW3",
            Switch::None => "nothing",
        }
    }
}

/// Which pen switch each mouse button is, and how far a wheel notch lifts the pen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MouseMap {
    /// The switch of the left, right and middle button (Space is the middle button).
    pub buttons: [Switch; 3],
    /// The pen's height per wheel notch away from the user, mm; negative turns the wheel round.
    pub wheel_mm: f64,
}

impl Default for MouseMap {
    /// Left SW1, right SW2, middle (and Space) SW3, [`WHEEL_MM`] a notch.
    fn default() -> MouseMap {
        MouseMap {
            buttons: [Switch::Sw1, Switch::Sw2, Switch::Sw3],
            wheel_mm: WHEEL_MM,
        }
    }
}

impl MouseMap {
    /// The pen's switches `[SW1, SW2, SW3]` while the mouse's `[left, right, middle]` are held.
    pub fn switches(&self, buttons: [bool; 3]) -> [bool; 3] {
        let mut sw = [false; 3];
        for (held, s) in buttons.iter().zip(self.buttons) {
            if let Some(i) = s.index() {
                sw[i] |= *held;
            }
        }
        sw
    }

    /// The mapping in a few words, as the window says it when it opens (`left draws, right
    /// grabs, middle/Space is SW3, wheel lifts`).
    pub fn summary(&self) -> String {
        let names = ["left", "right", "middle/Space"];
        let mut parts: Vec<String> = names
            .iter()
            .zip(self.buttons)
            .filter_map(|(n, s)| {
                let does = match s {
                    Switch::Sw1 => "draws",
                    Switch::Sw2 => "grabs",
                    Switch::Sw3 => "is SW3",
                    Switch::None => return None,
                };
                Some(format!("{n} {does}"))
            })
            .collect();
        if self.buttons.iter().any(|s| matches!(s, Switch::Sw2 | Switch::Sw3)) {
            parts.push(if self.wheel_mm > 0.0 {
                "wheel lifts".to_string()
            } else {
                "wheel (turned round) lifts".to_string()
            });
        }
        parts.join(", ")
    }

    /// The mapping as the window's help shows it: what each button does, the wheel, and off
    /// the picture.
    pub fn help(&self) -> Vec<(String, String)> {
        let names = ["left button", "right button", "middle / Space"];
        let mut lines: Vec<(String, String)> = names
            .iter()
            .zip(self.buttons)
            .map(|(n, s)| (n.to_string(), s.says().to_string()))
            .collect();
        let lifts = [Switch::Sw2, Switch::Sw3]
            .iter()
            .filter_map(|s| names.iter().zip(self.buttons).find(|(_, b)| b == s).map(|(n, _)| *n))
            .map(|n| n.split(' ').next().unwrap_or(n))
            .collect::<Vec<_>>();
        if !lifts.is_empty() {
            lines.push((
                format!("wheel + {}", lifts.join("/")),
                format!("lift the pen ({} mm a notch)", self.wheel_mm.abs()),
            ));
        }
        lines.push(("off the picture".to_string(), "out of range".to_string()));
        lines
    }
}

/// The pointer as the window reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointerState {
    /// Where over the picture, as fractions of its width and height from the top-left
    /// corner; `None` off the picture.
    pub at: Option<[f64; 2]>,
    /// Left, right and middle (or Space) held.
    pub buttons: [bool; 3],
    /// Wheel notches since the last state, away from the user positive.
    pub wheel: f64,
}

/// The mouse as a pen over a display of `display_mm`, shown in a picture of `picture_px`.
#[derive(Debug, Clone)]
pub struct MousePen {
    map: MouseMap,
    detector: EventDetector,
    height_mm: f64,
    seq: u16,
    started_us: u64,
}

impl Default for MousePen {
    fn default() -> MousePen {
        MousePen::new()
    }
}

impl MousePen {
    /// Out of range, nothing held, on the surface, with the default mapping.
    pub fn new() -> MousePen {
        MousePen::with_map(MouseMap::default())
    }

    /// [`MousePen::new`] with the buttons and wheel mapped by `map`.
    pub fn with_map(map: MouseMap) -> MousePen {
        MousePen {
            map,
            detector: EventDetector::new(),
            height_mm: 0.0,
            seq: 0,
            started_us: 0,
        }
    }

    /// The pen's height above the surface now, mm.
    pub fn height_mm(&self) -> f64 {
        self.height_mm
    }

    /// The mapping in use.
    pub fn map(&self) -> &MouseMap {
        &self.map
    }

    /// The pen events of the pointer's new state at host time `t_us` (µs since the epoch), for a
    /// display of `display_mm` (width, height) shown in a picture of `picture_px` pixels.
    pub fn update(
        &mut self,
        pointer: PointerState,
        display_mm: [f64; 2],
        picture_px: [u32; 2],
        t_us: u64,
    ) -> Vec<PenEvent> {
        let [tip, sw2, sw3] = self.map.switches(pointer.buttons);
        if self.seq == 0 {
            self.started_us = t_us;
        }
        if sw2 || sw3 {
            if pointer.wheel.is_finite() {
                self.height_mm = (self.height_mm + pointer.wheel * self.map.wheel_mm).clamp(0.0, MAX_HEIGHT_MM);
            }
        } else {
            self.height_mm = 0.0;
        }
        // The tip pressed is on the surface whatever the wheel said.
        let h_mm = if tip { 0.0 } else { self.height_mm };
        let [fx, fy] = pointer.at.unwrap_or([0.0, 0.0]);
        let point = DisplayPoint {
            u_mm: fx * display_mm[0],
            v_mm: (1.0 - fy) * display_mm[1],
            h_mm,
            u_px: fx * f64::from(picture_px[0]),
            v_px: (1.0 - fy) * f64::from(picture_px[1]),
        };
        self.seq = self.seq.wrapping_add(1).max(1);
        let sample = Sample {
            seq: self.seq,
            device_us: t_us.saturating_sub(self.started_us),
            host_us: t_us,
            // Off the picture the pen is out of range, and nothing can be held there.
            sw: if pointer.at.is_some() {
                [tip, sw2, sw3]
            } else {
                [false; 3]
            },
            in_range: pointer.at.is_some(),
            display_frame: true,
            position_mm: DVec3::new(point.u_mm, point.v_mm, point.h_mm),
            quality: Quality::NONE,
        };
        let mut out = Vec::new();
        self.detector.on_sample(&sample, point, &mut out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pen_host::events::EventKind;

    fn state(at: [f64; 2], buttons: [bool; 3], wheel: f64) -> PointerState {
        PointerState {
            at: Some(at),
            buttons,
            wheel,
        }
    }

    const DISPLAY: [f64; 2] = [600.0, 340.0];
    const PICTURE: [u32; 2] = [1280, 720];

    #[test]
    fn a_left_drag_is_a_stroke_on_the_display() {
        let mut m = MousePen::new();
        let mut kinds = Vec::new();
        let mut last = None;
        for (i, (at, left)) in [
            ([0.5, 0.5], false),
            ([0.5, 0.5], true),
            ([0.75, 0.25], true),
            ([0.75, 0.25], false),
        ]
        .into_iter()
        .enumerate()
        {
            for e in m.update(state(at, [left, false, false], 0.0), DISPLAY, PICTURE, 1_000 + i as u64) {
                kinds.push(e.kind.name());
                last = e.point;
            }
        }
        assert_eq!(
            kinds,
            [
                "proximity_in",
                "motion",
                "tip_down",
                "motion",
                "motion",
                "tip_up",
                "motion"
            ]
        );
        let p = last.expect("a point");
        assert_eq!(
            (p.u_mm, p.v_mm, p.h_mm),
            (450.0, 255.0, 0.0),
            "v up from the lower edge"
        );
        assert_eq!((p.u_px, p.v_px), (960.0, 540.0));
    }

    #[test]
    fn the_wheel_lifts_the_pen_only_while_a_barrel_button_is_held() {
        let mut m = MousePen::new();
        let at = [0.2, 0.2];
        m.update(state(at, [false; 3], 3.0), DISPLAY, PICTURE, 1);
        assert_eq!(m.height_mm(), 0.0, "the wheel alone moves nothing");
        m.update(state(at, [false, true, false], 0.0), DISPLAY, PICTURE, 2);
        let events = m.update(state(at, [false, true, false], 4.0), DISPLAY, PICTURE, 3);
        assert_eq!(
            events.last().and_then(|e| e.point).map(|p| p.h_mm),
            Some(4.0 * WHEEL_MM)
        );
        // The tip pressed is on the surface; let go, the pen is back at the wheel's height.
        let events = m.update(state(at, [true, true, false], 0.0), DISPLAY, PICTURE, 4);
        assert_eq!(events.last().and_then(|e| e.point).map(|p| p.h_mm), Some(0.0));
        m.update(state(at, [false, true, false], -100.0), DISPLAY, PICTURE, 5);
        assert_eq!(m.height_mm(), 0.0, "never below the surface");
        m.update(state(at, [false, true, false], 1e9), DISPLAY, PICTURE, 6);
        assert_eq!(m.height_mm(), MAX_HEIGHT_MM);
        m.update(state(at, [false; 3], 0.0), DISPLAY, PICTURE, 7);
        assert_eq!(m.height_mm(), 0.0, "released, back on the surface");
    }

    #[test]
    fn a_mapping_swaps_the_buttons_and_turns_the_wheel_round() {
        let map = MouseMap {
            buttons: [Switch::Sw1, Switch::Sw3, Switch::Sw2],
            wheel_mm: -2.0,
        };
        assert_eq!(map.switches([false, true, false]), [false, false, true]);
        assert_eq!(map.switches([false, false, true]), [false, true, false]);
        let mut m = MousePen::with_map(map);
        let at = [0.2, 0.2];
        // The middle button is SW2 now: its events say button 2, and the wheel lifts the pen
        // when turned towards the user.
        let kinds: Vec<EventKind> = [
            m.update(state(at, [false; 3], 0.0), DISPLAY, PICTURE, 1),
            m.update(state(at, [false, false, true], -3.0), DISPLAY, PICTURE, 2),
        ]
        .concat()
        .into_iter()
        .map(|e| e.kind)
        .collect();
        assert!(kinds.contains(&EventKind::ButtonDown { button: 2 }), "{kinds:?}");
        assert_eq!(m.height_mm(), 6.0);
        let help = map.help();
        assert_eq!(help[1], ("right button".to_string(), "SW3".to_string()));
        assert!(
            help.iter()
                .any(|(k, d)| k == "wheel + middle/right" && d.contains("2 mm a notch")),
            "{help:?}"
        );
        assert_eq!(
            MouseMap::default().summary(),
            "left draws, right grabs, middle/Space is SW3, wheel lifts"
        );
        assert_eq!(
            map.summary(),
            "left draws, right is SW3, middle/Space grabs, wheel (turned round) lifts"
        );
        let none = MouseMap {
            buttons: [Switch::Sw1, Switch::None, Switch::None],
            wheel_mm: 5.0,
        };
        assert_eq!(none.switches([true, true, true]), [true, false, false]);
        assert!(!none.help().iter().any(|(k, _)| k.starts_with("wheel")));
    }

    #[test]
    fn leaving_the_picture_releases_everything() {
        let mut m = MousePen::new();
        m.update(state([0.5, 0.5], [true, true, true], 0.0), DISPLAY, PICTURE, 1);
        let off = PointerState {
            at: None,
            buttons: [true, true, true],
            wheel: 0.0,
        };
        let kinds: Vec<EventKind> = m.update(off, DISPLAY, PICTURE, 2).into_iter().map(|e| e.kind).collect();
        assert_eq!(
            kinds,
            [
                EventKind::TipUp,
                EventKind::ButtonUp { button: 2 },
                EventKind::ButtonUp { button: 3 },
                EventKind::ProximityOut
            ]
        );
    }
}
