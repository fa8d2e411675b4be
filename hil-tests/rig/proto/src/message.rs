//! The messages between the host and the rig, over the rig's USB serial port (CDC-ACM).
//!
//! Each message is one frame of the base station's serial framing (`pen_protocol::encode_frame`:
//! COBS, CRC-32, 0x00 delimiters) whose payload starts with the message's type byte; integers
//! are little-endian. Host to rig: [`HostMessage`]; rig to host: [`RigMessage`]. The rig answers
//! every host message with exactly one rig message, so the host paces itself by the answers
//! and learns from each [`RigStatus`] how full the rig's queue is.

use crate::RECEIVERS;
use crate::schedule::{Edge, Edges, MAX_EDGES};

/// The largest payload of either direction (a cycle with every receiver's every pulse).
pub const MAX_MESSAGE: usize = 7 + (1 + 8 * MAX_EDGES) * RECEIVERS;
// One frame of the base station's framing carries it.
const _: () = assert!(MAX_MESSAGE <= pen_protocol::MAX_PAYLOAD);

/// Switch bits as the base station's reports carry them: SW1 (tip) = 1, SW2 = 2, SW3 = 4.
pub const SWITCH_MASK: u8 = 0b111;

/// From the host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[allow(
    clippy::large_enum_variant,
    reason = "no_std without an allocator: a cycle (~200 bytes) cannot be boxed, and one message is decoded at a time"
)]
pub enum HostMessage {
    /// Who is there: the rig answers [`RigMessage::Info`].
    Hello,
    /// One burst's worth: queued, played at the next burst whose predecessor has been played.
    Cycle {
        /// The host's count, echoed in [`RigStatus::last_played`].
        seq: u32,
        /// Switch lines to hold from that burst on (bits as [`SWITCH_MASK`]).
        switches: u8,
        /// Each receiver's pulses, rises in ns after the burst's first rising edge (none:
        /// heard nothing). Receivers past `count` hear nothing.
        edges: [Edges; RECEIVERS],
        /// Receivers carried on the wire.
        count: u8,
    },
    /// Sets the switch lines now (pressed = pulled low), outside any cycle: suspend and wake.
    Switches(u8),
    /// Empties the queue, releases the switches, zeroes the play counters; the receivers hear
    /// nothing until new cycles (but the cycle already handed to the state machines).
    Stop,
    /// The rig's counters: the rig answers [`RigMessage::Status`].
    Status,
}

/// What the rig is and can do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Info {
    /// [`crate::RIG_PROTOCOL_VERSION`] of the firmware.
    pub version: u8,
    /// Receiver inputs driven.
    pub receivers: u8,
    /// The PIO clock, Hz (the schedule's resolution is its period).
    pub pio_hz: u32,
    /// Cycles queued at most.
    pub queue_capacity: u16,
}

/// The rig's counters: `bursts` and `bad_frames` since start-up, the others since the last
/// [`HostMessage::Stop`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RigStatus {
    /// Bursts seen on the emitter pin.
    pub bursts: u32,
    /// Cycles played.
    pub played: u32,
    /// Bursts that found no cycle queued (the host fell behind): every receiver heard nothing.
    pub underruns: u32,
    /// Cycles waiting.
    pub queued: u16,
    /// `seq` of the last cycle played (0 before the first).
    pub last_played: u32,
    /// Frames dropped: bad CRC or COBS, unknown or malformed messages.
    pub bad_frames: u32,
}

/// Why the rig refused a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum ErrorCode {
    /// The frame or the message did not decode.
    Malformed = 1,
    /// The queue is full: the cycle was not queued; send it again after a status shows room.
    QueueFull = 2,
    /// An arrival outside what the state machine can play (`schedule::word` failed).
    Unplayable = 3,
}

/// From the rig.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RigMessage {
    /// The answer to [`HostMessage::Hello`].
    Info(Info),
    /// The answer to every other message that succeeded.
    Status(RigStatus),
    /// The answer to a message that did not.
    Error(ErrorCode),
}

/// Why a payload is not a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// No type byte.
    Empty,
    /// A type byte this version does not know.
    UnknownType(u8),
    /// Shorter or longer than its type says.
    Length {
        /// Type byte.
        kind: u8,
        /// Bytes received.
        len: usize,
    },
    /// A field out of its range (a receiver count, switch bits, an error code).
    Field(&'static str),
}

