//! USB HID through hidapi (hidraw on Linux, no system library needed).

use std::ffi::CString;
use std::time::Duration;

use hidapi::{HidApi, HidDevice};
use pen_protocol::{Message, ReportId, Status, USB_PID, USB_VID, usage};

use super::{Transport, TransportError};

/// A base station's HID interface as enumeration finds it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HidPen {
    /// The hidraw path.
    pub path: String,
    /// The product string.
    pub product: String,
    /// The serial number string, if any.
    pub serial: Option<String>,
}

/// The base stations attached: VID/PID of the protocol and the Digitizer / Pen collection.
pub fn list() -> Result<Vec<HidPen>, TransportError> {
    let api = HidApi::new().map_err(|e| TransportError::Os(format!("HID enumeration: {e}")))?;
    let mut out: Vec<HidPen> = api
        .device_list()
        .filter(|d| {
            d.vendor_id() == USB_VID
                && d.product_id() == USB_PID
                && d.usage_page() == usage::PAGE_DIGITIZER
                && d.usage() == usage::PEN
        })
        .map(|d| HidPen {
            path: d.path().to_string_lossy().into_owned(),
            product: d.product_string().unwrap_or("").to_string(),
            serial: d.serial_number().map(str::to_string),
        })
        .collect();
    out.dedup_by(|a, b| a.path == b.path);
    Ok(out)
}

/// Why `path` did not open, in the OS's words once (hidapi's message repeats them): not there,
/// not this user's to open (with what to do), or hidapi's own reason.
fn open_error(path: &str, e: hidapi::HidError) -> TransportError {
    match std::fs::OpenOptions::new().read(true).write(true).open(path) {
        Err(io) if io.kind() == std::io::ErrorKind::NotFound => TransportError::NotFound(format!("{path}: {io}")),
        Err(io) if io.kind() == std::io::ErrorKind::PermissionDenied => super::denied(path),
        _ => TransportError::Os(format!("cannot open {path}: {e}")),
    }
}

/// The HID interface of one base station.
pub struct HidTransport {
    device: HidDevice,
    path: String,
    dropped: u64,
}

impl HidTransport {
    /// Opens `path`, or the first base station found.
    pub fn open(path: Option<&str>) -> Result<HidTransport, TransportError> {
        let path = match path {
            Some(p) => p.to_string(),
            None => list()?
                .into_iter()
                .next()
                .map(|p| p.path)
                .ok_or_else(|| TransportError::NotFound(format!("no HID device {USB_VID:04x}:{USB_PID:04x}")))?,
        };
        let api = HidApi::new().map_err(|e| TransportError::Os(format!("HID: {e}")))?;
        let c = CString::new(path.clone()).map_err(|_| TransportError::NotFound(format!("bad path {path:?}")))?;
        let device = api.open_path(&c).map_err(|e| open_error(&path, e))?;
        Ok(HidTransport {
            device,
            path,
            dropped: 0,
        })
    }
}

impl Transport for HidTransport {
    fn describe(&self) -> String {
        format!("hid {}", self.path)
    }

    fn read(&mut self, timeout: Duration) -> Result<Option<Message>, TransportError> {
        let mut buf = [0u8; 64];
        let n = self
            .device
            .read_timeout(&mut buf, timeout.as_millis().min(i32::MAX as u128) as i32)
            .map_err(|e| TransportError::Disconnected(e.to_string()))?;
        if n == 0 {
            return Ok(None);
        }
        match Message::decode(&buf[..n]) {
            Ok(m @ (Message::Pen(_) | Message::Tof(_) | Message::Head(_))) => Ok(Some(m)),
            // The OS's pen report, for the OS's pen stack: the pen report carries all of it.
            Ok(Message::OsPen(_)) => Ok(None),
            _ => {
                self.dropped += 1;
                Ok(None)
            }
        }
    }

    fn get_feature(&mut self, id: ReportId) -> Result<Message, TransportError> {
        let mut buf = [0u8; 256];
        buf[0] = id as u8;
        let n = self
            .device
            .get_feature_report(&mut buf)
            .map_err(|e| TransportError::Disconnected(e.to_string()))?;
        Ok(Message::decode(&buf[..n.min(buf.len())])?)
    }

    fn set_feature(&mut self, report: &Message) -> Result<Status, TransportError> {
        let mut buf = [0u8; 256];
        let n = report
            .encode(&mut buf)
            .map_err(|e| TransportError::Unexpected(e.to_string()))?;
        self.device
            .send_feature_report(&buf[..n])
            .map_err(|e| TransportError::Disconnected(e.to_string()))?;
        super::expect_status(self.get_feature(ReportId::Status)?)
    }

    fn dropped(&self) -> u64 {
        self.dropped
    }
}
