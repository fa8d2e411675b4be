//! The simulated pen over a pseudo-terminal, opened with serialport exactly as a host opens
//! the base station's serial link: `pen-sim serve --pty` as a separate process.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use pen_protocol::*;

/// Kills the server when the test ends, however it ends.
struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn serve(args: &[&str]) -> (Server, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pen-sim"))
        .args(["serve", "--pty"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("pen-sim starts");
    let stdout = child.stdout.take().expect("stdout");
    let mut line = String::new();
    BufReader::new(stdout).read_line(&mut line).expect("the first line");
    (Server(child), line.trim().to_string())
}

/// A hang guard only: on a loaded machine the server may be slow, never this slow.
const GUARD: Duration = Duration::from_secs(30);

/// Reads frames until the decoded messages satisfy `done` (or [`GUARD`] passes), returning them
/// and the count of bad frames.
fn read_until(port: &mut Box<dyn serialport::SerialPort>, done: impl Fn(&[Message]) -> bool) -> (Vec<Message>, usize) {
    let mut decoder = FrameDecoder::new();
    let (mut messages, mut bad) = (Vec::new(), 0);
    let end = Instant::now() + GUARD;
    let mut buf = [0u8; 1024];
    while !done(&messages) && Instant::now() < end {
        match port.read(&mut buf) {
            Ok(n) => {
                for &b in &buf[..n] {
                    match decoder.push(b) {
                        Some(Ok(payload)) => messages.push(Message::decode(payload).expect("valid report")),
                        Some(Err(_)) => bad += 1,
                        None => {}
                    }
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("reading the pty: {e}"),
        }
    }
    (messages, bad)
}

fn pens_in(messages: &[Message]) -> usize {
    messages.iter().filter(|m| matches!(m, Message::Pen(_))).count()
}

fn send(port: &mut Box<dyn serialport::SerialPort>, m: &Message) {
    let mut payload = [0u8; MAX_PAYLOAD];
    let n = m.encode(&mut payload).expect("fits");
    let mut frame = [0u8; MAX_FRAME];
    let len = encode_frame(&payload[..n], &mut frame).expect("fits");
    port.write_all(&frame[..len]).expect("write");
}

fn open(path: &str) -> Box<dyn serialport::SerialPort> {
    serialport::new(path, 115_200)
        .timeout(Duration::from_millis(20))
        .open()
        .expect("the pty opens like a serial port")
}

#[test]
fn reports_stream_in_real_time_over_the_pty() {
    let (_server, path) = serve(&["--scenario", "hand-sweep"]);
    assert!(
        path.starts_with("/dev/pts/"),
        "first line is the device path, got {path:?}"
    );
    let mut port = open(&path);
    let (messages, bad) = read_until(&mut port, |m| pens_in(m) >= 200);
    let pens: Vec<PenReport> = messages
        .iter()
        .filter_map(|m| match m {
            Message::Pen(p) => Some(*p),
            _ => None,
        })
        .collect();
    assert_eq!(bad, 0, "no corrupted frames");
    assert!(pens.len() >= 200, "{} pen reports within {GUARD:?}", pens.len());
    // Consecutive, one fix cycle (6.5 ms, about 154 a second) apart on the device clock, in
    // range, with a quality figure. (The wall-clock rate is not asserted: a loaded machine may
    // deliver late. `pen-sim serve --pty` paces the stream; docs/simulator.md has its figure.)
    for pair in pens.windows(2) {
        assert_eq!(pair[1].seq, pair[0].seq.wrapping_add(1));
        assert_eq!(pair[1].timestamp_us.wrapping_sub(pair[0].timestamp_us), 6500);
    }
    assert!(pens.iter().filter(|p| p.in_range).count() > pens.len() * 9 / 10);
    // A fresh fix uses all four receivers; a held one (in range, no fix this cycle) none.
    assert!(
        pens.iter()
            .all(|p| !p.in_range || matches!(p.quality.receivers_used, 0 | 4))
    );
}

#[test]
fn requests_are_answered_over_the_pty() {
    let (_server, path) = serve(&["--scenario", "hold", "--speed", "2"]);
    let mut port = open(&path);
    send(
        &mut port,
        &Message::GetFeature(GetFeature {
            report: ReportId::DeviceInfo,
        }),
    );
    let (messages, _) = read_until(&mut port, |m| m.iter().any(|m| matches!(m, Message::DeviceInfo(_))));
    let info = messages
        .iter()
        .find_map(|m| match m {
            Message::DeviceInfo(i) => Some(*i),
            _ => None,
        })
        .expect("device information answered");
    assert_eq!(info.protocol, PROTOCOL_VERSION);
    assert_eq!(info.receiver_count, 4);

    // A configuration with a receiver count out of range is refused and named.
    let mut config = pen_core::default_config();
    config.receiver_count = 9;
    let mut bytes = [0u8; Config::LEN];
    config.encode(&mut bytes).expect("fits");
    let mut frame = [0u8; MAX_FRAME];
    let len = encode_frame(&bytes, &mut frame).expect("fits");
    port.write_all(&frame[..len]).expect("write");
    let (messages, _) = read_until(&mut port, |m| m.iter().any(|m| matches!(m, Message::Status(_))));
    let status = messages
        .iter()
        .find_map(|m| match m {
            Message::Status(s) => Some(*s),
            _ => None,
        })
        .expect("a status answer");
    assert_eq!(
        (status.request, status.code),
        (ReportId::Config as u8, StatusCode::Malformed)
    );

    // Garbage on the line is not answered and does not disturb the stream.
    port.write_all(&[0x13, 0x37, 0x00, 0xff, 0xfe, 0x00]).expect("write");
    let (messages, bad) = read_until(&mut port, |m| pens_in(m) >= 20);
    assert_eq!(bad, 0);
    assert!(messages.iter().any(|m| matches!(m, Message::Pen(_))));
}