mod kind {
    pub const HELLO: u8 = 0x01;
    pub const CYCLE: u8 = 0x02;
    pub const SWITCHES: u8 = 0x03;
    pub const STOP: u8 = 0x04;
    pub const STATUS: u8 = 0x05;
    pub const INFO: u8 = 0x81;
    pub const RIG_STATUS: u8 = 0x85;
    pub const ERROR: u8 = 0x8F;
}

/// Appends little-endian fields to a fixed buffer; the buffer is [`MAX_MESSAGE`] long, which
/// every message fits by construction.
struct Out<'a> {
    buf: &'a mut [u8; MAX_MESSAGE],
    len: usize,
}

impl Out<'_> {
    fn put(&mut self, bytes: &[u8]) {
        self.buf[self.len..self.len + bytes.len()].copy_from_slice(bytes);
        self.len += bytes.len();
    }
}

/// Reads little-endian fields; `None` past the end.
struct In<'a>(&'a [u8]);

impl In<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.0.split_first_chunk::<N>()?;
        self.0 = rest;
        Some(*head)
    }
    fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }
    fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_le_bytes)
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }
}

/// Decodes a whole payload with `f`, which must consume it exactly.
fn whole<T>(payload: &[u8], f: impl FnOnce(&mut In) -> Result<Option<T>, DecodeError>) -> Result<T, DecodeError> {
    let (&kind, body) = payload.split_first().ok_or(DecodeError::Empty)?;
    let length = DecodeError::Length {
        kind,
        len: payload.len(),
    };
    let mut input = In(body);
    let value = f(&mut input)?.ok_or(length)?;
    if !input.0.is_empty() {
        return Err(length);
    }
    Ok(value)
}

impl HostMessage {
    /// The payload; returns its length.
    pub fn encode(&self, buf: &mut [u8; MAX_MESSAGE]) -> usize {
        let mut out = Out { buf, len: 0 };
        match *self {
            HostMessage::Hello => out.put(&[kind::HELLO]),
            HostMessage::Cycle {
                seq,
                switches,
                ref edges,
                count,
            } => {
                out.put(&[kind::CYCLE]);
                out.put(&seq.to_le_bytes());
                out.put(&[switches, count]);
                for e in edges.iter().take(usize::from(count)) {
                    out.put(&[e.as_slice().len() as u8]);
                    for edge in e.as_slice() {
                        out.put(&edge.at_ns.to_le_bytes());
                        out.put(&edge.length_ns.to_le_bytes());
                    }
                }
            }
            HostMessage::Switches(bits) => out.put(&[kind::SWITCHES, bits]),
            HostMessage::Stop => out.put(&[kind::STOP]),
            HostMessage::Status => out.put(&[kind::STATUS]),
        }
        out.len
    }

    /// A payload as a message.
    pub fn decode(payload: &[u8]) -> Result<HostMessage, DecodeError> {
        let kind = payload.first().copied().ok_or(DecodeError::Empty)?;
        whole(payload, |input| {
            Ok(match kind {
                kind::HELLO => Some(HostMessage::Hello),
                kind::STOP => Some(HostMessage::Stop),
                kind::STATUS => Some(HostMessage::Status),
                kind::SWITCHES => match input.u8() {
                    Some(bits) if bits & !SWITCH_MASK != 0 => return Err(DecodeError::Field("switches")),
                    bits => bits.map(HostMessage::Switches),
                },
                kind::CYCLE => {
                    let (Some(seq), Some(switches), Some(count)) = (input.u32(), input.u8(), input.u8()) else {
                        return Ok(None);
                    };
                    if switches & !SWITCH_MASK != 0 {
                        return Err(DecodeError::Field("switches"));
                    }
                    if usize::from(count) > RECEIVERS {
                        return Err(DecodeError::Field("count"));
                    }
                    let mut edges = [Edges::NONE; RECEIVERS];
                    for e in edges.iter_mut().take(usize::from(count)) {
                        let Some(n) = input.u8() else { return Ok(None) };
                        let mut list = [Edge::default(); MAX_EDGES];
                        let Some(list) = list.get_mut(..usize::from(n)) else {
                            return Err(DecodeError::Field("edges"));
                        };
                        for edge in list.iter_mut() {
                            let (Some(at_ns), Some(length_ns)) = (input.u32(), input.u32()) else {
                                return Ok(None);
                            };
                            *edge = Edge { at_ns, length_ns };
                        }
                        // At most MAX_EDGES, as checked just above.
                        *e = Edges::new(list).ok_or(DecodeError::Field("edges"))?;
                    }
                    Some(HostMessage::Cycle {
                        seq,
                        switches,
                        edges,
                        count,
                    })
                }
                other => return Err(DecodeError::UnknownType(other)),
            })
        })
    }
}

