//! The USB HID report descriptor.
//!
//! Built at compile time from usbd-hid's item tags (`usbd-hid-descriptors`) by a small `const`
//! builder. usbd-hid's `gen_hid_descriptor!` macro cannot emit Unit items nor Feature reports, and
//! the pen needs both (physical units on X/Y/Z, feature reports for information and
//! configuration), so the items are written out here; the result is exposed through usbd-hid's
//! [`SerializedDescriptor`] and [`AsInputReport`] traits, which embassy-usb and usb-device HID
//! classes consume. The bytes the firmware presents are [`REPORT_DESCRIPTOR`], and the host's
//! tests parse those same bytes with an independent parser.
//!
//! Two application collections:
//!
//! * Digitizer / Pen: report 0x07 ([`OsPenReport`](crate::OsPenReport)), what the operating system's pen stack
//!   takes: tip, barrels, in range, X and Y on the display. Its logical ranges are the
//!   calibrated display's width and height in 0.1 mm, so the descriptor is built for the
//!   display ([`report_descriptor`]) when the device starts.
//! * Vendor 0xFF00 / 0x01: the project's own pen report 0x01 (3D, tracker or display frame,
//!   with its quality), described field by field with vendor usages only; the diagnostics input
//!   report 0x02, the head report 0x08 and the feature reports 0x03–0x06, opaque byte arrays
//!   whose layout the report codecs define. Linux's hid-input maps every input field by its
//!   usage, whatever its collection (a real kernel made a second pen of report 0x01 while its
//!   fields had Digitizer and Generic Desktop usages): only vendor usages keep the reports meant
//!   for our host away from the OS's input devices (docs/protocol.md, hil-tests/kernel).

use usbd_hid::descriptor::{AsInputReport, BufferOverflow, SerializedDescriptor};
use usbd_hid_descriptors::{GlobalItemKind as G, ItemType, LocalItemKind as L, MainItemKind as M};

use crate::ReportId;
use crate::codec::Report;
use crate::config::Config;
use crate::head::HeadReport;
use crate::info::DeviceInfo;

use crate::pen::{POSITION_LOGICAL_MAX, PenReport};
use crate::reset::ResetRecord;
use crate::status::{Command, Status};
use crate::tof::TofReport;

/// HID usage pages and usages the descriptor uses (HID Usage Tables 1.5).
pub mod usage {
    /// Generic Desktop page.
    pub const PAGE_GENERIC_DESKTOP: u16 = 0x01;
    /// Digitizer page.
    pub const PAGE_DIGITIZER: u16 = 0x0D;
    /// The first vendor-defined page.
    pub const PAGE_VENDOR: u16 = 0xFF00;

    /// Generic Desktop X.
    pub const X: u16 = 0x30;
    /// Generic Desktop Y.
    pub const Y: u16 = 0x31;
    /// Generic Desktop Z.
    pub const Z: u16 = 0x32;

    /// Digitizer: Pen (application collection).
    pub const PEN: u16 = 0x02;
    /// Digitizer: Stylus (physical collection).
    pub const STYLUS: u16 = 0x20;
    /// Digitizer: In Range.
    pub const IN_RANGE: u16 = 0x32;
    /// Digitizer: Tip Switch (SW1).
    pub const TIP_SWITCH: u16 = 0x42;
    /// Digitizer: Barrel Switch (SW2).
    pub const BARREL_SWITCH: u16 = 0x44;
    /// Digitizer: Secondary Barrel Switch (SW3).
    pub const SECONDARY_BARREL_SWITCH: u16 = 0x5A;

