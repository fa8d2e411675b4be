//! The bench rig from the host: find it on USB, talk to it, stream a scenario's cycles to it.
//!
//! The rig (docs/hil-rig.md) drives a real base station's receiver inputs and switch lines from
//! the simulator's times of flight; the board then measures, solves and reports over its own USB
//! as it would with a pen. This module is the rig's half of that: the board's half is an ordinary
//! transport (`pen-host`). The messages and the schedule are pen-rig-proto's, shared with the
//! rig's firmware.

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use pen_protocol::MAX_RECEIVERS;
use pen_rig_proto::{
    DecodeError, Edges, ErrorCode, FrameDecoder, HostMessage, Info, MAX_FRAME, MAX_MESSAGE, RIG_PID, RIG_PRODUCT,
    RIG_PROTOCOL_VERSION, RIG_VID, RigMessage, RigStatus, ScheduleError, encode_frame, words,
};
use pen_sim::CycleRecord;
use serialport::{SerialPort, SerialPortType};

/// How long the rig may take to answer one message: it answers at once, so this only has to
/// cover USB latency and a busy host.
const ANSWER_TIMEOUT: Duration = Duration::from_millis(500);

/// What went wrong with the rig.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    /// The serial port could not be listed or opened.
    #[error("serial port: {0}")]
    Serial(#[from] serialport::Error),
    /// Reading or writing the port failed.
    #[error("rig I/O: {0}")]
    Io(#[from] std::io::Error),
    /// No answer in time.
    #[error("the rig did not answer within {0:?} (unplugged, or its firmware stopped)")]
    Timeout(Duration),
    /// The answer's payload is not a rig message.
    #[error("bad message from the rig: {0:?}")]
    Decode(DecodeError),
    /// The rig refused the message.
    #[error("the rig refused a message: {0:?}")]
    Refused(ErrorCode),
    /// Another answer than the message calls for.
    #[error("unexpected answer from the rig: {0:?}")]
    Unexpected(RigMessage),
    /// The rig's firmware speaks another version of the messages.
    #[error("the rig speaks version {0} of its messages, this host {RIG_PROTOCOL_VERSION}: flash hil-tests/rig again")]
    Version(u8),
    /// A cycle holds an arrival the rig cannot play.
    #[error("cycle {cycle}, receiver {receiver}: {error:?}")]
    Unplayable {
        /// Index of the cycle in the stream.
        cycle: usize,
        /// The receiver.
        receiver: usize,
        /// Why.
        error: ScheduleError,
    },
}

/// The line a rig test prints when it has nothing to run on, and passes.
pub fn skip_message() -> String {
    format!("skipped: no bench rig attached (USB {RIG_VID:04x}:{RIG_PID:04x}, \"{RIG_PRODUCT}\"); see docs/hil-rig.md")
}

/// The rig's serial port, if one is attached: matched by VID, PID and, where the system reports
/// it, the product string (other test devices may share pid.codes' testing PID).
pub fn find() -> Result<Option<String>, RigError> {
    Ok(serialport::available_ports()?
        .into_iter()
        .find_map(|p| match p.port_type {
            SerialPortType::UsbPort(usb)
                if usb.vid == RIG_VID
                    && usb.pid == RIG_PID
                    && usb.product.as_deref().is_none_or(|name| name.contains(RIG_PRODUCT)) =>
            {
                Some(p.port_name)
            }
            _ => None,
        }))
}

/// Switch bits as the rig and the reports carry them: SW1 = 1, SW2 = 2, SW3 = 4.
pub fn switch_bits(switches: [bool; 3]) -> u8 {
    switches.iter().enumerate().map(|(i, &on)| u8::from(on) << i).sum()
}

/// One burst's message: `arrival_ns` per receiver (after the burst's first edge, as the
/// simulator's `Heard::arrival_ns` and the board's captures count), one comparator pulse each,
/// checked playable.
pub fn cycle_message(
    index: usize,
    seq: u32,
    arrival_ns: &[Option<u32>],
    switches: [bool; 3],
) -> Result<HostMessage, RigError> {
    let edges: Vec<Edges> = arrival_ns.iter().map(|&a| Edges::arrival(a)).collect();
    pulses_message(index, seq, &edges, switches)
}

/// One burst's message with any pulses per receiver (pickup, arrivals, echoes, late edges: up
/// to `MAX_EDGES` each), checked playable; receivers past the eighth are left out.
pub fn pulses_message(index: usize, seq: u32, edges: &[Edges], switches: [bool; 3]) -> Result<HostMessage, RigError> {
    let mut all = [Edges::NONE; MAX_RECEIVERS];
    let count = edges.len().min(MAX_RECEIVERS);
    for (receiver, (slot, e)) in all.iter_mut().zip(edges).enumerate() {
        words(e).map_err(|error| RigError::Unplayable {
            cycle: index,
            receiver,
            error,
        })?;
        *slot = *e;
    }
    Ok(HostMessage::Cycle {
        seq,
        switches: switch_bits(switches),
        edges: all,
        count: count as u8,
    })
}

/// A simulation's cycles as the rig's messages, numbered from 1: what the receivers heard and
/// the switches as the hand meant them at the end of each cycle. The rig sets the switches once
/// per burst (every 6–7 ms), so the simulated bounce (sub-millisecond) is not reproduced; the
/// board's debouncing is tested on the host with the simulator.
pub fn cycles(records: &[CycleRecord], receivers: usize) -> Result<Vec<HostMessage>, RigError> {
    records
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let n = receivers.min(MAX_RECEIVERS);
            cycle_message(i, i as u32 + 1, &r.heard.arrival_ns[..n], r.intended_switches)
        })
        .collect()
}

