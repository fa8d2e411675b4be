//! Where the pen comes from, chosen in one place for every tool: a [`Source`] from the string
//! every tool's `--source` takes (`hid`, `hid:PATH`, `serial:PATH`, `sim`, `sim:SCENARIO`;
//! penmodel adds its own), the flags [`DeviceArgs`] declares for `pend` and `penctl`, and how to
//! (re)open it.
//!
//! The earlier spellings (`--serial PATH`, `--hid PATH`, pend's `--sim [SCENARIO]`, penctl's
//! `--sim --scenario NAME`, `--sim-speed`) still work, hidden from `--help` (docs/cli.md).
//!
//! The simulated pen (`sim`, `sim:SCENARIO`) is there with the cargo feature `sim` only; built
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
    /// `--speed` is the simulated pen's; a device runs at its own.
    #[error("--speed is the simulated pen's (--source sim); {0} runs in real time")]
    SpeedWithoutSim(String),
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
        Source::parse(s, "modeling-session")
    }
}

impl Source {
    /// [`Source::FORMS`], `sim` alone playing `default_scenario` (each tool has its own).
    #[cfg_attr(not(feature = "sim"), allow(unused_variables))]
    pub fn parse(s: &str, default_scenario: &str) -> Result<Source, SourceError> {
        let (kind, arg) = match s.split_once(':') {
            Some((k, a)) => (k, Some(a)),
            None => (s, None),
        };
        match (kind, arg) {
            ("hid", path) => Ok(Source::Hid(path.map(str::to_string))),
            ("serial", Some(path)) if !path.is_empty() => Ok(Source::Serial(path.to_string())),
            ("serial", _) => Err(SourceError::SerialWithoutPath),
            #[cfg(feature = "sim")]
            ("sim", name) => Source::sim(name.unwrap_or(default_scenario), 1.0),
            _ => Err(SourceError::UnknownKind { given: s.into() }),
        }
    }
}

/// `--source`, checked as clap reads it (a usage error otherwise).
fn source_form(s: &str) -> Result<String, SourceError> {
    Source::parse(s, "hold").map(|_| s.to_string())
}

/// `--speed`: device seconds per real second, finite and not negative (every tool's).
#[cfg(feature = "sim")]
pub fn speed_value(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "{s:?} is not a speed: device seconds per real second, 0 or more (0: as fast as it is read)"
        )),
    }
}

/// Which base station, as `pend` and `penctl` take it: `--source SOURCE` (default: the first
/// base station found on USB HID), `--speed` for the simulated pen; `S` says which scenario
/// `--source sim` plays in this tool, and declares the tool's earlier, hidden spelling of the
/// simulated pen ([`SimSwitch`], [`SimScenario`]).
#[derive(Args, Clone, Debug)]
pub struct DeviceArgs<S: SimFlag> {
    /// The base station: hid, hid:PATH, serial:PATH, sim or sim:SCENARIO ([`SimFlag::SOURCE_HELP`]).
    #[arg(long, value_name = "SOURCE", value_parser = source_form, help = S::SOURCE_HELP)]
    pub source: Option<String>,
    /// Earlier spelling of --source serial:PATH.
    #[arg(long, value_name = "PATH", hide = true, conflicts_with_all = ["source", "hid"])]
    #[cfg_attr(feature = "sim", arg(conflicts_with = "sim"))]
    pub serial: Option<String>,
    /// Earlier spelling of --source hid:PATH.
    #[arg(long, value_name = "PATH", hide = true, conflicts_with = "source")]
    #[cfg_attr(feature = "sim", arg(conflicts_with = "sim"))]
    pub hid: Option<String>,
    #[allow(missing_docs)]
    #[command(flatten)]
    pub sim: S,
    /// The simulated pen's speed: device seconds per real second (0: as fast as it is read)
    /// [default: 1].
    #[cfg(feature = "sim")]
    #[arg(long = "speed", alias = "sim-speed", value_name = "X", value_parser = speed_value,
          allow_negative_numbers = true)]
    pub sim_speed: Option<f64>,
}