    /// Vendor: the configuration and diagnostics application collection.
    pub const VENDOR_COLLECTION: u16 = 0x01;
    /// Vendor: position is in the display frame (1 bit).
    pub const VENDOR_DISPLAY_FRAME: u16 = 0x10;
    /// Vendor: sequence number.
    pub const VENDOR_SEQUENCE: u16 = 0x11;
    /// Vendor: device timestamp.
    pub const VENDOR_TIMESTAMP: u16 = 0x12;
    /// Vendor: receivers used.
    pub const VENDOR_RECEIVERS_USED: u16 = 0x13;
    /// Vendor: RMS range residual.
    pub const VENDOR_RESIDUAL: u16 = 0x14;
    /// Vendor: dilution of precision.
    pub const VENDOR_DOP: u16 = 0x15;
    /// Vendor: the pen report's SW1 (tip).
    pub const VENDOR_SW1: u16 = 0x16;
    /// Vendor: the pen report's SW2 (barrel).
    pub const VENDOR_SW2: u16 = 0x17;
    /// Vendor: the pen report's SW3 (second barrel).
    pub const VENDOR_SW3: u16 = 0x18;
    /// Vendor: the pen report's in-range bit.
    pub const VENDOR_IN_RANGE: u16 = 0x19;
    /// Vendor: the pen report's X (tracker or display frame).
    pub const VENDOR_X: u16 = 0x1A;
    /// Vendor: the pen report's Y.
    pub const VENDOR_Y: u16 = 0x1B;
    /// Vendor: the pen report's Z.
    pub const VENDOR_Z: u16 = 0x1C;
    /// Vendor usages of the vendor collection's reports are 0x20 + the report ID.
    pub const VENDOR_REPORT_BASE: u16 = 0x20;
}

/// HID collection kinds.
mod collection {
    pub const PHYSICAL: u32 = 0x00;
    pub const APPLICATION: u32 = 0x01;
}

/// Main item flags (HID 1.11 §6.2.2.5).
mod flags {
    /// Data, Variable, Absolute.
    pub const DATA_VAR_ABS: u32 = 0x02;
    /// Constant, Variable, Absolute: padding.
    pub const CONST_VAR_ABS: u32 = 0x03;
}

/// Unit item values (HID 1.11 §6.2.2.7): system nibble 1 = SI linear.
mod unit {
    pub const NONE: u32 = 0x00;
    /// SI linear, length¹: centimetres.
    pub const CENTIMETRE: u32 = 0x11;
    /// SI linear, time¹: seconds.
    pub const SECOND: u32 = 0x1001;
}

/// Room for the descriptor; the builder fails to compile if it overflows.
const CAPACITY: usize = 384;

/// A `const` HID report descriptor builder: each method appends one item.
#[derive(Clone, Copy)]
struct Builder {
    buf: [u8; CAPACITY],
    len: usize,
    /// Where the OS pen's X and Y logical and physical maxima items start.
    marks: [usize; 4],
}

impl Builder {
    const fn new() -> Self {
        Builder {
            buf: [0; CAPACITY],
            len: 0,
            marks: [0; 4],
        }
    }

    /// Remembers where the next item starts, as mark `i`.
    const fn mark(mut self, i: usize) -> Self {
        self.marks[i] = self.len;
        self
    }

    /// `logical(0, max)` and `physical(0, max)`, the maxima's items marked `i` and `i + 1`.
    const fn extent(self, max: i32, i: usize) -> Self {
        self.global_signed(G::LogicalMin, 0)
            .mark(i)
            .global_signed(G::LogicalMax, max)
            .global_signed(G::PhysicalMin, 0)
            .mark(i + 1)
            .global_signed(G::PhysicalMax, max)
    }

    const fn byte(mut self, b: u8) -> Self {
        self.buf[self.len] = b;
        self.len += 1;
        self
    }

    /// A short item whose data is `size` bytes of `data`, little-endian (size 0, 1, 2 or 4).
    const fn item(mut self, typ: ItemType, tag: u8, data: u32, size: usize) -> Self {
        let size_code = match size {
            0 => 0,
            1 => 1,
            2 => 2,
            _ => 3,
        };
        self = self.byte((tag << 4) | ((typ as u8) << 2) | size_code);
        let mut i = 0;
        while i < size {
            self = self.byte((data >> (8 * i)) as u8);
            i += 1;
        }
        self
    }

    /// An item with unsigned data in its shortest form.
    const fn unsigned(self, typ: ItemType, tag: u8, v: u32) -> Self {
        let size = if v <= 0xFF {
            1
        } else if v <= 0xFFFF {
            2
        } else {
            4
        };
        self.item(typ, tag, v, size)
    }

