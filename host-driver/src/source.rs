//! Where the pen comes from, chosen in one place for every tool: a [`Source`] from a string
//! (`penmodel --source`) or from the flags [`DeviceArgs`] declares (`pend`, `penctl`), and how
//! to (re)open it.
//!
//! The simulated pen (`--sim`, `sim:SCENARIO`) is there with the cargo feature `sim` only; built
//! without it, the flags do not exist and `sim` is an unknown source.

use std::fmt;
use std::str::FromStr;

use clap::Args;

use crate::transport::hid::HidTransport;
use crate::transport::serial::SerialTransport;
#[cfg(feature = "sim")]
use crate::transport::sim::{SimOptions, SimTransport};
use crate::transport::{Transport, TransportError};

/// A pen source.
#[derive(Debug, Clone)]
// One per session, never in a collection: the simulated pen's scenario may be large.
#[allow(clippy::large_enum_variant)]
pub enum Source {
    /// USB HID: a hidraw path, or the first base station found.
    Hid(Option<String>),
    /// The serial link at a path.
    Serial(String),
    /// The simulated pen in this process.
    #[cfg(feature = "sim")]
    Sim(SimOptions),
}

/// Why a source cannot be had.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs)]
pub enum SourceError {
    /// The string names no kind of source.
    #[error("unknown source {given:?}: {}", Source::FORMS)]
    UnknownKind { given: String },
    /// `serial` without a path.
    #[error("serial needs a path: serial:/dev/ttyACM0")]
    SerialWithoutPath,
    /// pen-sim has no scenario of this name.
    #[error("unknown scenario {0:?}; `pen-sim scenarios` lists them")]
    UnknownScenario(String),
}

impl Source {
    /// The forms [`FromStr`] reads, for messages.
    #[cfg(feature = "sim")]
    pub const FORMS: &'static str = "hid, hid:PATH, serial:PATH, sim or sim:SCENARIO";
    /// The forms [`FromStr`] reads, for messages.
    #[cfg(not(feature = "sim"))]
    pub const FORMS: &'static str = "hid, hid:PATH or serial:PATH";

    /// The simulated pen playing the pen-sim scenario `name`, `speed` device seconds per
    /// wall-clock second (0: as fast as it is read).
    #[cfg(feature = "sim")]
    pub fn sim(name: &str, speed: f64) -> Result<Source, SourceError> {
        let scenario = pen_sim::scenarios::by_name(name).ok_or_else(|| SourceError::UnknownScenario(name.into()))?;
        Ok(Source::Sim(SimOptions {
            scenario,
            seed: 1,
            speed,
            plug: Default::default(),
        }))
    }

    /// Opens the source once.
    pub fn open(&self) -> Result<Box<dyn Transport>, TransportError> {
        Ok(match self {
            Source::Hid(path) => Box::new(HidTransport::open(path.as_deref())?),
            Source::Serial(path) => Box::new(SerialTransport::open(path)?),
            #[cfg(feature = "sim")]
            Source::Sim(options) => Box::new(SimTransport::open(options)?),
        })
    }
}

impl fmt::Display for Source {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Source::Hid(Some(p)) => write!(f, "hid:{p}"),
            Source::Hid(None) => write!(f, "hid"),
            Source::Serial(p) => write!(f, "serial:{p}"),
            #[cfg(feature = "sim")]
            Source::Sim(o) => write!(f, "sim:{}", o.scenario.name),
        }
    }
}

/// [`Source::FORMS`]: `hid`, `hid:PATH`, `serial:PATH`, `sim` or `sim:SCENARIO` (the simulated
/// pen in real time, `modeling-session` by default).
impl FromStr for Source {
    type Err = SourceError;

    fn from_str(s: &str) -> Result<Source, SourceError> {
        let (kind, arg) = match s.split_once(':') {
            Some((k, a)) => (k, Some(a)),
            None => (s, None),
        };
        match (kind, arg) {
            ("hid", path) => Ok(Source::Hid(path.map(str::to_string))),
            ("serial", Some(path)) if !path.is_empty() => Ok(Source::Serial(path.to_string())),
            ("serial", _) => Err(SourceError::SerialWithoutPath),
            #[cfg(feature = "sim")]
            ("sim", name) => Source::sim(name.unwrap_or("modeling-session"), 1.0),
            _ => Err(SourceError::UnknownKind { given: s.into() }),
        }
    }
}

/// Which base station, as `pend` and `penctl` take it: `--serial PATH`, `--hid PATH` (default:
/// the first base station found) or the simulated pen, whose flags `S` declares — the two tools
/// spell it differently ([`SimSwitch`], [`SimScenario`]).
#[derive(Args, Clone, Debug)]
pub struct DeviceArgs<S: SimFlag> {
    /// The serial link at PATH instead of USB HID.
    #[arg(long, value_name = "PATH", conflicts_with = "hid")]
    #[cfg_attr(feature = "sim", arg(conflicts_with = "sim"))]
    pub serial: Option<String>,
    /// A hidraw device instead of the first base station found.
    #[arg(long, value_name = "PATH")]
    #[cfg_attr(feature = "sim", arg(conflicts_with = "sim"))]
    pub hid: Option<String>,
    #[allow(missing_docs)]
    #[command(flatten)]
    pub sim: S,
    /// Device seconds per real second for --sim (0: as fast as possible).
    #[cfg(feature = "sim")]
    #[arg(long, default_value_t = 1.0, requires = "sim")]
    pub sim_speed: f64,
}

impl<S: SimFlag> DeviceArgs<S> {
    /// The source the flags choose.
    pub fn source(&self) -> Result<Source, SourceError> {
        #[cfg(feature = "sim")]
        if let Some(name) = self.sim.scenario() {
            return Source::sim(name, self.sim_speed);
        }
        Ok(match &self.serial {
            Some(path) => Source::Serial(path.clone()),
            None => Source::Hid(self.hid.clone()),
        })
    }

    /// Whether the simulated pen was asked for.
    pub fn is_sim(&self) -> bool {
        self.sim.scenario().is_some()
    }
}

/// How a tool spells "the simulated pen, playing this scenario".
pub trait SimFlag: Args + Clone + fmt::Debug {
    /// The scenario, when the simulated pen was asked for.
    fn scenario(&self) -> Option<&str>;
}

/// penctl's spelling: `--sim`, and `--scenario NAME` (default `hold`).
#[derive(Args, Clone, Debug)]
pub struct SimSwitch {
    /// The simulated pen in this process.
    #[cfg(feature = "sim")]
    #[arg(long)]
    sim: bool,
    /// The session the simulated pen plays (`pen-sim scenarios` lists them).
    #[cfg(feature = "sim")]
    #[arg(long, value_name = "NAME", default_value = "hold", requires = "sim")]
    scenario: String,
}

impl SimFlag for SimSwitch {
    fn scenario(&self) -> Option<&str> {
        #[cfg(feature = "sim")]
        if self.sim {
            return Some(&self.scenario);
        }
        None
    }
}

/// pend's spelling: `--sim [SCENARIO]` (default `modeling-session`).
#[derive(Args, Clone, Debug)]
pub struct SimScenario {
    /// Use the simulated pen, playing SCENARIO (default modeling-session) in real time.
    #[cfg(feature = "sim")]
    #[arg(long, value_name = "SCENARIO", num_args = 0..=1, default_missing_value = "modeling-session")]
    sim: Option<String>,
}

impl SimFlag for SimScenario {
    fn scenario(&self) -> Option<&str> {
        #[cfg(feature = "sim")]
        return self.sim.as_deref();
        #[cfg(not(feature = "sim"))]
        None
    }
}