impl<S: SimFlag> DeviceArgs<S> {
    /// The source the flags choose.
    pub fn source(&self) -> Result<Source, SourceError> {
        #[allow(unused_mut)]
        let mut source = match (&self.source, self.sim.scenario(), &self.serial) {
            (Some(s), _, _) => Source::parse(s, S::DEFAULT_SCENARIO)?,
            #[cfg(feature = "sim")]
            (None, Some(name), _) => Source::sim(if name.is_empty() { S::DEFAULT_SCENARIO } else { name }, 1.0)?,
            (None, _, Some(path)) => Source::Serial(path.clone()),
            _ => Source::Hid(self.hid.clone()),
        };
        #[cfg(feature = "sim")]
        match (&mut source, self.sim_speed) {
            (Source::Sim(o), Some(speed)) => o.speed = speed,
            (other, Some(_)) => return Err(SourceError::SpeedWithoutSim(other.to_string())),
            (_, None) => {}
        }
        Ok(source)
    }

    /// Whether the simulated pen was asked for.
    pub fn is_sim(&self) -> bool {
        self.sim.scenario().is_some()
            || self
                .source
                .as_deref()
                .is_some_and(|s| s == "sim" || s.starts_with("sim:"))
    }

    /// The simulated pen's speed (`--speed`, 1 by default).
    #[cfg(feature = "sim")]
    pub fn speed(&self) -> f64 {
        self.sim_speed.unwrap_or(1.0)
    }
}

/// A tool's simulated pen: the scenario `--source sim` plays, and the tool's earlier, hidden
/// spelling of "the simulated pen, playing this scenario".
pub trait SimFlag: Args + Clone + fmt::Debug {
    /// What `--source sim` plays in this tool.
    const DEFAULT_SCENARIO: &'static str;

    /// `--source`'s help in this tool, naming [`Self::DEFAULT_SCENARIO`].
    const SOURCE_HELP: &'static str;

    /// The scenario the earlier spelling asked for, if it was used ("" for the default).
    fn scenario(&self) -> Option<&str>;
}

/// `--source`'s help in a build without the simulated pen.
#[cfg(not(feature = "sim"))]
const NO_SIM_HELP: &str = "The base station: hid (the first one found on USB; the default), hid:PATH or serial:PATH";

/// penctl's: `--source sim` plays `hold` (the pen held still over the display: steady figures
/// for info, monitor and config); earlier spelled `--sim`, and `--scenario NAME`.
#[derive(Args, Clone, Debug)]
pub struct SimSwitch {
    /// Earlier spelling of --source sim.
    #[cfg(feature = "sim")]
    #[arg(long, hide = true, conflicts_with = "source")]
    sim: bool,
    /// Earlier spelling of --source sim:NAME.
    #[cfg(feature = "sim")]
    #[arg(long, value_name = "NAME", hide = true, requires = "sim")]
    scenario: Option<String>,
}

impl SimFlag for SimSwitch {
    const DEFAULT_SCENARIO: &'static str = "hold";
    #[cfg(not(feature = "sim"))]
    const SOURCE_HELP: &'static str = NO_SIM_HELP;
    #[cfg(feature = "sim")]
    const SOURCE_HELP: &'static str = "The base station: hid (the first one found on USB; the default), hid:PATH, \
        serial:PATH, or the simulated pen: sim (playing `hold`, the pen held still over the display), sim:SCENARIO \
        (`pen-sim scenarios` lists them)";

    fn scenario(&self) -> Option<&str> {
        #[cfg(feature = "sim")]
        if self.sim {
            return Some(self.scenario.as_deref().unwrap_or(""));
        }
        None
    }
}

/// pend's: `--source sim` plays `modeling-session` (a session of modeling gestures: the events
/// a modeler sees); earlier spelled `--sim [SCENARIO]`.
#[derive(Args, Clone, Debug)]
pub struct SimScenario {
    /// Earlier spelling of --source sim[:SCENARIO].
    #[cfg(feature = "sim")]
    #[arg(long, value_name = "SCENARIO", num_args = 0..=1, default_missing_value = "", hide = true,
          conflicts_with = "source")]
    sim: Option<String>,
}

impl SimFlag for SimScenario {
    const DEFAULT_SCENARIO: &'static str = "modeling-session";
    #[cfg(not(feature = "sim"))]
    const SOURCE_HELP: &'static str = NO_SIM_HELP;
    #[cfg(feature = "sim")]
    const SOURCE_HELP: &'static str = "The base station: hid (the first one found on USB; the default), hid:PATH, \
        serial:PATH, or the simulated pen: sim (playing `modeling-session`, the events a modeler sees), \
        sim:SCENARIO (`pen-sim scenarios` lists them)";

    fn scenario(&self) -> Option<&str> {
        #[cfg(feature = "sim")]
        return self.sim.as_deref();
        #[cfg(not(feature = "sim"))]
        None
    }
}