/// An open connection to the rig.
pub struct BenchRig {
    port: Box<dyn SerialPort>,
    decoder: FrameDecoder,
    info: Info,
    name: String,
}

impl BenchRig {
    /// The attached rig, opened; `None` if there is none.
    pub fn attached() -> Result<Option<BenchRig>, RigError> {
        find()?.map(|path| BenchRig::open(&path)).transpose()
    }

    /// Opens the rig at `path` and checks that it speaks this host's messages.
    pub fn open(path: &str) -> Result<BenchRig, RigError> {
        // CDC-ACM ignores the baud rate; the timeout paces reads.
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()?;
        BenchRig::over(port, path)
    }

    /// Talks to a rig over an open port (a real one, or a pseudo-terminal in the tests).
    pub fn over(port: Box<dyn SerialPort>, name: &str) -> Result<BenchRig, RigError> {
        let mut rig = BenchRig {
            port,
            decoder: FrameDecoder::new(),
            info: Info {
                version: 0,
                receivers: 0,
                pio_hz: 0,
                queue_capacity: 0,
            },
            name: name.to_string(),
        };
        // A frame cut short by a previous session ends at our first delimiter.
        match rig.request(HostMessage::Hello)? {
            RigMessage::Info(info) if info.version == RIG_PROTOCOL_VERSION => rig.info = info,
            RigMessage::Info(info) => return Err(RigError::Version(info.version)),
            other => return Err(RigError::Unexpected(other)),
        }
        Ok(rig)
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// What the rig said it is.
    pub fn info(&self) -> Info {
        self.info
    }

    /// Sends one message and returns the rig's answer.
    fn request(&mut self, message: HostMessage) -> Result<RigMessage, RigError> {
        let mut payload = [0; MAX_MESSAGE];
        let n = message.encode(&mut payload);
        let mut frame = [0; MAX_FRAME];
        let len = encode_frame(&payload[..n], &mut frame).map_err(|_| RigError::Decode(DecodeError::Empty))?;
        self.port.write_all(&frame[..len])?;
        self.port.flush()?;
        let deadline = Instant::now() + ANSWER_TIMEOUT;
        let mut buf = [0; 64];
        loop {
            if Instant::now() > deadline {
                return Err(RigError::Timeout(ANSWER_TIMEOUT));
            }
            let got = match self.port.read(&mut buf) {
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => 0,
                Err(e) => return Err(e.into()),
            };
            for (i, &b) in buf[..got].iter().enumerate() {
                if let Some(frame) = self.decoder.push(b) {
                    // Noise on the line (a half frame from an earlier session) spoils only
                    // itself: the answer is the next intact frame.
                    let Ok(answer) = frame else { continue };
                    let answer = RigMessage::decode(answer).map_err(RigError::Decode)?;
                    // One answer per message: bytes after it belong to nothing we asked.
                    if buf[i + 1..got].iter().any(|&b| b != 0) {
                        return Err(RigError::Unexpected(answer));
                    }
                    return Ok(answer);
                }
            }
        }
    }

    /// Sends a message that the rig answers with its counters.
    fn command(&mut self, message: HostMessage) -> Result<RigStatus, RigError> {
        match self.request(message)? {
            RigMessage::Status(s) => Ok(s),
            RigMessage::Error(code) => Err(RigError::Refused(code)),
            other => Err(RigError::Unexpected(other)),
        }
    }

    /// The rig's counters.
    pub fn status(&mut self) -> Result<RigStatus, RigError> {
        self.command(HostMessage::Status)
    }

    /// Empties the rig's queue and releases the switches; the counters start again.
    pub fn stop(&mut self) -> Result<RigStatus, RigError> {
        self.command(HostMessage::Stop)
    }

    /// Sets SW1–SW3 at once (true = pressed).
    pub fn set_switches(&mut self, switches: [bool; 3]) -> Result<RigStatus, RigError> {
        self.command(HostMessage::Switches(switch_bits(switches)))
    }

    /// Queues one cycle, waiting while the rig's queue is full.
    pub fn send(&mut self, cycle: HostMessage) -> Result<RigStatus, RigError> {
        loop {
            match self.command(cycle) {
                // At ~150 bursts/s a slot frees every ~7 ms.
                Err(RigError::Refused(ErrorCode::QueueFull)) => std::thread::sleep(Duration::from_millis(3)),
                other => return other,
            }
        }
    }

    /// Streams `cycles`, one per burst of the board, and returns the counters once the last one
    /// has played (or `timeout` passed).
    pub fn stream(&mut self, cycles: &[HostMessage], timeout: Duration) -> Result<RigStatus, RigError> {
        let start = Instant::now();
        for &c in cycles {
            self.send(c)?;
        }
        let last = match cycles.last() {
            Some(HostMessage::Cycle { seq, .. }) => *seq,
            _ => return self.status(),
        };
        loop {
            let s = self.status()?;
            if s.last_played == last || start.elapsed() > timeout {
                return Ok(s);
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pen_rig_proto::Edge;
    use pen_sim::{Simulation, scenarios};

    #[test]
    fn switch_bits_are_the_reports() {
        assert_eq!(switch_bits([false; 3]), 0);
        assert_eq!(switch_bits([true, false, false]), 1);
        assert_eq!(switch_bits([false, true, true]), 6);
    }

    #[test]
    fn a_scenario_becomes_the_cycles_it_heard() {
        let scenario = scenarios::by_name("echoes").unwrap();
        let receivers = scenario.rig.receivers_mm.len();
        let records = Simulation::new(&scenario, 7).run_for(0.5);
        let messages = cycles(&records, receivers).unwrap();
        assert_eq!(messages.len(), records.len());
        let mut dropouts = 0;
        for (i, (m, r)) in messages.iter().zip(&records).enumerate() {
            let HostMessage::Cycle {
                seq,
                switches,
                edges,
                count,
            } = *m
            else {
                panic!("not a cycle: {m:?}");
            };
            assert_eq!(seq, i as u32 + 1);
            assert_eq!(usize::from(count), receivers);
            assert_eq!(switches, switch_bits(r.intended_switches));
            for (e, a) in edges[..receivers].iter().zip(&r.heard.arrival_ns[..receivers]) {
                // One comparator pulse per arrival, as long as the burst's envelope.
                assert_eq!(*e, Edges::arrival(*a));
                assert_eq!(e.first_ns(), *a);
            }
            dropouts += edges[..receivers].iter().filter(|e| e.first_ns().is_none()).count();
        }
        // The scenario drops 2 % of arrivals: the stream carries them as "heard nothing".
        assert!(dropouts > 0, "no dropout in {} cycles", records.len());
    }

    /// A rig in software on the far side of a pseudo-terminal: it answers as the firmware does
    /// (pen-rig-proto's messages in the base station's frames), refuses each cycle once with
    /// QueueFull, and puts line noise before its first answer. Returns the cycles it queued.
    fn software_rig(mut port: serialport::TTYPort, version: u8) -> std::thread::JoinHandle<Vec<u32>> {
        std::thread::spawn(move || {
            let mut decoder = FrameDecoder::new();
            let mut status = RigStatus::default();
            let mut queued = Vec::new();
            let mut refused = None;
            let mut noise = true;
            let mut buf = [0; 64];
            loop {
                let n = match port.read(&mut buf) {
                    Ok(0) => return queued,
                    Ok(n) => n,
                    Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
                    Err(_) => return queued,
                };
                for &b in &buf[..n] {
                    let Some(frame) = decoder.push(b) else { continue };
                    let answer = match HostMessage::decode(frame.unwrap()).unwrap() {
                        HostMessage::Hello => RigMessage::Info(Info {
                            version,
                            receivers: 8,
                            pio_hz: 125_000_000,
                            queue_capacity: 64,
                        }),
                        HostMessage::Cycle { seq, .. } if refused != Some(seq) => {
                            refused = Some(seq);
                            RigMessage::Error(ErrorCode::QueueFull)
                        }
                        HostMessage::Cycle { seq, .. } => {
                            queued.push(seq);
                            status.played += 1;
                            status.last_played = seq;
                            RigMessage::Status(status)
                        }
                        _ => RigMessage::Status(status),
                    };
                    let mut payload = [0; MAX_MESSAGE];
                    let len = answer.encode(&mut payload);
                    let mut out = [0; MAX_FRAME];
                    let len = encode_frame(&payload[..len], &mut out).unwrap();
                    if std::mem::take(&mut noise) {
                        // A half frame left over from an earlier session, then the answer.
                        port.write_all(&[0x13, 0x37, 0x42]).unwrap();
                    }
                    if port.write_all(&out[..len]).is_err() {
                        return queued;
                    }
                }
            }
        })
    }

    #[test]
    fn the_host_side_streams_to_a_rig_over_a_serial_line() {
        let (host, mut far) = serialport::TTYPort::pair().expect("a pseudo-terminal pair");
        far.set_timeout(Duration::from_millis(20)).unwrap();
        let rig_thread = software_rig(far, RIG_PROTOCOL_VERSION);
        let mut rig = BenchRig::over(Box::new(host), "pty").expect("the rig answers Hello");
        assert_eq!(rig.info().queue_capacity, 64);
        let stream: Vec<HostMessage> = (1..=20)
            .map(|seq| {
                cycle_message(
                    0,
                    seq,
                    &[Some(400_000), None, Some(1_200_000)],
                    [seq % 2 == 0, false, false],
                )
                .unwrap()
            })
            .collect();
        // Each cycle is refused once (queue full) and sent again: all twenty arrive, in order.
        let status = rig.stream(&stream, Duration::from_secs(5)).expect("the stream plays");
        assert_eq!(status.last_played, 20);
        assert_eq!(status.played, 20);
        drop(rig);
        assert_eq!(rig_thread.join().unwrap(), (1..=20).collect::<Vec<u32>>());
    }

    #[test]
    fn a_rig_of_another_version_is_refused() {
        let (host, mut far) = serialport::TTYPort::pair().expect("a pseudo-terminal pair");
        far.set_timeout(Duration::from_millis(20)).unwrap();
        let _rig_thread = software_rig(far, RIG_PROTOCOL_VERSION + 1);
        match BenchRig::over(Box::new(host), "pty") {
            Err(RigError::Version(v)) => assert_eq!(v, RIG_PROTOCOL_VERSION + 1),
            Err(e) => panic!("wrong error: {e}"),
            Ok(_) => panic!("a rig of another version was accepted"),
        }
    }

    #[test]
    fn an_arrival_the_rig_cannot_play_is_refused_before_sending() {
        let late = pen_rig_proto::schedule::MAX_END_NS - pen_rig_proto::schedule::PULSE_NS + 8;
        let err = cycle_message(3, 4, &[Some(1_000_000), Some(late)], [false; 3]).unwrap_err();
        assert!(
            matches!(
                err,
                RigError::Unplayable {
                    cycle: 3,
                    receiver: 1,
                    ..
                }
            ),
            "{err}"
        );
        assert!(cycle_message(0, 1, &[None, Some(300_000)], [true, false, false]).is_ok());
        // Several pulses on one receiver: out of order is refused, naming the receiver.
        let backwards = Edges::new(&[Edge::arrival(2_000_000), Edge::arrival(1_000_000)]).unwrap();
        let err = pulses_message(5, 6, &[Edges::NONE, Edges::NONE, backwards], [false; 3]).unwrap_err();
        assert!(
            matches!(
                err,
                RigError::Unplayable {
                    cycle: 5,
                    receiver: 2,
                    error: ScheduleError::TooClose { at_ns: 1_000_000 }
                }
            ),
            "{err}"
        );
    }
}