    /// An item with signed data in its shortest two's-complement form.
    const fn signed(self, typ: ItemType, tag: u8, v: i32) -> Self {
        let size = if v >= i8::MIN as i32 && v <= i8::MAX as i32 {
            1
        } else if v >= i16::MIN as i32 && v <= i16::MAX as i32 {
            2
        } else {
            4
        };
        self.item(typ, tag, v as u32, size)
    }

    const fn global(self, kind: G, v: u32) -> Self {
        self.unsigned(ItemType::Global, kind as u8, v)
    }

    const fn global_signed(self, kind: G, v: i32) -> Self {
        self.signed(ItemType::Global, kind as u8, v)
    }

    const fn usage_page(self, page: u16) -> Self {
        self.global(G::UsagePage, page as u32)
    }

    const fn usage(self, id: u16) -> Self {
        self.unsigned(ItemType::Local, L::Usage as u8, id as u32)
    }

    const fn collection(self, kind: u32) -> Self {
        self.unsigned(ItemType::Main, M::Collection as u8, kind)
    }

    const fn end_collection(self) -> Self {
        self.item(ItemType::Main, M::EndCollection as u8, 0, 0)
    }

    const fn report_id(self, id: ReportId) -> Self {
        self.global(G::ReportID, id as u8 as u32)
    }

    const fn logical(self, min: i32, max: i32) -> Self {
        self.global_signed(G::LogicalMin, min).global_signed(G::LogicalMax, max)
    }

    const fn physical(self, min: i32, max: i32) -> Self {
        self.global_signed(G::PhysicalMin, min)
            .global_signed(G::PhysicalMax, max)
    }

    /// Unit and unit exponent; the exponent is a 4-bit two's-complement nibble (HID 1.11 §6.2.2.7).
    const fn unit(self, unit: u32, exponent: i8) -> Self {
        self.global(G::Unit, unit)
            .global(G::UnitExponent, (exponent as u8 & 0x0F) as u32)
    }

    const fn fields(self, bits: u32, count: u32) -> Self {
        self.global(G::ReportSize, bits).global(G::ReportCount, count)
    }

    const fn input(self, flags: u32) -> Self {
        self.unsigned(ItemType::Main, M::Input as u8, flags)
    }

    const fn feature(self, flags: u32) -> Self {
        self.unsigned(ItemType::Main, M::Feature as u8, flags)
    }

    /// A vendor report of `len` bytes (report ID included) as an opaque byte array.
    const fn vendor_bytes(self, id: ReportId, len: usize, feature: bool) -> Self {
        let b = self
            .report_id(id)
            .usage(usage::VENDOR_REPORT_BASE + id as u8 as u16)
            .fields(8, (len - 1) as u32);
        if feature {
            b.feature(flags::DATA_VAR_ABS)
        } else {
            b.input(flags::DATA_VAR_ABS)
        }
    }

