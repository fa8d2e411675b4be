//! `pen-kernel-guest STEP`: the test steps that run inside the virtual machine (hil-tests/kernel),
//! as root on Debian's kernel with uhid, hid-generic, evdev and uinput loaded and devtmpfs on
//! /dev. Each step prints `KT` lines on the console: `KT DEV …` for every evdev device of the
//! pen, `KT EVENTS …` with what was seen, and `KT PASS step: …` or `KT FAIL step: why`.
//!
//! * `uhid`: the descriptor and the firmware core's reports (`/data/reports.bin`, from the
//!   simulated pen) through `/dev/uhid`; evdev read back after every report.
//! * `pend-hid`: `pend --source hid` (hidapi's enumeration from sysfs, its hidraw reads) on the
//!   uhid device, a socket client reading its events, the device destroyed mid-stroke and
//!   created again; every event compared with what docs/events.md promises for the reports sent.
//! * `uinput-refused`: `pend --virtual-tablet` with `/dev/uinput` removed: it exits 1 at once
//!   naming the node and the udev rule, and serves nothing; the node is made again.
//! * `virtual-tablet`: `pend --virtual-tablet`, its uinput device read back through evdev.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, anyhow, bail, ensure};
use evdev::{AbsoluteAxisCode, Device, EventType, KeyCode, PropType};
use pen_host::client::{Line, parse_line};
use pen_host::events::{EventKind, PenEvent};
use pen_protocol::{
    DeviceInfo, FirmwareVersion, Message, OsPenReport, PROTOCOL_VERSION, PenReport, Report, USB_PID, USB_VID,
    os_extent, report_descriptor,
};

/// The README's pen report (`penctl decode`): SW1 and SW3, in range, (123.4, −56.7, 89.0) mm.
const README_PEN_REPORT: [u8; 17] = [
    0x01, 0x0d, 0xd2, 0x04, 0xc9, 0xfd, 0x7a, 0x03, 0x34, 0x12, 0x04, 0x03, 0x02, 0x01, 0x05, 0x07, 0x12,
];

/// The display the descriptor is built for, mm: the reference build's.
const DISPLAY_MM: [f32; 2] = [600.0, 340.0];

/// The uhid device's name; hid-input appends the collection's suffix.
const UHID_NAME: &str = "penscape base station";

mod uhid {
    //! `/dev/uhid` (linux/uhid.h): events are a `u32` type and a packed union, 4376 bytes.

    use super::*;

    pub const EVENT_LEN: usize = 4 + 4372;
    const DESTROY: u32 = 1;
    const GET_REPORT: u32 = 9;
    const GET_REPORT_REPLY: u32 = 10;
    const CREATE2: u32 = 11;
    const INPUT2: u32 = 12;
    const SET_REPORT: u32 = 13;
    const SET_REPORT_REPLY: u32 = 14;
    const BUS_USB: u16 = 0x03;
    const EIO: u16 = 5;

    /// A uhid file and the thread that answers the kernel's requests on it.
    pub struct Uhid {
        file: Arc<File>,
        /// GET_REPORT requests answered.
        pub answered: Arc<AtomicU32>,
    }

    impl Uhid {
        /// Opens `/dev/uhid` and starts answering feature-report reads with `info` (the
        /// device-information report) and every other request with EIO.
        pub fn open(info: Vec<u8>) -> Result<Uhid> {
            let file = Arc::new(
                File::options()
                    .read(true)
                    .write(true)
                    .open("/dev/uhid")
                    .context("/dev/uhid")?,
            );
            let answered = Arc::new(AtomicU32::new(0));
            let (f, count) = (file.clone(), answered.clone());
            std::thread::spawn(move || {
                let mut ev = vec![0u8; EVENT_LEN];
                while let Ok(n) = (&*f).read(&mut ev) {
                    if n < 4 {
                        continue;
                    }
                    let kind = u32::from_le_bytes([ev[0], ev[1], ev[2], ev[3]]);
                    let id = [ev[4], ev[5], ev[6], ev[7]];
                    let rnum = ev[8];
                    let mut reply = vec![0u8; EVENT_LEN];
                    match kind {
                        GET_REPORT => {
                            reply[..4].copy_from_slice(&GET_REPORT_REPLY.to_le_bytes());
                            reply[4..8].copy_from_slice(&id);
                            if rnum == info[0] {
                                reply[10..12].copy_from_slice(&(info.len() as u16).to_le_bytes());
                                reply[12..12 + info.len()].copy_from_slice(&info);
                            } else {
                                reply[8..10].copy_from_slice(&EIO.to_le_bytes());
                            }
                            count.fetch_add(1, Ordering::Relaxed);
                        }
                        SET_REPORT => {
                            reply[..4].copy_from_slice(&SET_REPORT_REPLY.to_le_bytes());
                            reply[4..8].copy_from_slice(&id);
                            reply[8..10].copy_from_slice(&EIO.to_le_bytes());
                        }
                        _ => continue,
                    }
                    let _ = (&*f).write(&reply);
                }
            });
            Ok(Uhid { file, answered })
        }

        fn send(&self, ev: &[u8]) -> Result<()> {
            let n = (&*self.file).write(ev).context("writing /dev/uhid")?;
            ensure!(n == ev.len(), "uhid took {n} of {} bytes", ev.len());
            Ok(())
        }

        /// Creates the HID device with `descriptor`, the protocol's USB IDs.
        pub fn create(&self, descriptor: &[u8]) -> Result<()> {
            let mut ev = vec![0u8; EVENT_LEN];
            ev[..4].copy_from_slice(&CREATE2.to_le_bytes());
            let p = &mut ev[4..];
            p[..UHID_NAME.len()].copy_from_slice(UHID_NAME.as_bytes());
            p[128..128 + 9].copy_from_slice(b"uhid-test");
            p[256..258].copy_from_slice(&(descriptor.len() as u16).to_le_bytes());
            p[258..260].copy_from_slice(&BUS_USB.to_le_bytes());
            p[260..264].copy_from_slice(&u32::from(USB_VID).to_le_bytes());
            p[264..268].copy_from_slice(&u32::from(USB_PID).to_le_bytes());
            p[268..272].copy_from_slice(&1u32.to_le_bytes());
            p[276..276 + descriptor.len()].copy_from_slice(descriptor);
            self.send(&ev)
        }

