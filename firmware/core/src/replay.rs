//! The replay format: what the core was given in recorded measurement cycles, so the same inputs
//! can be fed to another build of it (the core on QEMU's Cortex-M4F, `firmware/qemu`) and its
//! reports compared bit for bit with the host build's.
//!
//! One format, written by the simulated pen's harness (`pen-hil`) and read by `pen-qemu`, both
//! through this module. Little-endian:
//!
//! ```text
//! header: "PRPL"  version u32 = 2  configuration report (Config::LEN = 195 bytes; version 1
//!         had protocol 1's 187)
//! cycle:  burst time u64 µs
//!         8 × capture time u32 ns after the burst (0xFFFF_FFFF: nothing heard)
//!         switch-sample count u16
//!         one byte per switch sample (SW1 = 1, SW2 = 2, SW3 = 4)
//! ```
//!
//! Cycles follow the header until the end of the file. `no_std` and allocation-free: the reader
//! pulls bytes from any [`Source`] (semihosting on the board), the writer pushes them to a
//! closure.

use pen_protocol::{Config, MAX_RECEIVERS, NO_ARRIVAL, Report};

/// The file's first four bytes.
pub const MAGIC: [u8; 4] = *b"PRPL";
/// The format version this build reads and writes.
pub const VERSION: u32 = 2;
/// Bytes before the first cycle.
pub const HEADER_LEN: usize = 4 + 4 + Config::LEN;
/// Bytes of a cycle before its switch samples.
pub const CYCLE_HEAD_LEN: usize = 8 + 4 * MAX_RECEIVERS + 2;

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
    /// When the burst was fired, device µs.
    pub t0_us: u64,
    /// Each receiver's capture, ns after the burst.
    pub arrival_ns: [Option<u32>; MAX_RECEIVERS],
    /// How many switch samples follow.
    pub samples: u16,
}

/// Writes the header for a run with `config`.
pub fn write_header(config: &Config, out: &mut impl FnMut(&[u8])) {
    out(&MAGIC);
    out(&VERSION.to_le_bytes());
    let mut c = [0u8; Config::LEN];
    // A buffer of exactly the report's length cannot be too short.
    let _ = config.encode(&mut c);
    out(&c);
}

/// Writes one cycle. More than `u16::MAX` switch samples are cut to that many (a cycle holds a
/// few thousand at most: 1 s at the slowest report rate, sampled every 500 µs).
pub fn write_cycle(t0_us: u64, arrival_ns: &[Option<u32>; MAX_RECEIVERS], samples: &[u8], out: &mut impl FnMut(&[u8])) {
    out(&t0_us.to_le_bytes());
    for a in arrival_ns {
        out(&a.unwrap_or(NO_ARRIVAL).to_le_bytes());
    }
    let n = samples.len().min(u16::MAX as usize);
    out(&(n as u16).to_le_bytes());
    out(&samples[..n]);
}

/// Reads the header and returns the run's configuration.
pub fn read_header(src: &mut impl Source) -> Result<Config, ReplayError> {
    let mut magic = [0u8; 4];
    if !src.read_exact(&mut magic) {
        return Err(ReplayError::Truncated);
    }
    if magic != MAGIC {
        return Err(ReplayError::NotAReplay);
    }
    let version = read_u32(src)?;
    if version != VERSION {
        return Err(ReplayError::Version(version));
    }
    let mut c = [0u8; Config::LEN];
    if !src.read_exact(&mut c) {
        return Err(ReplayError::Truncated);
    }
    Config::decode(&c).map_err(|_| ReplayError::BadConfig)
}

/// Reads the next cycle, its switch samples into `samples[..head.samples]`; `Ok(None)` at a clean
/// end of the file (no byte of a next cycle).
pub fn read_cycle(src: &mut impl Source, samples: &mut [u8]) -> Result<Option<CycleHead>, ReplayError> {
    let mut t = [0u8; 8];
    if !src.read_exact(&mut t) {
        return Ok(None);
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
