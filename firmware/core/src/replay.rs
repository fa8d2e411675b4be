//! The replay format: what the core was given in recorded measurement cycles, so the same inputs
//! can be fed to another build of it (the core on QEMU's Cortex-M4F, `firmware/qemu`) and its
//! reports compared bit for bit with the host build's.
//!
//! One format, written by the simulated pen's harness (`pen-hil`) and read by `pen-qemu`, both
//! through this module. Little-endian:
//!
//! ```text
//! header: "PRPL"  version u32 = 3  configuration report (Config::LEN = 195 bytes; version 1
//!         had protocol 1's 187)
//!         head: pen slots u8, head slots u8, prediction ms u8 (all 0: the pen alone)
//! cycle:  emitter u8 (0 the pen, 1 the glasses; only in a run with the head)
//!         burst time u64 µs
//!         8 × capture time u32 ns after the burst (0xFFFF_FFFF: nothing heard)
//!         switch-sample count u16
//!         one byte per switch sample (SW1 = 1, SW2 = 2, SW3 = 4)
//! ```
//!
//! Cycles follow the header until the end of the file. Version 2 (before the tracked head) has
//! neither the head bytes nor the emitter byte: it still reads, as a run of the pen alone, and
//! written again with its [`Header`] it is the same bytes. `no_std` and allocation-free: the reader
//! pulls bytes from any [`Source`] (semihosting on the board), the writer pushes them to a
//! closure.

use pen_protocol::{Config, MAX_PREDICTION_MS, MAX_RECEIVERS, NO_ARRIVAL, Report};

use crate::head::{Emitter, HeadSettings, Schedule};

/// The file's first four bytes.
pub const MAGIC: [u8; 4] = *b"PRPL";
/// The format version this build writes.
pub const VERSION: u32 = 3;
/// The version before the tracked head, still read.
pub const VERSION_2: u32 = 2;
/// Bytes before the first cycle.
pub const HEADER_LEN: usize = 4 + 4 + Config::LEN + 3;
/// Bytes before the first cycle of a version 2 replay.
pub const HEADER_LEN_2: usize = 4 + 4 + Config::LEN;
/// Bytes of a cycle before its switch samples (version 3; version 2's have no emitter byte).
pub const CYCLE_HEAD_LEN: usize = 1 + 8 + 4 * MAX_RECEIVERS + 2;

/// What a replay's header says about its run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Header {
    /// The format version it was read in ([`VERSION`] for a header made here).
    pub version: u32,
    /// The configuration the run started with.
    pub config: Config,
    /// Head tracking through the whole run (the schedule and prediction), or the pen alone.
    pub head: Option<HeadSettings>,
}

impl Header {
    /// A header of this build's version.
    pub fn new(config: Config, head: Option<HeadSettings>) -> Header {
        Header {
            version: VERSION,
            config,
            head,
        }
    }

    /// Bytes of this header in its version.
    pub fn encoded_len(&self) -> usize {
        if self.version == VERSION_2 {
            HEADER_LEN_2
        } else {
            HEADER_LEN
        }
    }
}

/// Why a replay could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReplayError {
    /// The file does not start with [`MAGIC`].
    NotAReplay,
    /// A version this build does not know.
    Version(u32),
    /// The configuration report in the header does not decode.
    BadConfig,
    /// The head bytes in the header are not a schedule and a prediction (or all zero).
    BadHead,
    /// A cycle's emitter byte is neither the pen's nor, in a run with the head, the glasses'.
    BadEmitter(u8),
    /// The file ends inside the header or a cycle.
    Truncated,
    /// A cycle has more switch samples than the reader's buffer holds.
    TooManySamples(u16),
}

/// Where a reader's bytes come from.
pub trait Source {
    /// Fills `buf` entirely; false at the end of the input (or if fewer bytes are left).
    fn read_exact(&mut self, buf: &mut [u8]) -> bool;
}

impl Source for &[u8] {
    fn read_exact(&mut self, buf: &mut [u8]) -> bool {
        match self.split_at_checked(buf.len()) {
            Some((head, rest)) => {
                buf.copy_from_slice(head);
                *self = rest;
                true
            }
            None => false,
        }
    }
}

/// One recorded cycle's inputs, without its switch samples (they go to the caller's buffer).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleHead {
    /// The emitter the burst came from.
    pub emitter: Emitter,
    /// When the burst was fired, device µs.
    pub t0_us: u64,
    /// Each receiver's capture, ns after the burst.
    pub arrival_ns: [Option<u32>; MAX_RECEIVERS],
    /// How many switch samples follow.
    pub samples: u16,
}