        /// An input report, as the device sends it on its interrupt endpoint.
        pub fn input(&self, report: &[u8]) -> Result<()> {
            let mut ev = vec![0u8; 4 + 2 + report.len()];
            ev[..4].copy_from_slice(&INPUT2.to_le_bytes());
            ev[4..6].copy_from_slice(&(report.len() as u16).to_le_bytes());
            ev[6..].copy_from_slice(report);
            self.send(&ev)
        }

        /// Destroys the device: to the host, the base station unplugged.
        pub fn destroy(&self) -> Result<()> {
            self.send(&DESTROY.to_le_bytes())
        }
    }
}

/// The reports of `/data/reports.bin`: each a length byte and the report's bytes.
fn read_reports(path: &Path) -> Result<Vec<Vec<u8>>> {
    let bytes = std::fs::read(path).with_context(|| format!("{}", path.display()))?;
    let mut out = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let len = usize::from(bytes[at]);
        let report = bytes
            .get(at + 1..at + 1 + len)
            .ok_or_else(|| anyhow!("reports.bin truncated at byte {at}"))?;
        out.push(report.to_vec());
        at += 1 + len;
    }
    Ok(out)
}

/// The device-information report the uhid device answers with.
fn device_info() -> Vec<u8> {
    let info = DeviceInfo {
        protocol: PROTOCOL_VERSION,
        firmware: FirmwareVersion {
            major: 0,
            minor: 1,
            patch: 0,
        },
        receiver_count: 4,
        max_receivers: 8,
        fix_rate_hz: 100,
        unique_id: *b"uhid-kernel\0",
    };
    let mut buf = vec![0u8; DeviceInfo::LEN];
    // The buffer has the report's length.
    let _ = info.encode(&mut buf);
    buf
}

