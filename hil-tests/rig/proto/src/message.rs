//! The messages between the host and the rig, over the rig's USB serial port (CDC-ACM).
//!
//! Each message is one frame of the base station's serial framing (`pen_protocol::encode_frame`:
//! COBS, CRC-32, 0x00 delimiters) whose payload starts with the message's type byte; integers
//! are little-endian. Host to rig: [`HostMessage`]; rig to host: [`RigMessage`]. The rig answers
//! every host message with exactly one rig message, so the host paces itself by the answers
//! and learns from each [`RigStatus`] how full the rig's queue is.

use crate::RECEIVERS;
use pen_protocol::NO_ARRIVAL;

/// The largest payload of either direction (a cycle with every receiver).
pub const MAX_MESSAGE: usize = 7 + 4 * RECEIVERS;

/// Switch bits as the base station's reports carry them: SW1 (tip) = 1, SW2 = 2, SW3 = 4.
pub const SWITCH_MASK: u8 = 0b111;

/// From the host.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HostMessage {
    /// Who is there: the rig answers [`RigMessage::Info`].
    Hello,
    /// One burst's worth: queued, played at the next burst whose predecessor has been played.
    Cycle {
        /// The host's count, echoed in [`RigStatus::last_played`].
        seq: u32,
        /// Switch lines to hold from that burst on (bits as [`SWITCH_MASK`]).
        switches: u8,
        /// Arrival per receiver, ns after the burst's first rising edge; `None` heard nothing.
        /// Receivers past `count` hear nothing.
        arrival_ns: [Option<u32>; RECEIVERS],
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
                arrival_ns,
                count,
            } => {
                out.put(&[kind::CYCLE]);
                out.put(&seq.to_le_bytes());
                out.put(&[switches, count]);
                for a in arrival_ns.iter().take(usize::from(count)) {
                    out.put(&a.unwrap_or(NO_ARRIVAL).to_le_bytes());
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
                    let mut arrival_ns = [None; RECEIVERS];
                    for a in arrival_ns.iter_mut().take(usize::from(count)) {
                        let Some(t) = input.u32() else { return Ok(None) };
                        *a = (t != NO_ARRIVAL).then_some(t);
                    }
                    Some(HostMessage::Cycle {
                        seq,
                        switches,
                        arrival_ns,
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
        let mut arrival_ns = [None; RECEIVERS];
        for (i, a) in arrival_ns.iter_mut().enumerate().take(usize::from(count)) {
            // A dropout at receiver 2; zeros in the times, which COBS must carry.
            *a = (i != 2).then_some(1_000_000 + i as u32 * 256);
        }
        HostMessage::Cycle {
            seq: 0x0100_00FF,
            switches: 0b101,
            arrival_ns,
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
                0x02, 0xFF, 0, 0, 0x01, 0b101, 4, // type, seq, switches, count
                0x40, 0x42, 0x0F, 0, // 1 000 000
                0x40, 0x43, 0x0F, 0, // 1 000 256
                0xFF, 0xFF, 0xFF, 0xFF, // no arrival
                0x40, 0x45, 0x0F, 0, // 1 000 768
            ]
        );
        let n = cycle(RECEIVERS as u8).encode(&mut buf);
        assert_eq!(n, MAX_MESSAGE);
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
