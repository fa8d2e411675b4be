//! The operating system's pen report (0x07): the one report in the Digitizer / Pen application
//! collection, so the OS's pen stack (Windows' integrated pen, libinput) maps it onto the screen
//! as it maps a tablet's.
//!
//! An OS maps the collection's logical X and Y ranges onto the whole screen. So X and Y here are
//! the display frame's u and height − v (Y down from the top edge, as screens count; v runs up)
//! in 0.1 mm, with logical ranges 0…W and 0…H of the calibrated display and the same physical
//! ranges: a pen at the display's
//! top-left corner is at the screen's top-left, one at its centre at the centre. The descriptor
//! is built for the display's size ([`crate::report_descriptor`]). Before a calibration gives
//! the size the pen is never in range for the OS. The 3D tracker data stays in the project's own
//! report ([`crate::PenReport`], in the vendor collection).

use crate::ReportId;
use crate::codec::{Reader, Report, Writer};
use crate::error::DecodeError;

/// The OS's pen: switches, proximity and the point on the display.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OsPenReport {
    /// SW1 (HID Tip Switch); never set while out of range.
    pub tip: bool,
    /// SW2 (HID Barrel Switch).
    pub barrel: bool,
    /// SW3 (HID Secondary Barrel Switch).
    pub secondary_barrel: bool,
    /// HID In Range: the pen is in range and over the calibrated display.
    pub in_range: bool,
    /// u on the display, 0.1 mm from its left edge.
    pub x: u16,
    /// 0.1 mm down from the display's top edge (its height − v).
    pub y: u16,
}

const TIP: u8 = 1 << 0;
const BARREL: u8 = 1 << 1;
const SECONDARY: u8 = 1 << 2;
const IN_RANGE: u8 = 1 << 3;

impl Report for OsPenReport {
    const ID: ReportId = ReportId::OsPen;
    const LEN: usize = 6;

    fn write_body(&self, w: &mut Writer<'_>) {
        let bit = |on: bool, b: u8| if on { b } else { 0 };
        w.u8(bit(self.tip, TIP)
            | bit(self.barrel, BARREL)
            | bit(self.secondary_barrel, SECONDARY)
            | bit(self.in_range, IN_RANGE));
        w.u16(self.x);
        w.u16(self.y);
    }

    fn read_body(r: &mut Reader<'_>) -> Result<Self, DecodeError> {
        let b = r.flags(TIP | BARREL | SECONDARY | IN_RANGE)?;
        Ok(OsPenReport {
            tip: b & TIP != 0,
            barrel: b & BARREL != 0,
            secondary_barrel: b & SECONDARY != 0,
            in_range: b & IN_RANGE != 0,
            x: r.u16()?,
            y: r.u16()?,
        })
    }
}