/// Waits for the evdev devices of `name` (or the protocol's IDs when `None`) to appear and
/// settle: at least one, then nothing new for half a second.
fn settled_devices(pick: impl Fn(&Device) -> bool) -> Result<Vec<(PathBuf, Device)>> {
    let start = Instant::now();
    let mut last = 0;
    let mut since = Instant::now();
    loop {
        let now: Vec<_> = evdev::enumerate().filter(|(_, d)| pick(d)).collect();
        if now.len() != last {
            last = now.len();
            since = Instant::now();
        } else if last > 0 && since.elapsed() > Duration::from_millis(500) {
            return Ok(now);
        }
        if start.elapsed() > Duration::from_secs(10) {
            bail!("no evdev device appeared within 10 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// One evdev device as a table row.
fn describe(path: &Path, d: &Device) -> String {
    let props: Vec<String> = d.properties().iter().map(|p| format!("{p:?}")).collect();
    let keys: Vec<String> = d
        .supported_keys()
        .map(|k| k.iter().map(|k| format!("{k:?}")).collect())
        .unwrap_or_default();
    let abs: Vec<String> = d
        .get_absinfo()
        .map(|a| {
            a.map(|(code, info)| {
                format!(
                    "{code:?} {}…{} res {}",
                    info.minimum(),
                    info.maximum(),
                    info.resolution()
                )
            })
            .collect()
        })
        .unwrap_or_default();
    format!(
        "{} | {} | props {} | keys {} | abs {}",
        path.display(),
        d.name().unwrap_or("?"),
        props.join(" "),
        keys.join(" "),
        abs.join(", ")
    )
}

/// The pen's evdev state: keys pressed and axis values.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
struct PenState {
    keys: BTreeMap<u16, i32>,
    abs: BTreeMap<u16, i32>,
}

impl PenState {
    fn key(&self, k: KeyCode) -> i32 {
        self.keys.get(&k.0).copied().unwrap_or(0)
    }

    fn abs(&self, a: AbsoluteAxisCode) -> i32 {
        self.abs.get(&a.0).copied().unwrap_or(0)
    }

    /// The four buttons and X, Y: what the OS pen sets.
    fn pen_vector(&self) -> [i32; 6] {
        [
            self.key(KeyCode::BTN_TOUCH),
            self.key(KeyCode::BTN_STYLUS),
            self.key(KeyCode::BTN_STYLUS2),
            self.key(KeyCode::BTN_TOOL_PEN),
            self.abs(AbsoluteAxisCode::ABS_X),
            self.abs(AbsoluteAxisCode::ABS_Y),
        ]
    }

    /// The same buttons and axes (a code never seen reads 0).
    fn same(&self, other: &PenState) -> bool {
        self.pen_vector() == other.pen_vector()
    }

    /// The device's state now, as evdev keeps it: a reader that opens late starts from it.
    fn of_device(d: &Device) -> Result<PenState> {
        let mut s = PenState::default();
        for k in d.get_key_state()?.iter() {
            s.keys.insert(k.0, 1);
        }
        for (code, info) in d.get_absinfo()? {
            s.abs.insert(code.0, info.value());
        }
        Ok(s)
    }

    /// What the OS pen report must leave evdev in.
    fn of_report(r: &OsPenReport) -> PenState {
        let mut s = PenState::default();
        for (k, on) in [
            (KeyCode::BTN_TOUCH, r.tip),
            (KeyCode::BTN_STYLUS, r.barrel),
            (KeyCode::BTN_STYLUS2, r.secondary_barrel),
            (KeyCode::BTN_TOOL_PEN, r.in_range),
        ] {
            s.keys.insert(k.0, i32::from(on));
        }
        s.abs.insert(AbsoluteAxisCode::ABS_X.0, i32::from(r.x));
        s.abs.insert(AbsoluteAxisCode::ABS_Y.0, i32::from(r.y));
        s
    }
}

/// Transitions counted from a stream of evdev events.
#[derive(Debug, Default)]
struct Tally {
    counts: BTreeMap<String, u32>,
}

impl Tally {
    fn add(&mut self, what: String) {
        *self.counts.entry(what).or_default() += 1;
    }

    fn get(&self, what: &str) -> u32 {
        self.counts.get(what).copied().unwrap_or(0)
    }

    fn line(&self) -> String {
        self.counts
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Applies the events waiting on `d` to `state`; counts key transitions into `tally`; returns
/// how many events there were. A SYN_DROPPED (the buffer overflowed) is an error.
fn drain(d: &mut Device, state: &mut PenState, tally: &mut Tally) -> Result<usize> {
    drain_frames(d, state, tally, None, |_, _| Ok(()))
}

/// [`drain`], with `frame` called with the state at each `SYN_REPORT` and the frame's events in
/// words: a read may end inside a frame (its buffer full), so the state is whole only there.
/// Events stamped before `since` are passed over: `state` was read from the device after them
/// (the reader's queue holds what came after it opened the device, before its state was read).
fn drain_frames(
    d: &mut Device,
    state: &mut PenState,
    tally: &mut Tally,
    since: Option<std::time::SystemTime>,
    mut frame: impl FnMut(&PenState, &str) -> Result<()>,
) -> Result<usize> {
    let mut words = String::new();
    let mut n = 0;
    let events: Vec<_> = match d.fetch_events() {
        Ok(events) => events.collect(),
        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => Vec::new(),
        Err(e) => return Err(e).context("reading evdev"),
    };
    for e in events {
        if since.is_some_and(|t| e.timestamp() < t) {
            continue;
        }
        match e.event_type() {
            EventType::KEY => {
                let name = format!("{:?} {}", KeyCode(e.code()), e.value());
                words += &format!("{name}, ");
                tally.add(name);
                state.keys.insert(e.code(), e.value());
            }
            EventType::ABSOLUTE => {
                words += &format!("{:?} {}, ", AbsoluteAxisCode(e.code()), e.value());
                state.abs.insert(e.code(), e.value());
            }
            // hid-input sends the HID usage as MSC_SCAN before a button's key event.
            EventType::MISC => continue,
            EventType::SYNCHRONIZATION => {
                ensure!(e.code() != 3, "SYN_DROPPED: events were lost");
                if e.code() == 0 {
                    frame(state, &words)?;
                    words.clear();
                }
                continue;
            }
            other => bail!("unexpected {other:?} event code {}", e.code()),
        }
        n += 1;
    }
    Ok(n)
}

/// Drains `pen` into `state` and every other device; returns the events there were.
fn drain_all(pen: &mut Device, others: &mut [(PathBuf, Device)], state: &mut PenState) -> Result<usize> {
    let mut t = Tally::default();
    let mut n = drain(pen, state, &mut t)?;
    for (_, d) in others.iter_mut() {
        n += drain(d, &mut PenState::default(), &mut t)?;
    }
    Ok(n)
}

/// Step 1: the descriptor and the reports through uhid, evdev read back.
fn step_uhid() -> Result<String> {
    let reports = read_reports(Path::new("/data/reports.bin"))?;
    let extent = os_extent(DISPLAY_MM).ok_or_else(|| anyhow!("display size"))?;
    let descriptor = report_descriptor(Some(extent));
    let uhid = uhid::Uhid::open(device_info())?;
    uhid.create(descriptor.bytes())?;
    let mut pens = settled_devices(|d| d.input_id().vendor() == USB_VID && d.input_id().product() == USB_PID)?;
    for (path, d) in &pens {
        println!("KT DEV {}", describe(path, d));
    }
    let hidraw: Vec<String> = std::fs::read_dir("/dev")?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("hidraw"))
        .collect();
    println!("KT HIDRAW {}", hidraw.join(" "));
    ensure!(
        pens.len() == 1,
        "{} evdev devices for the pen, expected exactly one",
        pens.len()
    );
    let (path, mut pen) = pens.remove(0);
    let name = pen.name().unwrap_or("").to_string();
    ensure!(
        name.ends_with("Stylus"),
        "the pen is {name:?}: not the Digitizer / Pen collection's"
    );
    ensure!(pen.properties().contains(PropType::DIRECT), "no INPUT_PROP_DIRECT");
    let keys: Vec<KeyCode> = pen.supported_keys().map(|k| k.iter().collect()).unwrap_or_default();
    let want = [
        KeyCode::BTN_TOOL_PEN,
        KeyCode::BTN_TOUCH,
        KeyCode::BTN_STYLUS,
        KeyCode::BTN_STYLUS2,
    ];
    let mut sorted_want = want.to_vec();
    sorted_want.sort_by_key(|k| k.0);
    ensure!(keys == sorted_want, "keys {keys:?}, expected {sorted_want:?}");
    let abs: Vec<(AbsoluteAxisCode, i32, i32, i32)> = pen
        .get_absinfo()?
        .map(|(c, i)| (c, i.minimum(), i.maximum(), i.resolution()))
        .collect();
    let want_abs = vec![
        (AbsoluteAxisCode::ABS_X, 0, i32::from(extent[0]), 10),
        (AbsoluteAxisCode::ABS_Y, 0, i32::from(extent[1]), 10),
    ];
    ensure!(abs == want_abs, "axes {abs:?}, expected {want_abs:?}");

    // Every evdev device of the machine, to see that the 3D report makes no event anywhere.
    let mut others: Vec<(PathBuf, Device)> = evdev::enumerate().filter(|(p, _)| *p != path).collect();
    pen.set_nonblocking(true)?;
    for (_, d) in &others {
        d.set_nonblocking(true)?;
    }
    let mut state = PenState::default();
    let mut tally = Tally::default();
    drain_all(&mut pen, &mut others, &mut state)?;
    state = PenState::default();

    uhid.input(&README_PEN_REPORT)?;
    let n = drain_all(&mut pen, &mut others, &mut state)?;
    ensure!(n == 0, "the README's 3D report made {n} evdev events");

    let (mut pen_reports, mut os_reports, mut changes) = (0, 0, 0);
    let mut expected_prev = PenState::default();
    for (i, r) in reports.iter().enumerate() {
        uhid.input(r)?;
        match Message::decode(r) {
            Ok(Message::OsPen(os)) => {
                os_reports += 1;
                let n = drain(&mut pen, &mut state, &mut tally)?;
                let mut t = Tally::default();
                for (p, d) in others.iter_mut() {
                    let m = drain(d, &mut PenState::default(), &mut t)?;
                    ensure!(m == 0, "report {i} (OS pen) made {m} events on {}", p.display());
                }
                let expected = PenState::of_report(&os);
                ensure!(
                    state.same(&expected),
                    "after report {i} {os:?}: evdev {state:?}, expected {expected:?}"
                );
                if !expected.same(&expected_prev) {
                    changes += 1;
                    ensure!(n > 0, "report {i} changed the pen but made no event");
                } else {
                    ensure!(n == 0, "report {i} changed nothing but made {n} events");
                }
                expected_prev = expected;
            }
            Ok(_) => {
                pen_reports += 1;
                let n = drain_all(&mut pen, &mut others, &mut state)?;
                ensure!(n == 0, "report {i} ({:#04x}) made {n} evdev events", r[0]);
            }
            Err(e) => bail!("report {i} does not decode: {e}"),
        }
    }
    println!(
        "KT EVENTS uhid: {} reports ({os_reports} OS pen, {pen_reports} others: no event), {changes} frames; {}",
        reports.len(),
        tally.line()
    );
    // The pen comes into range and stays there at the session's end (home, over the display).
    ensure!(tally.get("BTN_TOOL_PEN 1") >= 1, "never in proximity: {}", tally.line());
    for key in ["BTN_TOUCH", "BTN_STYLUS2"] {
        ensure!(
            tally.get(&format!("{key} 1")) > 0 && tally.get(&format!("{key} 1")) == tally.get(&format!("{key} 0")),
            "{key}: {} presses, {} releases",
            tally.get(&format!("{key} 1")),
            tally.get(&format!("{key} 0"))
        );
    }
    uhid.destroy()?;
    Ok(format!(
        "one pen device {name:?}, {os_reports} OS pen reports matched, {pen_reports} others silent, {} feature reads answered",
        uhid.answered.load(Ordering::Relaxed)
    ))
}

/// An event as the test compares it: its `type`, the report's sequence number (none for the
/// events pend makes itself) and the switches after it.
type Seen = (&'static str, Option<u16>, Option<[bool; 3]>);

fn seen(e: &PenEvent) -> Seen {
    (e.kind.name(), e.seq.map(|(s, _)| s), e.sw)
}

/// The events docs/events.md promises for `reports`, sent in order to a device pend has just
/// attached (nothing pressed, out of range), written from the docs' rules, not from pend's
/// code: per report `proximity_in`; a down or up per switch changed (SW1 as `tip_*`, SW2 and
/// SW3 as `button_*`); `motion` while in range; `proximity_out`. Returns the pen's state after.
fn promised(reports: &[PenReport], out: &mut Vec<Seen>) -> (bool, [bool; 3]) {
    let (mut in_range, mut sw) = (false, [false; 3]);
    for r in reports {
        let now = [r.sw1, r.sw2, r.sw3];
        let ev = |kind| (kind, Some(r.seq), Some(now));
        if r.in_range && !in_range {
            out.push(ev("proximity_in"));
        }
        for i in 0..3 {
            if sw[i] != now[i] {
                out.push(ev(match (i, now[i]) {
                    (0, true) => "tip_down",
                    (0, false) => "tip_up",
                    (_, true) => "button_down",
                    (_, false) => "button_up",
                }));
            }
        }
        if r.in_range {
            out.push(ev("motion"));
        }
        if !r.in_range && in_range {
            out.push(ev("proximity_out"));
        }
        (in_range, sw) = (r.in_range, now);
    }
    (in_range, sw)
}

/// What the docs promise at a loss with the pen in `in_range` and `sw`: `device_lost`, then an
/// up for each switch pressed (tip first), then `proximity_out`; none has a sequence number.
fn promised_loss(in_range: bool, mut sw: [bool; 3], out: &mut Vec<Seen>) {
    out.push(("device_lost", None, None));
    for i in 0..3 {
        if sw[i] {
            sw[i] = false;
            out.push((if i == 0 { "tip_up" } else { "button_up" }, None, Some(sw)));
        }
    }
    if in_range {
        out.push(("proximity_out", None, Some(sw)));
    }
}

/// pend's socket, read on a thread: each line parsed strictly (`pen_host::client::parse_line`),
/// as every client of pend reads it.
struct SocketClient {
    lines: Receiver<Result<Line, String>>,
    hello: Option<Option<String>>,
    events: Vec<PenEvent>,
}

impl SocketClient {
    fn connect(path: &Path) -> Result<SocketClient> {
        let start = Instant::now();
        let stream = loop {
            match UnixStream::connect(path) {
                Ok(s) => break s,
                Err(e) if start.elapsed() > Duration::from_secs(20) => {
                    return Err(e).with_context(|| format!("pend's socket {}", path.display()));
                }
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        };
        stream.set_read_timeout(Some(Duration::from_secs(120)))?;
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(stream);
            loop {
                let mut line = String::new();
                let sent = match reader.read_line(&mut line) {
                    Ok(0) => tx.send(Err("pend closed the socket".into())),
                    Ok(_) => tx.send(parse_line(line.trim_end()).map_err(|e| format!("{e}"))),
                    Err(e) => tx.send(Err(format!("reading pend's socket: {e}"))),
                };
                if sent.is_err() || line.is_empty() {
                    return;
                }
            }
        });
        Ok(SocketClient {
            lines: rx,
            hello: None,
            events: Vec::new(),
        })
    }

    /// Takes the lines that came, waiting at most `wait` for the first.
    fn take(&mut self, wait: Duration) -> Result<()> {
        let mut wait = wait;
        loop {
            match self.lines.recv_timeout(wait) {
                Ok(Ok(Line::Hello { device })) => {
                    ensure!(self.hello.is_none(), "a second greeting");
                    self.hello = Some(device);
                }
                Ok(Ok(Line::Event(e))) => {
                    ensure!(self.hello.is_some(), "an event before the greeting: {e:?}");
                    self.events.push(e);
                }
                Ok(Err(why)) => bail!("{why}"),
                Err(RecvTimeoutError::Timeout) => return Ok(()),
                Err(RecvTimeoutError::Disconnected) => bail!("the socket's reader ended"),
            }
            wait = Duration::ZERO;
        }
    }

    /// Reads until `done` holds of the events, at most `limit`.
    fn until(&mut self, what: &str, limit: Duration, done: impl Fn(&[PenEvent]) -> bool) -> Result<()> {
        let start = Instant::now();
        while !done(&self.events) {
            ensure!(
                start.elapsed() < limit,
                "{what}: not within {limit:?}; the last events: {:?}",
                self.events.iter().rev().take(8).map(seen).collect::<Vec<_>>()
            );
            self.take(Duration::from_millis(20))?;
        }
        Ok(())
    }
}

/// pend's log so far.
fn pend_log(path: &str) -> String {
    std::fs::read_to_string(path).unwrap_or_default()
}

/// Waits at most `limit` for a line of pend's log after its first `after` lines to contain
/// `what`; returns that line.
fn wait_log(path: &str, after: usize, what: &str, limit: Duration) -> Result<String> {
    let start = Instant::now();
    loop {
        if let Some(l) = pend_log(path).lines().skip(after).find(|l| l.contains(what)) {
            return Ok(l.to_string());
        }
        ensure!(
            start.elapsed() < limit,
            "pend logged no {what:?} within {limit:?}:\n{}",
            pend_log(path)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// pend is still running.
fn alive(pend: &mut Child, when: &str) -> Result<()> {
    match pend.try_wait()? {
        None => Ok(()),
        Some(status) => bail!("pend exited {when}: {status}"),
    }
}

/// Sends `reports` (pen reports and the OS pen reports after them) at the device's own pace:
/// each pen report at its device time after the first's.
fn send_paced(uhid: &uhid::Uhid, reports: &[Vec<u8>]) -> Result<()> {
    // Each pen report waits its interval after the one before, as a device's do: a stall of
    // this process (one vCPU, TCG on a loaded host) delays the rest instead of sending them in a
    // burst that hidraw's 64-report queue could not hold for a reader the burst starves.
    let mut last: Option<(u32, Instant)> = None;
    for r in reports {
        if let Ok(Message::Pen(p)) = Message::decode(r) {
            if let Some((t, at)) = last {
                let due = at + Duration::from_micros(u64::from(p.timestamp_us.wrapping_sub(t)));
                if let Some(wait) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(wait);
                }
            }
            last = Some((p.timestamp_us, Instant::now()));
        }
        uhid.input(r)?;
    }
    Ok(())
}

const PEND_HID_LOG: &str = "/tmp/pend-hid.log";

/// `pend --source SOURCE --socket SOCKET`, its configuration in a folder of the guest's own.
fn pend_command(source: &str, socket: &str) -> Command {
    let mut pend = Command::new("/bin/pend");
    pend.args(["--source", source, "--socket", socket])
        .env("XDG_CONFIG_HOME", "/tmp/config");
    pend
}

/// Step 2: `pend --source hid` (hidapi's enumeration and its hidraw reads) on the uhid device,
/// a socket client, the device destroyed mid-stroke and created again.
fn step_pend_hid() -> Result<String> {
    let log = File::create(PEND_HID_LOG)?;
    // Started before the device exists: it says what it waits for. Notices every 0.5 s
    // instead of 5 s, so the wait after the loss is logged soon.
    let mut pend = pend_command("hid", "/tmp/penscape-guest/hid.sock")
        .env("PENSCAPE_NOTICE_SECS", "0.5")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log)
        .spawn()
        .context("starting pend")?;
    let result = pend_hid(&mut pend);
    // SIGTERM: pend removes its socket and exits 0.
    let stopped = Command::new("kill")
        .args(["-TERM", &pend.id().to_string()])
        .status()
        .map_err(anyhow::Error::from)
        .and_then(|_| {
            let start = Instant::now();
            loop {
                if let Some(status) = pend.try_wait()? {
                    return Ok(status);
                }
                if start.elapsed() > Duration::from_secs(10) {
                    let _ = pend.kill();
                    bail!("pend did not stop within 10 s of SIGTERM");
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        });
    for line in pend_log(PEND_HID_LOG).lines() {
        println!("KT LOG {line}");
    }
    let summary = result?;
    let status = stopped?;
    ensure!(status.success(), "pend ended {status} at SIGTERM");
    let end = wait_log(PEND_HID_LOG, 0, "pend: stopped;", Duration::from_secs(1))?;
    ensure!(end.contains(" 0 missed"), "{end}");
    Ok(summary)
}

fn pend_hid(pend: &mut Child) -> Result<String> {
    let reports = read_reports(Path::new("/data/reports.bin"))?;
    let pens: Vec<(usize, PenReport)> = reports
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match Message::decode(r) {
            Ok(Message::Pen(p)) => Some((i, p)),
            _ => None,
        })
        .collect();
    // The unplug: halfway through the first stroke, after that pen report's OS pen report.
    let down = pens
        .iter()
        .position(|(_, p)| p.sw1)
        .ok_or_else(|| anyhow!("the reports have no stroke"))?;
    let stroke = pens[down..].iter().take_while(|(_, p)| p.sw1).count();
    ensure!(stroke >= 10, "the first stroke is {stroke} reports long");
    let last_before = down + stroke / 2;
    let cut = pens.get(last_before + 1).map(|&(i, _)| i).unwrap_or(reports.len());
    let (before, after) = reports.split_at(cut);
    let pens_before: Vec<PenReport> = pens[..=last_before].iter().map(|(_, p)| *p).collect();
    let pens_after: Vec<PenReport> = pens[last_before + 1..].iter().map(|(_, p)| *p).collect();

    let mut expected: Vec<Seen> = vec![("device_found", None, None)];
    let (in_range, sw) = promised(&pens_before, &mut expected);
    ensure!(sw[0], "the unplug is not mid-stroke");
    let until_loss = expected.len();
    promised_loss(in_range, sw, &mut expected);
    let until_found = expected.len();
    expected.push(("device_found", None, None));
    promised(&pens_after, &mut expected);

    let mut client = SocketClient::connect(Path::new("/tmp/penscape-guest/hid.sock"))?;
    client.take(Duration::from_secs(5))?;
    ensure!(
        client.hello == Some(None),
        "the greeting before the device exists: {:?}",
        client.hello
    );
    let waiting = wait_log(PEND_HID_LOG, 0, "waiting for", Duration::from_secs(20))?;

    let extent = os_extent(DISPLAY_MM).ok_or_else(|| anyhow!("display size"))?;
    let descriptor = report_descriptor(Some(extent));
    let uhid = uhid::Uhid::open(device_info())?;
    uhid.create(descriptor.bytes())?;
    client.until(
        "device_found after the device was created",
        Duration::from_secs(20),
        |e| !e.is_empty(),
    )?;
    let found = match &client.events[0].kind {
        EventKind::DeviceFound { device } => device.clone(),
        other => bail!("the first event is {other:?}, not device_found"),
    };
    ensure!(found.starts_with("hid /dev/hidraw"), "attached {found:?}");

    let started = Instant::now();
    send_paced(&uhid, before)?;
    let last_seq = pens_before[last_before].seq;
    // Every report sent has reached pend before the unplug: it cannot lose what the kernel
    // still holds for it (a real unplug loses what is on the wire).
    client.until("the last report before the unplug", Duration::from_secs(20), |e| {
        e.iter().any(|e| e.seq.map(|(s, _)| s) == Some(last_seq))
    })?;
    client.take(Duration::from_millis(100))?;
    let delivered_before = client.events.len();
    ensure!(
        delivered_before == until_loss,
        "{delivered_before} events before the unplug, {until_loss} promised"
    );
    alive(pend, "before the unplug")?;
    let log_lines = pend_log(PEND_HID_LOG).lines().count();
    let unplugged = Instant::now();
    uhid.destroy()?;
    client.until("the stroke ended by the loss", Duration::from_secs(20), |e| {
        e.len() >= until_found
    })?;
    let released_in = unplugged.elapsed();
    let lost = wait_log(PEND_HID_LOG, log_lines, "device lost", Duration::from_secs(5))?;
    let still = wait_log(PEND_HID_LOG, log_lines, "still waiting", Duration::from_secs(10))?;
    alive(pend, "after the unplug")?;
    let reason = match &client.events[until_loss].kind {
        EventKind::DeviceLost { reason } => reason.clone(),
        other => bail!("the first event after the unplug is {other:?}"),
    };

    uhid.create(descriptor.bytes())?;
    client.until(
        "device_found after the device came back",
        Duration::from_secs(20),
        |e| e.len() > until_found,
    )?;
    let refound = match &client.events[until_found].kind {
        EventKind::DeviceFound { device } => device.clone(),
        other => bail!("the first event after the device came back is {other:?}"),
    };
    send_paced(&uhid, after)?;
    // Short of the promise, the comparison below says which event is missing.
    let complete = client.until("every event promised", Duration::from_secs(30), |e| {
        e.len() >= expected.len()
    });
    if complete.is_ok() {
        // Nothing more comes.
        client.take(Duration::from_millis(500))?;
    }
    alive(pend, "after the device came back")?;

    let got: Vec<Seen> = client.events.iter().map(seen).collect();
    if let Some(i) = (0..got.len().max(expected.len())).find(|&i| got.get(i) != expected.get(i)) {
        let near = |v: &[Seen]| v[i.saturating_sub(3)..(i + 3).min(v.len())].to_vec();
        bail!(
            "event {i} differs: got {:?}, promised {:?} ({} got, {} promised); got near it {:?}, promised {:?}",
            got.get(i),
            expected.get(i),
            got.len(),
            expected.len(),
            near(&got),
            near(&expected)
        );
    }
    complete?;
    let motions = |v: &[Seen]| v.iter().filter(|e| e.0 == "motion").count();
    let missed = got.iter().filter(|e| e.0 == "missed").count();
    ensure!(missed == 0, "{missed} missed");
    let answered = uhid.answered.load(Ordering::Relaxed);
    ensure!(
        answered >= 2,
        "{answered} feature reads: pend reads the device information at each attach"
    );
    uhid.destroy()?;
    println!("KT PENDLOG {waiting}");
    println!("KT PENDLOG {lost}");
    println!("KT PENDLOG {still}");
    println!(
        "KT EVENTS pend-hid: before the unplug {} pen reports → {} events ({} motions); at the unplug {}; after {} pen reports → {} events ({} motions); in {:.1} s",
        pens_before.len(),
        until_loss - 1,
        motions(&got[..until_loss]),
        got[until_loss..until_found]
            .iter()
            .map(|e| e.0)
            .collect::<Vec<_>>()
            .join(" "),
        pens_after.len(),
        got.len() - until_found - 1,
        motions(&got[until_found..]),
        started.elapsed().as_secs_f64()
    );
    Ok(format!(
        "{found}, then {refound}: {} events as promised, none missed; lost ({reason}), stroke released {} ms after the unplug; {answered} device-information reads answered",
        got.len(),
        released_in.as_millis()
    ))
}

/// Where the refusal step's pend is told to serve: it must not.
const REFUSED_SOCKET: &str = "/tmp/penscape-guest/refused.sock";

/// The uinput node as devtmpfs made it: the misc device's number (from
/// `/sys/class/misc/uinput/dev`) and its permission bits.
fn uinput_node() -> Result<(u32, u32, u32)> {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let dev = std::fs::read_to_string("/sys/class/misc/uinput/dev").context("/sys/class/misc/uinput/dev")?;
    let (major, minor) = dev
        .trim()
        .split_once(':')
        .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
        .ok_or_else(|| anyhow!("/sys/class/misc/uinput/dev reads {dev:?}"))?;
    let meta = std::fs::metadata("/dev/uinput").context("/dev/uinput before the step")?;
    ensure!(
        meta.file_type().is_char_device(),
        "/dev/uinput is not a character device"
    );
    let rdev = meta.rdev();
    // Linux's encoding of dev_t (glibc's and musl's gnu_dev_makedev).
    let (node_major, node_minor) = (
        ((rdev >> 32) & 0xffff_f000) | ((rdev >> 8) & 0xfff),
        ((rdev >> 12) & 0xffff_ff00) | (rdev & 0xff),
    );
    ensure!(
        (node_major, node_minor) == (u64::from(major), u64::from(minor)),
        "/dev/uinput is {node_major}:{node_minor}, sysfs says {major}:{minor}"
    );
    Ok((major, minor, meta.mode() & 0o7777))
}

/// Step 3: `pend --virtual-tablet` where `/dev/uinput` is not there (removed from devtmpfs; as
/// root, mode bits would not stop the open): refused at once, with the reason, nothing served.
/// The node is made again afterwards, as it was, for the virtual-tablet step.
fn step_uinput_refused() -> Result<String> {
    let (major, minor, mode) = uinput_node()?;
    std::fs::remove_file("/dev/uinput").context("removing /dev/uinput")?;
    let result = pend_refused();
    let made = Command::new("mknod")
        .args(["-m", format!("{mode:o}").as_str(), "/dev/uinput", "c"])
        .args([major.to_string(), minor.to_string()])
        .status()
        .context("running mknod");
    let summary = result?;
    let made = made?;
    ensure!(made.success(), "mknod /dev/uinput c {major} {minor}: {made}");
    ensure!(uinput_node()? == (major, minor, mode), "/dev/uinput made again differs");
    File::options()
        .read(true)
        .write(true)
        .open("/dev/uinput")
        .context("/dev/uinput made again does not open")?;
    Ok(format!(
        "{summary}; /dev/uinput made again ({major}:{minor}, mode {mode:o})"
    ))
}

fn pend_refused() -> Result<String> {
    ensure!(!Path::new("/dev/uinput").exists(), "/dev/uinput is still there");
    let started = Instant::now();
    let mut pend = pend_command("sim:draw-figures", REFUSED_SOCKET)
        .args(["--speed", "4", "--virtual-tablet"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting pend")?;
    let mut stderr = pend.stderr.take().ok_or_else(|| anyhow!("no stderr"))?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let status = loop {
        if let Some(status) = pend.try_wait()? {
            break status;
        }
        if started.elapsed() > Duration::from_secs(20) {
            let _ = pend.kill();
            let _ = pend.wait();
            bail!("pend --virtual-tablet without /dev/uinput still runs after 20 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let took = started.elapsed();
    let log = reader.join().map_err(|_| anyhow!("the stderr reader panicked"))?;
    for line in log.lines() {
        println!("KT LOG {line}");
    }
    ensure!(status.code() == Some(1), "pend ended {status}, not with exit status 1");
    ensure!(
        took < Duration::from_secs(5),
        "pend took {} ms to refuse",
        took.as_millis()
    );
    let refusal = log
        .lines()
        .find(|l| l.starts_with("pend: cannot open /dev/uinput: No such file or directory"))
        .ok_or_else(|| anyhow!("no \"pend: cannot open /dev/uinput: No such file or directory\" line"))?;
    ensure!(
        refusal.contains("host-driver/udev/70-penscape.rules"),
        "the refusal names no udev rule: {refusal}"
    );
    ensure!(!log.contains("serving"), "pend served before it refused");
    let left: Vec<String> = std::fs::read_dir("/tmp")?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("pend-refused"))
        .collect();
    ensure!(left.is_empty(), "pend left {left:?} in /tmp");
    Ok(format!(
        "exit status 1 after {} ms, /dev/uinput and host-driver/udev/70-penscape.rules named, no socket",
        took.as_millis()
    ))
}

/// Step 4: `pend --virtual-tablet` with the simulated pen drawing figures; its uinput pen read
/// back through evdev.
fn step_virtual_tablet() -> Result<String> {
    let log = File::create("/tmp/pend-vt.log")?;
    let mut pend = pend_command("sim:draw-figures", "/tmp/penscape-guest/vt.sock")
        .args(["--speed", "4", "--virtual-tablet"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(log)
        .spawn()
        .context("starting pend")?;
    let result = read_virtual_tablet();
    let _ = pend.kill();
    let _ = pend.wait();
    for line in std::fs::read_to_string("/tmp/pend-vt.log").unwrap_or_default().lines() {
        println!("KT LOG {line}");
    }
    result
}

fn read_virtual_tablet() -> Result<String> {
    let mut devices = settled_devices(|d| d.name() == Some("penscape pen"))?;
    for (path, d) in &devices {
        println!("KT DEV {}", describe(path, d));
    }
    ensure!(devices.len() == 1, "{} virtual tablets", devices.len());
    let (_, mut pen) = devices.remove(0);
    ensure!(pen.properties().contains(PropType::DIRECT), "no INPUT_PROP_DIRECT");
    let keys: Vec<KeyCode> = pen.supported_keys().map(|k| k.iter().collect()).unwrap_or_default();
    ensure!(
        keys == [
            KeyCode::BTN_TOUCH,
            KeyCode::BTN_STYLUS,
            KeyCode::BTN_STYLUS2,
            KeyCode::BTN_TOOL_PEN
        ]
        .iter()
        .copied()
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect::<Vec<_>>(),
        "keys {keys:?}"
    );
    let abs: Vec<(AbsoluteAxisCode, i32, i32, i32)> = pen
        .get_absinfo()?
        .map(|(c, i)| (c, i.minimum(), i.maximum(), i.resolution()))
        .collect();
    let want = vec![
        (AbsoluteAxisCode::ABS_X, 0, 6000, 10),
        (AbsoluteAxisCode::ABS_Y, 0, 3400, 10),
        (AbsoluteAxisCode::ABS_PRESSURE, 0, 1023, 0),
        (AbsoluteAxisCode::ABS_DISTANCE, 0, 5000, 10),
    ];
    ensure!(abs == want, "axes {abs:?}, expected {want:?}");
    pen.set_nonblocking(true)?;
    // pend moves the tablet from the start: what happened before this reader opened it is in
    // the device's state, and what the queue holds from before the state was read is not
    // applied again on top of it.
    let since = std::time::SystemTime::now();
    let mut state = PenState::of_device(&pen)?;
    let in_range_at_open = state.key(KeyCode::BTN_TOOL_PEN) == 1;
    let mut tally = Tally::default();
    let (mut frames, mut touching_moves) = (0u32, 0u32);
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(90) {
        // Each frame whole, as a program reading the tablet sees it.
        let n = drain_frames(&mut pen, &mut state, &mut tally, Some(since), |state, words| {
            frames += 1;
            let touch = state.key(KeyCode::BTN_TOUCH);
            let pressure = state.abs(AbsoluteAxisCode::ABS_PRESSURE);
            ensure!(pressure == touch * 1023, "pressure {pressure} with BTN_TOUCH {touch}");
            if touch == 1 {
                ensure!(state.key(KeyCode::BTN_TOOL_PEN) == 1, "touching out of proximity");
                ensure!(
                    state.abs(AbsoluteAxisCode::ABS_DISTANCE) == 0,
                    "a distance while touching, frame {frames}: {words}"
                );
                touching_moves += 1;
            }
            Ok(())
        })?;
        if n == 0 {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        let downs = tally.get("BTN_TOUCH 1");
        if downs >= 3 && downs == tally.get("BTN_TOUCH 0") && tally.get("BTN_STYLUS2 1") >= 3 {
            break;
        }
    }
    println!(
        "KT EVENTS virtual-tablet: {frames} frames, {touching_moves} while touching; {}",
        tally.line()
    );
    ensure!(tally.get("BTN_TOUCH 1") >= 3, "fewer than 3 strokes: {}", tally.line());
    ensure!(
        tally.get("BTN_STYLUS2 1") >= 3,
        "fewer than 3 SW3 clicks: {}",
        tally.line()
    );
    ensure!(
        in_range_at_open || tally.get("BTN_TOOL_PEN 1") >= 1,
        "never in proximity"
    );
    Ok(format!(
        "\"penscape pen\" {frames} frames, {} strokes",
        tally.get("BTN_TOUCH 1")
    ))
}

fn main() -> ExitCode {
    let step = std::env::args().nth(1).unwrap_or_default();
    let result = match step.as_str() {
        "uhid" => step_uhid(),
        "pend-hid" => step_pend_hid(),
        "uinput-refused" => step_uinput_refused(),
        "virtual-tablet" => step_virtual_tablet(),
        other => Err(anyhow!("unknown step {other:?}")),
    };
    let _ = std::io::stderr().flush();
    match result {
        Ok(summary) => {
            println!("KT PASS {step}: {summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            println!("KT FAIL {step}: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The README's report with these switches, range and sequence number.
    fn pen(seq: u16, in_range: bool, sw1: bool, sw3: bool) -> PenReport {
        let Ok(Message::Pen(readme)) = Message::decode(&README_PEN_REPORT) else {
            panic!("the README's report is a pen report");
        };
        PenReport {
            sw1,
            sw2: false,
            sw3,
            in_range,
            seq,
            ..readme
        }
    }

    #[test]
    fn the_promised_events_follow_the_docs_order() {
        let mut out = Vec::new();
        let end = promised(
            &[
                pen(1, false, false, false),
                pen(2, true, true, false),
                pen(3, true, true, true),
                pen(4, false, false, false),
            ],
            &mut out,
        );
        let on = |sw1, sw3| Some([sw1, false, sw3]);
        assert_eq!(
            out,
            [
                ("proximity_in", Some(2), on(true, false)),
                ("tip_down", Some(2), on(true, false)),
                ("motion", Some(2), on(true, false)),
                ("button_down", Some(3), on(true, true)),
                ("motion", Some(3), on(true, true)),
                ("tip_up", Some(4), on(false, false)),
                ("button_up", Some(4), on(false, false)),
                ("proximity_out", Some(4), on(false, false)),
            ]
        );
        assert_eq!(end, (false, [false; 3]));
        let mut loss = Vec::new();
        promised_loss(true, [true, false, true], &mut loss);
        assert_eq!(
            loss,
            [
                ("device_lost", None, None),
                ("tip_up", None, on(false, true)),
                ("button_up", None, on(false, false)),
                ("proximity_out", None, on(false, false)),
            ]
        );
    }
}
