//! The USB side: feature reports over HID control transfers, reports out over the HID interrupt
//! endpoint and the CDC-ACM serial link, requests in over the serial link, suspend and resume.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use defmt::{info, warn};
use embassy_futures::select::select;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::ThreadModeRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;
use embassy_usb::Handler;
use embassy_usb::class::cdc_acm::{ControlChanged, Receiver, Sender};
use embassy_usb::class::hid::{HidWriter, ReportId as HidReportId, RequestHandler};
use embassy_usb::control::OutResponse;
use embassy_usb::driver::Driver;
use pen_core::{Action, LogStore, ReportSink, SharedEngine};
use pen_protocol::{
    FrameDecoder, HeadReport, MAX_FRAME, MAX_PAYLOAD, OsPenReport, PenReport, Report, TofReport, encode_frame,
};

use crate::flash_store::ConfigSector;

/// The engine, shared by the station and the request handlers.
pub type Engine = SharedEngine<ThreadModeRawMutex>;
/// The configuration store, shared by the request handlers.
pub type Store<'d> = Mutex<ThreadModeRawMutex, RefCell<LogStore<ConfigSector<'d>>>>;

/// Largest input report (time of flight), the HID endpoint's packet size.
pub const HID_PACKET: usize = 64;

/// An input report for the HID endpoint.
pub struct HidPacket {
    len: usize,
    buf: [u8; HID_PACKET],
}

/// A framed report for the serial link.
pub struct SerialFrame {
    len: usize,
    buf: [u8; MAX_FRAME],
}

/// Reports waiting for the HID endpoint: the pen and the OS pen report of each cycle, and the
/// head report of each head slot.
pub type HidQueue = Channel<ThreadModeRawMutex, HidPacket, 16>;
/// Frames waiting for the serial link.
pub type SerialQueue = Channel<ThreadModeRawMutex, SerialFrame, 8>;

/// Reports dropped because a host did not read them fast enough.
pub static DROPPED_HID: AtomicU32 = AtomicU32::new(0);
/// Frames dropped because the serial host did not read them fast enough.
pub static DROPPED_SERIAL: AtomicU32 = AtomicU32::new(0);
/// Frames from the host that failed COBS or the CRC.
pub static BAD_FRAMES: AtomicU32 = AtomicU32::new(0);

/// Set while the bus is suspended: the station stops firing bursts.
pub static SUSPENDED: AtomicBool = AtomicBool::new(false);
/// Set while the host has configured the device: only then may it draw its declared current.
pub static CONFIGURED: AtomicBool = AtomicBool::new(false);
/// Raised by the station when SW1 is pressed during suspend: wake the host.
pub static WAKE_HOST: Signal<ThreadModeRawMutex, ()> = Signal::new();
/// Raised when a request asked for the bootloader; main restarts once the answer is out.
pub static BOOTLOADER: Signal<ThreadModeRawMutex, ()> = Signal::new();
/// Raised when a saved configuration needs a new USB descriptor; main restarts once the answer
/// is out.
pub static RESTART: Signal<ThreadModeRawMutex, ()> = Signal::new();

fn act(action: Option<Action>) {
    match action {
        Some(Action::EnterBootloader) => BOOTLOADER.signal(()),
        Some(Action::Restart) => RESTART.signal(()),
        None => {}
    }
}

/// Answers HID GET_REPORT and SET_REPORT for the feature reports.
pub struct FeatureHandler<'a, 'd> {
    pub engine: &'a Engine,
    pub store: &'a Store<'d>,
}

impl RequestHandler for FeatureHandler<'_, '_> {
    fn get_report(&mut self, id: HidReportId, buf: &mut [u8]) -> Option<usize> {
        match id {
            HidReportId::Feature(id) => self.engine.lock(|e| e.borrow().get_feature(id, buf)),
            _ => None,
        }
    }

    fn set_report(&mut self, id: HidReportId, data: &[u8]) -> OutResponse {
        let HidReportId::Feature(_) = id else {
            return OutResponse::Rejected;
        };
        let (status, action) = self.store.lock(|s| {
            self.engine
                .lock(|e| e.borrow_mut().set_feature(data, &mut *s.borrow_mut()))
        });
        info!("feature report written: {}", status);
        act(action);
        // The status report tells the host why a write was refused; the transfer itself
        // succeeds so that hosts read it rather than retry.
        OutResponse::Accepted
    }
}

/// Tracks the bus state for the station.
pub struct BusState;

impl Handler for BusState {
    fn suspended(&mut self, suspended: bool) {
        SUSPENDED.store(suspended, Ordering::Relaxed);
        info!("USB {}", if suspended { "suspended" } else { "resumed" });
    }

    fn configured(&mut self, configured: bool) {
        CONFIGURED.store(configured, Ordering::Relaxed);
        info!("USB {}", if configured { "configured" } else { "not configured" });
    }
}

/// Sends reports to the HID queue, and to the serial queue while a host has the port open.
pub struct BoardSink<'a, 'd> {
    pub hid: &'a HidQueue,
    pub serial: &'a SerialQueue,
    pub serial_control: &'a ControlChanged<'d>,
}

