//! `pend --virtual-tablet`: the pen as a tablet every program can use, through uinput.
//!
//! pend creates a uinput device called [`NAME`] and moves it with its calibrated events, so
//! that Krita, Blender, GIMP or a game engine see a pen on the display through the OS's own
//! input stack (libinput, evdev) with the base station in its default mode. The device has
//! `INPUT_PROP_DIRECT` (a pen on a screen), `BTN_TOOL_PEN` (in range), `BTN_TOUCH` (SW1, the
//! tip), `BTN_STYLUS` (SW2), `BTN_STYLUS2` (SW3), and absolute axes:
//!
//! * `ABS_X`, `ABS_Y`: the point on the display in 0.1 mm ([`UNITS_PER_MM`] units per mm, the
//!   axes' resolution) from its top-left corner, 0 … width and 0 … height of the calibration's
//!   display; a point beyond an edge is held at it.
//! * `ABS_DISTANCE`: the pen's height above the surface in 0.1 mm, 0 … [`DISTANCE_MAX_MM`];
//!   0 while the tip is down.
//! * `ABS_PRESSURE`: from the tip switch, which has no force sensor: [`PRESSURE_MAX`] while SW1
//!   is closed, 0 otherwise.
//!
//! Events map one to one: `proximity_in`/`proximity_out` set `BTN_TOOL_PEN`, `tip_down`/`tip_up`
//! `BTN_TOUCH` and the pressure, `button_down`/`button_up` the barrel buttons, `motion` the
//! axes; each pen event is one evdev frame (a `SYN_REPORT`). A lost device's events (its ups
//! and `proximity_out`) release everything, as on the socket. docs/events.md says when to use
//! this or the base station's own display-frame pen.

use evdev::uinput::VirtualDevice;
use evdev::{
    AbsInfo, AbsoluteAxisCode, AttributeSet, BusType, EventType, InputEvent, InputId, KeyCode, PropType, UinputAbsSetup,
};

use crate::events::{DisplayPoint, EventKind, PenEvent};

/// The uinput device's name.
pub const NAME: &str = "penscape pen";

/// Axis units per millimetre: 0.1 mm units, the protocol's.
pub const UNITS_PER_MM: i32 = 10;

/// The largest height `ABS_DISTANCE` reports, mm (the workspace's top).
pub const DISTANCE_MAX_MM: f64 = 500.0;

/// `ABS_PRESSURE` with the tip down.
pub const PRESSURE_MAX: i32 = 1023;

/// The device node the virtual tablet needs.
pub const UINPUT: &str = "/dev/uinput";

/// Why the virtual tablet could not be made.
#[derive(Debug, thiserror::Error)]
pub enum VirtualTabletError {
    /// `/dev/uinput` does not open.
    #[error(
        "cannot open {UINPUT}: {0}; the virtual tablet needs write access to it: install \
         host-driver/udev/70-penscape.rules (it gives the logged-in user {UINPUT}) or load the \
         uinput module (modprobe uinput)"
    )]
    Open(std::io::Error),
    /// uinput refused the device.
    #[error("uinput refused the virtual tablet: {0}")]
    Create(std::io::Error),
}

/// The display's extent in axis units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// Width, mm.
    pub width_mm: f64,
    /// Height, mm.
    pub height_mm: f64,
}

impl Extent {
    fn max(mm: f64) -> i32 {
        (mm * f64::from(UNITS_PER_MM))
            .round()
            .clamp(1.0, f64::from(i32::MAX / 2)) as i32
    }

    /// `ABS_X`'s maximum.
    pub fn x_max(&self) -> i32 {
        Extent::max(self.width_mm)
    }

    /// `ABS_Y`'s maximum.
    pub fn y_max(&self) -> i32 {
        Extent::max(self.height_mm)
    }