    const fn descriptor(self, extent: [u16; 2]) -> Self {
        use usage::*;
        let max = POSITION_LOGICAL_MAX as i32;
        let (w, h) = (extent[0] as i32, extent[1] as i32);
        self.usage_page(PAGE_DIGITIZER)
            .usage(PEN)
            .collection(collection::APPLICATION)
            .report_id(ReportId::OsPen)
            .usage(STYLUS)
            .collection(collection::PHYSICAL)
            // Byte 1: Tip, Barrel, Secondary Barrel, In Range, 4 bits padding.
            .usage(TIP_SWITCH)
            .usage(BARREL_SWITCH)
            .usage(SECONDARY_BARREL_SWITCH)
            .usage(IN_RANGE)
            .logical(0, 1)
            .fields(1, 4)
            .input(flags::DATA_VAR_ABS)
            .fields(1, 4)
            .input(flags::CONST_VAR_ABS)
            // Bytes 2–5: X and Y on the display, 0.1 mm (centimetres × 10⁻²), from its top-left
            // corner; the logical and physical ranges are the display's width and height.
            .usage_page(PAGE_GENERIC_DESKTOP)
            .usage(X)
            .extent(w, 0)
            .unit(unit::CENTIMETRE, -2)
            .fields(16, 1)
            .input(flags::DATA_VAR_ABS)
            .usage(Y)
            .extent(h, 2)
            .input(flags::DATA_VAR_ABS)
            .end_collection()
            .end_collection()
            // The vendor collection: the project's pen report, diagnostics and feature reports.
            .usage_page(PAGE_VENDOR)
            .usage(VENDOR_COLLECTION)
            .collection(collection::APPLICATION)
            .report_id(ReportId::Pen)
            // The page is the vendor's: this is usage 0xFF00:0x20, not the Digitizer's Stylus.
            .usage(STYLUS)
            .collection(collection::PHYSICAL)
            // Every usage of this report is a vendor one (page 0xFF00 from here on): hid-input
            // maps Digitizer and Generic Desktop usages in any collection, and would make a
            // second pen of the tracker frame.
            // Byte 1: SW1, SW2, SW3, In Range, display-frame flag, 3 bits padding.
            .usage(VENDOR_SW1)
            .usage(VENDOR_SW2)
            .usage(VENDOR_SW3)
            .usage(VENDOR_IN_RANGE)
            .logical(0, 1)
            .physical(0, 0)
            .unit(unit::NONE, 0)
            .fields(1, 4)
            .input(flags::DATA_VAR_ABS)
            .usage(VENDOR_DISPLAY_FRAME)
            .fields(1, 1)
            .input(flags::DATA_VAR_ABS)
            .fields(1, 3)
            .input(flags::CONST_VAR_ABS)
            // Bytes 2–7: X, Y, Z, signed 16-bit, 0.1 mm (centimetres × 10⁻²).
            .usage(VENDOR_X)
            .usage(VENDOR_Y)
            .usage(VENDOR_Z)
            .logical(-max, max)
            .physical(-max, max)
            .unit(unit::CENTIMETRE, -2)
            .fields(16, 3)
            .input(flags::DATA_VAR_ABS)
            // Bytes 8–9: sequence number.
            .usage(VENDOR_SEQUENCE)
            .logical(0, 0xFFFF)
            .physical(0, 0)
            .unit(unit::NONE, 0)
            .fields(16, 1)
            .input(flags::DATA_VAR_ABS)
            // Bytes 10–13: timestamp, µs. HID logical values are signed 32-bit at most, so the
            // declared maximum is 2³¹−1; hosts read the field as unsigned and unwrap it.
            .usage(VENDOR_TIMESTAMP)
            .logical(0, i32::MAX)
            .unit(unit::SECOND, -6)
            .fields(32, 1)
            .input(flags::DATA_VAR_ABS)
            // Bytes 14–16: receivers used, residual (0.1 mm), DOP (×10).
            .usage(VENDOR_RECEIVERS_USED)
            .logical(0, 8)
            .unit(unit::NONE, 0)
            .fields(8, 1)
            .input(flags::DATA_VAR_ABS)
            .usage(VENDOR_RESIDUAL)
            .logical(0, 255)
            .physical(0, 255)
            .unit(unit::CENTIMETRE, -2)
            .fields(8, 1)
            .input(flags::DATA_VAR_ABS)
            .usage(VENDOR_DOP)
            .physical(0, 0)
            .unit(unit::NONE, 0)
            .input(flags::DATA_VAR_ABS)
            .end_collection()
            // Diagnostics and feature reports as byte arrays.
            .vendor_bytes(ReportId::Tof, TofReport::LEN, false)
            .vendor_bytes(ReportId::Head, HeadReport::LEN, false)
            .vendor_bytes(ReportId::DeviceInfo, DeviceInfo::LEN, true)
            .vendor_bytes(ReportId::Config, Config::LEN, true)
            .vendor_bytes(ReportId::Status, Status::LEN, true)
            .vendor_bytes(ReportId::Command, Command::LEN, true)
            .vendor_bytes(ReportId::ResetRecord, ResetRecord::LEN, true)
            .end_collection()
    }