/// Writes `header` (in its version: a version 2 header read is written back as it was).
pub fn write_header(header: &Header, out: &mut impl FnMut(&[u8])) {
    out(&MAGIC);
    out(&header.version.to_le_bytes());
    let mut c = [0u8; Config::LEN];
    // A buffer of exactly the report's length cannot be too short.
    let _ = header.config.encode(&mut c);
    out(&c);
    if header.version != VERSION_2 {
        out(&match header.head {
            Some(h) => [h.schedule.pen, h.schedule.head, h.prediction_ms],
            None => [0; 3],
        });
    }
}

/// Writes one cycle of a run with `header`, its burst from `emitter`. More than `u16::MAX`
/// switch samples are cut to that many (a cycle holds a few thousand at most: 1 s at the
/// slowest report rate, sampled every 500 µs).
pub fn write_cycle(
    header: &Header,
    emitter: Emitter,
    t0_us: u64,
    arrival_ns: &[Option<u32>; MAX_RECEIVERS],
    samples: &[u8],
    out: &mut impl FnMut(&[u8]),
) {
    if header.version != VERSION_2 {
        out(&[emitter_byte(emitter)]);
    }
    out(&t0_us.to_le_bytes());
    for a in arrival_ns {
        out(&a.unwrap_or(NO_ARRIVAL).to_le_bytes());
    }
    let n = samples.len().min(u16::MAX as usize);
    out(&(n as u16).to_le_bytes());
    out(&samples[..n]);
}

fn emitter_byte(emitter: Emitter) -> u8 {
    match emitter {
        Emitter::Pen => 0,
        Emitter::Head => 1,
    }
}

/// Reads the header: the run's configuration and head mode.
pub fn read_header(src: &mut impl Source) -> Result<Header, ReplayError> {
    let mut magic = [0u8; 4];
    if !src.read_exact(&mut magic) {
        return Err(ReplayError::Truncated);
    }
    if magic != MAGIC {
        return Err(ReplayError::NotAReplay);
    }
    let version = read_u32(src)?;
    if version != VERSION && version != VERSION_2 {
        return Err(ReplayError::Version(version));
    }
    let mut c = [0u8; Config::LEN];
    if !src.read_exact(&mut c) {
        return Err(ReplayError::Truncated);
    }
    let config = Config::decode(&c).map_err(|_| ReplayError::BadConfig)?;
    let head = if version == VERSION_2 {
        None
    } else {
        let mut h = [0u8; 3];
        if !src.read_exact(&mut h) {
            return Err(ReplayError::Truncated);
        }
        match h {
            [0, 0, 0] => None,
            [pen, head, prediction_ms] if pen > 0 && head > 0 && prediction_ms <= MAX_PREDICTION_MS => {
                Some(HeadSettings {
                    schedule: Schedule { pen, head },
                    prediction_ms,
                })
            }
            _ => return Err(ReplayError::BadHead),
        }
    };
    Ok(Header { version, config, head })
}

/// Reads the next cycle of a run with `header`, its switch samples into
/// `samples[..head.samples]`; `Ok(None)` at a clean end of the file (no byte of a next cycle).
pub fn read_cycle(
    src: &mut impl Source,
    header: &Header,
    samples: &mut [u8],
) -> Result<Option<CycleHead>, ReplayError> {
    let emitter = if header.version == VERSION_2 {
        Emitter::Pen
    } else {
        let mut e = [0u8; 1];
        if !src.read_exact(&mut e) {
            return Ok(None);
        }
        match e[0] {
            0 => Emitter::Pen,
            1 if header.head.is_some() => Emitter::Head,
            other => return Err(ReplayError::BadEmitter(other)),
        }
    };
    let mut t = [0u8; 8];
    if !src.read_exact(&mut t) {
        // A version 3 cycle cut after its emitter byte is cut, not ended.
        return if header.version == VERSION_2 {
            Ok(None)
        } else {
            Err(ReplayError::Truncated)
        };
    }
    let mut arrival_ns = [None; MAX_RECEIVERS];
    for a in arrival_ns.iter_mut() {
        let v = read_u32(src)?;
        *a = (v != NO_ARRIVAL).then_some(v);
    }
    let mut n = [0u8; 2];
    if !src.read_exact(&mut n) {
        return Err(ReplayError::Truncated);
    }
    let count = u16::from_le_bytes(n);
    let buf = samples
        .get_mut(..count as usize)
        .ok_or(ReplayError::TooManySamples(count))?;
    if !src.read_exact(buf) {
        return Err(ReplayError::Truncated);
    }
    Ok(Some(CycleHead {
        emitter,
        t0_us: u64::from_le_bytes(t),
        arrival_ns,
        samples: count,
    }))
}

fn read_u32(src: &mut impl Source) -> Result<u32, ReplayError> {
    let mut b = [0u8; 4];
    src.read_exact(&mut b)
        .then(|| u32::from_le_bytes(b))
        .ok_or(ReplayError::Truncated)
}