impl BoardSink<'_, '_> {
    fn send_hid<R: Report>(&mut self, report: &R) {
        let mut packet = HidPacket {
            len: 0,
            buf: [0; HID_PACKET],
        };
        if let Ok(len) = report.encode(&mut packet.buf) {
            packet.len = len;
            if self.hid.try_send(packet).is_err() {
                DROPPED_HID.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    fn send<R: Report>(&mut self, report: &R) {
        self.send_hid(report);
        if self.serial_control.dtr() {
            let mut payload = [0u8; HID_PACKET];
            let mut frame = SerialFrame {
                len: 0,
                buf: [0; MAX_FRAME],
            };
            if let Ok(n) = report.encode(&mut payload)
                && let Ok(len) = encode_frame(&payload[..n], &mut frame.buf)
            {
                frame.len = len;
                if self.serial.try_send(frame).is_err() {
                    DROPPED_SERIAL.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    }
}

impl ReportSink for BoardSink<'_, '_> {
    async fn pen(&mut self, report: &PenReport) {
        self.send(report);
    }

    async fn tof(&mut self, report: &TofReport) {
        self.send(report);
    }

    /// HID only: the serial link's host reads the project's own reports.
    async fn os_pen(&mut self, report: &OsPenReport) {
        self.send_hid(report);
    }

    /// The vendor collection's head report on HID, and the same bytes framed on the serial link.
    async fn head(&mut self, report: &HeadReport) {
        self.send(report);
    }
}

/// Writes queued reports to the HID interrupt endpoint.
pub async fn hid_writer<'d, D: Driver<'d>>(mut writer: HidWriter<'d, D, HID_PACKET>, queue: &HidQueue) -> ! {
    loop {
        // Before the host configures the device the endpoint is disabled and every write fails
        // at once: wait for it instead of failing (and logging) 150–300 times a second. Reports
        // queued meanwhile are dropped and counted by the sink.
        writer.ready().await;
        let packet = queue.receive().await;
        if let Err(e) = writer.write(&packet.buf[..packet.len]).await {
            warn!("HID report not sent: {}", e);
        }
    }
}

/// Writes queued frames to the serial link in packets, to the session that queued them. When
/// the host closes the port (DTR drops) the frame being written is abandoned; when one opens it,
/// whatever is still queued belongs to the last session and is dropped (and counted), so the
/// first frames a new session reads are fresh, not reports up to 8 frames old.
pub async fn serial_writer<'d, D: Driver<'d>>(
    mut sender: Sender<'d, D>,
    control: &ControlChanged<'_>,
    queue: &SerialQueue,
) -> ! {
    loop {
        while !control.dtr() {
            control.control_changed().await;
        }
        let stale = queue.len() as u32;
        queue.clear();
        DROPPED_SERIAL.fetch_add(stale, Ordering::Relaxed);
        let closed = async {
            loop {
                control.control_changed().await;
                if !control.dtr() {
                    break;
                }
            }
        };
        let session = async {
            loop {
                let frame = queue.receive().await;
                write_frame(&mut sender, &frame).await;
            }
        };
        // The session never ends by itself: this returns when the port closes.
        select(closed, session).await;
    }
}

/// One frame in packets; a failed packet counts the frame as dropped.
async fn write_frame<'d, D: Driver<'d>>(sender: &mut Sender<'d, D>, frame: &SerialFrame) {
    let packet = sender.max_packet_size() as usize;
    let bytes = &frame.buf[..frame.len];
    let mut ok = true;
    for chunk in bytes.chunks(packet) {
        ok &= sender.write_packet(chunk).await.is_ok();
    }
    // A transfer that ends on a full packet needs a zero-length packet to end it.
    if bytes.len().is_multiple_of(packet) {
        ok &= sender.write_packet(&[]).await.is_ok();
    }
    if !ok {
        DROPPED_SERIAL.fetch_add(1, Ordering::Relaxed);
    }
}

/// Reads requests from the serial link and queues the answers.
pub async fn serial_reader<'d, D: Driver<'d>>(
    mut receiver: Receiver<'d, D>,
    engine: &Engine,
    store: &Store<'_>,
    queue: &SerialQueue,
) -> ! {
    let mut decoder = FrameDecoder::new();
    let mut packet = [0u8; 64];
    loop {
        receiver.wait_connection().await;
        let Ok(n) = receiver.read_packet(&mut packet).await else {
            continue;
        };
        for &byte in &packet[..n] {
            let Some(frame) = decoder.push(byte) else { continue };
            let Ok(request) = frame else {
                BAD_FRAMES.fetch_add(1, Ordering::Relaxed);
                continue;
            };
            let mut answer = [0u8; MAX_PAYLOAD];
            let (len, action) = store.lock(|s| {
                engine.lock(|e| {
                    e.borrow_mut()
                        .handle_request(request, &mut answer, &mut *s.borrow_mut())
                })
            });
            if let Some(len) = len {
                let mut frame = SerialFrame {
                    len: 0,
                    buf: [0; MAX_FRAME],
                };
                if let Ok(flen) = encode_frame(&answer[..len], &mut frame.buf) {
                    frame.len = flen;
                    queue.send(frame).await;
                }
            }
            act(action);
        }
    }
}