    /// The axes' values for `p`: X from the left edge, Y down from the top edge (the display
    /// frame's v runs up from the bottom), the height; each held within its range.
    pub fn axes(&self, p: &DisplayPoint) -> (i32, i32, i32) {
        let units = |mm: f64, max: i32| {
            let v = (mm * f64::from(UNITS_PER_MM)).round();
            if v.is_nan() {
                0
            } else {
                v.clamp(0.0, f64::from(max)) as i32
            }
        };
        (
            units(p.u_mm, self.x_max()),
            units(self.height_mm - p.v_mm, self.y_max()),
            units(p.h_mm, Extent::max(DISTANCE_MAX_MM)),
        )
    }
}

/// The evdev events (without the closing `SYN_REPORT`) for one pen event; empty for events
/// that move nothing (device found, missed, head).
pub fn evdev_events(extent: &Extent, e: &PenEvent) -> Vec<InputEvent> {
    let key = |k: KeyCode, on: bool| InputEvent::new(EventType::KEY.0, k.0, i32::from(on));
    let abs = |a: AbsoluteAxisCode, v: i32| InputEvent::new(EventType::ABSOLUTE.0, a.0, v);
    let mut out = Vec::new();
    match &e.kind {
        EventKind::ProximityIn => out.push(key(KeyCode::BTN_TOOL_PEN, true)),
        EventKind::ProximityOut => out.push(key(KeyCode::BTN_TOOL_PEN, false)),
        EventKind::TipDown => {
            out.push(key(KeyCode::BTN_TOUCH, true));
            out.push(abs(AbsoluteAxisCode::ABS_PRESSURE, PRESSURE_MAX));
        }
        EventKind::TipUp => {
            out.push(key(KeyCode::BTN_TOUCH, false));
            out.push(abs(AbsoluteAxisCode::ABS_PRESSURE, 0));
        }
        EventKind::ButtonDown { button } | EventKind::ButtonUp { button } => {
            let down = matches!(e.kind, EventKind::ButtonDown { .. });
            match button {
                2 => out.push(key(KeyCode::BTN_STYLUS, down)),
                3 => out.push(key(KeyCode::BTN_STYLUS2, down)),
                _ => {}
            }
        }
        EventKind::Motion => {}
        EventKind::DeviceLost { .. }
        | EventKind::DeviceFound { .. }
        | EventKind::Missed { .. }
        | EventKind::Head(_) => {
            return out;
        }
    }
    // Every pen event carries where the pen is: the axes go with the keys, in one frame.
    if let Some(p) = &e.point {
        let (x, y, distance) = extent.axes(p);
        let tip = e.sw.is_some_and(|sw| sw[0]);
        out.push(abs(AbsoluteAxisCode::ABS_X, x));
        out.push(abs(AbsoluteAxisCode::ABS_Y, y));
        out.push(abs(AbsoluteAxisCode::ABS_DISTANCE, if tip { 0 } else { distance }));
    }
    out
}

/// The uinput pen.
pub struct VirtualTablet {
    device: VirtualDevice,
    extent: Extent,
}

impl VirtualTablet {
    /// Creates the uinput device for a display of `extent`.
    pub fn open(extent: Extent) -> Result<VirtualTablet, VirtualTabletError> {
        let builder = VirtualDevice::builder().map_err(VirtualTabletError::Open)?;
        let mut keys = AttributeSet::<KeyCode>::new();
        for k in [
            KeyCode::BTN_TOOL_PEN,
            KeyCode::BTN_TOUCH,
            KeyCode::BTN_STYLUS,
            KeyCode::BTN_STYLUS2,
        ] {
            keys.insert(k);
        }
        let mut props = AttributeSet::<PropType>::new();
        props.insert(PropType::DIRECT);
        let axis = |code, max, resolution| UinputAbsSetup::new(code, AbsInfo::new(0, 0, max, 0, 0, resolution));
        let device = builder
            .name(NAME)
            .input_id(InputId::new(
                BusType::BUS_VIRTUAL,
                pen_protocol::USB_VID,
                pen_protocol::USB_PID,
                1,
            ))
            .with_keys(&keys)
            .and_then(|b| b.with_properties(&props))
            .and_then(|b| b.with_absolute_axis(&axis(AbsoluteAxisCode::ABS_X, extent.x_max(), UNITS_PER_MM)))
            .and_then(|b| b.with_absolute_axis(&axis(AbsoluteAxisCode::ABS_Y, extent.y_max(), UNITS_PER_MM)))
            .and_then(|b| {
                b.with_absolute_axis(&axis(
                    AbsoluteAxisCode::ABS_DISTANCE,
                    Extent::max(DISTANCE_MAX_MM),
                    UNITS_PER_MM,
                ))
            })
            .and_then(|b| b.with_absolute_axis(&axis(AbsoluteAxisCode::ABS_PRESSURE, PRESSURE_MAX, 0)))
            .and_then(|b| b.build())
            .map_err(VirtualTabletError::Create)?;
        Ok(VirtualTablet { device, extent })
    }