impl RigMessage {
    /// The payload; returns its length.
    pub fn encode(&self, buf: &mut [u8; MAX_MESSAGE]) -> usize {
        let mut out = Out { buf, len: 0 };
        match *self {
            RigMessage::Info(i) => {
                out.put(&[kind::INFO, i.version, i.receivers]);
                out.put(&i.pio_hz.to_le_bytes());
                out.put(&i.queue_capacity.to_le_bytes());
            }
            RigMessage::Status(s) => {
                out.put(&[kind::RIG_STATUS]);
                out.put(&s.bursts.to_le_bytes());
                out.put(&s.played.to_le_bytes());
                out.put(&s.underruns.to_le_bytes());
                out.put(&s.queued.to_le_bytes());
                out.put(&s.last_played.to_le_bytes());
                out.put(&s.bad_frames.to_le_bytes());
            }
            RigMessage::Error(code) => out.put(&[kind::ERROR, code as u8]),
        }
        out.len
    }

    /// A payload as a message.
    pub fn decode(payload: &[u8]) -> Result<RigMessage, DecodeError> {
        let kind = payload.first().copied().ok_or(DecodeError::Empty)?;
        whole(payload, |input| {
            Ok(match kind {
                kind::INFO => (|| {
                    Some(RigMessage::Info(Info {
                        version: input.u8()?,
                        receivers: input.u8()?,
                        pio_hz: input.u32()?,
                        queue_capacity: input.u16()?,
                    }))
                })(),
                kind::RIG_STATUS => (|| {
                    Some(RigMessage::Status(RigStatus {
                        bursts: input.u32()?,
                        played: input.u32()?,
                        underruns: input.u32()?,
                        queued: input.u16()?,
                        last_played: input.u32()?,
                        bad_frames: input.u32()?,
                    }))
                })(),
                kind::ERROR => match input.u8() {
                    None => None,
                    Some(1) => Some(RigMessage::Error(ErrorCode::Malformed)),
                    Some(2) => Some(RigMessage::Error(ErrorCode::QueueFull)),
                    Some(3) => Some(RigMessage::Error(ErrorCode::Unplayable)),
                    Some(_) => return Err(DecodeError::Field("error code")),
                },
                other => return Err(DecodeError::UnknownType(other)),
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pen_protocol::{FrameDecoder, MAX_FRAME, encode_frame};

    /// Encodes, frames, unframes and decodes: the path the bytes take over USB.
    fn through_the_wire_host(m: HostMessage) -> HostMessage {
        let mut payload = [0; MAX_MESSAGE];
        let n = m.encode(&mut payload);
        let mut frame = [0; MAX_FRAME];
        let len = encode_frame(&payload[..n], &mut frame).unwrap();
        let mut dec = FrameDecoder::new();
        let mut got = None;
        for &b in &frame[..len] {
            if let Some(r) = dec.push(b) {
                got = Some(HostMessage::decode(r.unwrap()).unwrap());
            }
        }
        got.unwrap()
    }

    fn cycle(count: u8) -> HostMessage {
        let mut edges = [Edges::NONE; RECEIVERS];
        for (i, e) in edges.iter_mut().enumerate().take(usize::from(count)) {
            // A dropout at receiver 2, pickup and an echo around receiver 3's arrival; zeros
            // in the times, which COBS must carry.
            *e = match i {
                2 => Edges::NONE,
                3 => Edges::new(&[
                    Edge {
                        at_ns: 20_000,
                        length_ns: 100_000,
                    },
                    Edge::arrival(1_000_000 + i as u32 * 256),
                    Edge::arrival(1_600_000),
                ])
                .unwrap(),
                _ => Edges::arrival(Some(1_000_000 + i as u32 * 256)),
            };
        }
        HostMessage::Cycle {
            seq: 0x0100_00FF,
            switches: 0b101,
            edges,
            count,
        }
    }

    #[test]
    fn host_messages_survive_the_wire() {
        for m in [
            HostMessage::Hello,
            HostMessage::Stop,
            HostMessage::Status,
            HostMessage::Switches(0b010),
            cycle(0),
            cycle(4),
            cycle(RECEIVERS as u8),
        ] {
            assert_eq!(through_the_wire_host(m), m);
        }
    }

    #[test]
    fn rig_messages_survive_encoding() {
        let status = RigStatus {
            bursts: 1,
            played: 0x0102_0304,
            underruns: 7,
            queued: 300,
            last_played: u32::MAX - 1,
            bad_frames: 0,
        };
        let info = Info {
            version: crate::RIG_PROTOCOL_VERSION,
            receivers: RECEIVERS as u8,
            pio_hz: crate::schedule::PIO_HZ,
            queue_capacity: 64,
        };
        for m in [
            RigMessage::Status(status),
            RigMessage::Info(info),
            RigMessage::Error(ErrorCode::Malformed),
            RigMessage::Error(ErrorCode::QueueFull),
            RigMessage::Error(ErrorCode::Unplayable),
        ] {
            let mut buf = [0; MAX_MESSAGE];
            let n = m.encode(&mut buf);
            assert_eq!(RigMessage::decode(&buf[..n]), Ok(m));
        }
    }

    #[test]
    fn the_layout_is_as_documented() {
        let mut buf = [0; MAX_MESSAGE];
        let n = cycle(4).encode(&mut buf);
        assert_eq!(
            &buf[..n],
            &[
                0x02, 0xFF, 0, 0, 0x01, 0b101, 4, // type, seq, switches, receivers
                1, 0x40, 0x42, 0x0F, 0, 0x40, 0x0D, 0x03, 0, // 1 pulse: 1 000 000 ns, 200 000 ns
                1, 0x40, 0x43, 0x0F, 0, 0x40, 0x0D, 0x03, 0, // 1 000 256 ns
                0, // heard nothing
                3, // pickup, arrival, echo
                0x20, 0x4E, 0, 0, 0xA0, 0x86, 0x01, 0, // 20 000 ns, 100 000 ns
                0x40, 0x45, 0x0F, 0, 0x40, 0x0D, 0x03, 0, // 1 000 768 ns
                0x00, 0x6A, 0x18, 0, 0x40, 0x0D, 0x03, 0, // 1 600 000 ns
            ]
        );
        // Every receiver with every pulse fills the largest payload exactly.
        let full = HostMessage::Cycle {
            seq: 1,
            switches: 0,
            edges: [Edges::new(&[Edge::arrival(1); MAX_EDGES]).unwrap(); RECEIVERS],
            count: RECEIVERS as u8,
        };
        assert_eq!(full.encode(&mut buf), MAX_MESSAGE);
        assert_eq!(through_the_wire_host(full), full);
    }

    #[test]
    fn malformed_payloads_are_refused_not_guessed() {
        let mut buf = [0; MAX_MESSAGE];
        let n = cycle(4).encode(&mut buf);
        assert_eq!(
            HostMessage::decode(&buf[..n - 1]),
            Err(DecodeError::Length { kind: 0x02, len: n - 1 })
        );
        assert_eq!(HostMessage::decode(&[]), Err(DecodeError::Empty));
        assert_eq!(HostMessage::decode(&[0x7E]), Err(DecodeError::UnknownType(0x7E)));
        assert_eq!(
            HostMessage::decode(&[0x01, 0]),
            Err(DecodeError::Length { kind: 0x01, len: 2 })
        );
        assert_eq!(
            HostMessage::decode(&[0x03, 0b1000]),
            Err(DecodeError::Field("switches"))
        );
        assert_eq!(
            HostMessage::decode(&[0x02, 0, 0, 0, 0, 0, RECEIVERS as u8 + 1]),
            Err(DecodeError::Field("count"))
        );
        // One receiver with MAX_EDGES + 1 pulses: refused, not cut short.
        let mut too_many = [0u8; 8 + 8 * (MAX_EDGES + 1)];
        too_many[..8].copy_from_slice(&[0x02, 0, 0, 0, 0, 0, 1, MAX_EDGES as u8 + 1]);
        assert_eq!(HostMessage::decode(&too_many), Err(DecodeError::Field("edges")));
        // A pulse cut in the middle of its length.
        assert_eq!(
            HostMessage::decode(&[0x02, 0, 0, 0, 0, 0, 1, 1, 0x40, 0x42, 0x0F, 0, 0x40]),
            Err(DecodeError::Length { kind: 0x02, len: 13 })
        );
        // A rig message is not a host message, and the other way round.
        assert_eq!(HostMessage::decode(&[0x85]), Err(DecodeError::UnknownType(0x85)));
        assert_eq!(RigMessage::decode(&[0x01]), Err(DecodeError::UnknownType(0x01)));
        assert_eq!(RigMessage::decode(&[0x8F, 9]), Err(DecodeError::Field("error code")));
        assert_eq!(
            RigMessage::decode(&[0x81, 1, 8]),
            Err(DecodeError::Length { kind: 0x81, len: 3 })
        );
    }
}