    /// The first `N` bytes, where `N` must be the builder's length.
    const fn take<const N: usize>(self) -> [u8; N] {
        assert!(N == self.len, "descriptor length mismatch");
        let mut out = [0u8; N];
        let mut i = 0;
        while i < N {
            out[i] = self.buf[i];
            i += 1;
        }
        out
    }
}

/// The OS pen's extent before a calibration gives the display's size, 0.1 mm: a 600 × 340 mm
/// display, the reference build's (the pen is never in range for the OS then).
const UNKNOWN_EXTENT: [u16; 2] = [6000, 3400];

/// The OS pen's logical X and Y maxima, 0.1 mm, for a display of `size_mm` (width, height);
/// `None` while the size is unknown (zero) or unusable.
pub fn os_extent(size_mm: [f32; 2]) -> Option<[u16; 2]> {
    let tenths = |mm: f32| {
        let t = mm * 10.0;
        // At least 50 mm (the configuration's limit), and within the 15 bits the logical
        // maximum's two-byte item holds; NaN fails both.
        (t >= 500.0 && t <= i16::MAX as f32).then_some(t as u16)
    };
    Some([tenths(size_mm[0])?, tenths(size_mm[1])?])
}

const BUILT: Builder = Builder::new().descriptor(UNKNOWN_EXTENT);

/// The report descriptor's length in bytes, whatever the display (every valid extent takes a
/// two-byte logical and physical maximum).
pub const REPORT_DESCRIPTOR_LEN: usize = BUILT.len;

/// The report descriptor of a device that knows no display size yet; the host's tests parse it.
pub const REPORT_DESCRIPTOR: [u8; REPORT_DESCRIPTOR_LEN] = BUILT.take();

/// A report descriptor built for a display.
#[derive(Clone, Copy)]
pub struct Descriptor {
    bytes: [u8; REPORT_DESCRIPTOR_LEN],
}

impl Descriptor {
    /// The descriptor's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }
}

/// Where the OS pen's X and Y logical and physical maxima items start in the descriptor.
const EXTENT_ITEMS: [usize; 4] = BUILT.marks;

/// The report descriptor for a display whose OS pen extent is `extent` ([`os_extent`]), or
/// [`REPORT_DESCRIPTOR`] when there is none.
pub fn report_descriptor(extent: Option<[u16; 2]>) -> Descriptor {
    let mut bytes = REPORT_DESCRIPTOR;
    // Every valid maximum (500…32767) is a two-byte item, as the placeholder's are: the four
    // items' data are rewritten in place rather than the descriptor built again (which would
    // cost the firmware the builder's code, 4 KiB).
    if let Some([w, h]) = extent.filter(|e| e.iter().all(|&v| (500..=i16::MAX as u16).contains(&v))) {
        for (at, v) in EXTENT_ITEMS.into_iter().zip([w, w, h, h]) {
            bytes[at + 1..at + 3].copy_from_slice(&v.to_le_bytes());
        }
    }
    Descriptor { bytes }
}

impl SerializedDescriptor for PenReport {
    fn desc() -> &'static [u8] {
        &REPORT_DESCRIPTOR
    }
}

impl AsInputReport for PenReport {
    fn serialize(&self, buffer: &mut [u8]) -> Result<usize, BufferOverflow> {
        self.encode(buffer).map_err(|_| BufferOverflow)
    }
}

impl AsInputReport for HeadReport {
    fn serialize(&self, buffer: &mut [u8]) -> Result<usize, BufferOverflow> {
        self.encode(buffer).map_err(|_| BufferOverflow)
    }
}

impl AsInputReport for TofReport {
    fn serialize(&self, buffer: &mut [u8]) -> Result<usize, BufferOverflow> {
        self.encode(buffer).map_err(|_| BufferOverflow)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patched_extents_equal_built_ones() {
        for extent in [[500, 500], [6000, 3400], [12000, 6750], [32767, 32767]] {
            let built: [u8; REPORT_DESCRIPTOR_LEN] = Builder::new().descriptor(extent).take();
            assert_eq!(report_descriptor(Some(extent)).bytes(), &built[..], "{extent:?}");
        }
        assert_eq!(report_descriptor(Some([499, 3400])).bytes(), &REPORT_DESCRIPTOR[..]);
    }
}