    /// Moves the tablet with `e`.
    pub fn event(&mut self, e: &PenEvent) -> std::io::Result<()> {
        let events = evdev_events(&self.extent, e);
        if events.is_empty() {
            return Ok(());
        }
        self.device.emit(&events)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(kind: EventKind, u: f64, v: f64, h: f64, tip: bool) -> PenEvent {
        PenEvent {
            kind,
            t_us: 0,
            point: Some(DisplayPoint {
                u_mm: u,
                v_mm: v,
                h_mm: h,
                u_px: 0.0,
                v_px: 0.0,
            }),
            sw: Some([tip, false, false]),
            seq: None,
        }
    }

    fn codes(events: &[InputEvent]) -> Vec<(u16, u16, i32)> {
        events.iter().map(|e| (e.event_type().0, e.code(), e.value())).collect()
    }

    #[test]
    fn events_map_onto_keys_and_display_axes() {
        let extent = Extent {
            width_mm: 600.0,
            height_mm: 340.0,
        };
        assert_eq!((extent.x_max(), extent.y_max()), (6000, 3400));
        let (k, a) = (EventType::KEY.0, EventType::ABSOLUTE.0);
        // In range 40 mm above (150, 255) mm: a quarter across, a quarter down from the top.
        let e = evdev_events(&extent, &at(EventKind::ProximityIn, 150.0, 255.0, 40.0, false));
        assert_eq!(
            codes(&e),
            [
                (k, KeyCode::BTN_TOOL_PEN.0, 1),
                (a, AbsoluteAxisCode::ABS_X.0, 1500),
                (a, AbsoluteAxisCode::ABS_Y.0, 850),
                (a, AbsoluteAxisCode::ABS_DISTANCE.0, 400),
            ]
        );
        // The tip down: touch, full pressure, no distance.
        let e = evdev_events(&extent, &at(EventKind::TipDown, 150.0, 255.0, 0.3, true));
        assert_eq!(
            codes(&e)[..2],
            [
                (k, KeyCode::BTN_TOUCH.0, 1),
                (a, AbsoluteAxisCode::ABS_PRESSURE.0, 1023)
            ]
        );
        assert_eq!(codes(&e)[4], (a, AbsoluteAxisCode::ABS_DISTANCE.0, 0));
        // Beyond the edges: held at them.
        let e = evdev_events(&extent, &at(EventKind::Motion, -20.0, 400.0, 900.0, false));
        assert_eq!(
            codes(&e),
            [
                (a, AbsoluteAxisCode::ABS_X.0, 0),
                (a, AbsoluteAxisCode::ABS_Y.0, 0),
                (a, AbsoluteAxisCode::ABS_DISTANCE.0, 5000),
            ]
        );
        let e = evdev_events(&extent, &at(EventKind::ButtonDown { button: 3 }, 1.0, 1.0, 1.0, false));
        assert_eq!(codes(&e)[0], (k, KeyCode::BTN_STYLUS2.0, 1));
        let lost = PenEvent {
            kind: EventKind::DeviceLost { reason: "x".into() },
            t_us: 0,
            point: None,
            sw: None,
            seq: None,
        };
        assert!(evdev_events(&extent, &lost).is_empty());
    }
}
