//! Where the pen comes from: a choice of transport, and how to (re)open it.

use std::fmt;
use std::str::FromStr;

use crate::transport::hid::HidTransport;
use crate::transport::serial::SerialTransport;
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
    Sim(SimOptions),
}

impl Source {
    /// Opens the source once.
    pub fn open(&self) -> Result<Box<dyn Transport>, TransportError> {
        Ok(match self {
            Source::Hid(path) => Box::new(HidTransport::open(path.as_deref())?),
            Source::Serial(path) => Box::new(SerialTransport::open(path)?),
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
            Source::Sim(o) => write!(f, "sim:{}", o.scenario.name),
        }
    }
}

/// `hid`, `hid:PATH`, `serial:PATH`, `sim` or `sim:SCENARIO` (the simulated pen in real time).
impl FromStr for Source {
    type Err = String;

    fn from_str(s: &str) -> Result<Source, String> {
        let (kind, arg) = match s.split_once(':') {
            Some((k, a)) => (k, Some(a)),
            None => (s, None),
        };
        match (kind, arg) {
            ("hid", path) => Ok(Source::Hid(path.map(str::to_string))),
            ("serial", Some(path)) if !path.is_empty() => Ok(Source::Serial(path.to_string())),
            ("serial", _) => Err("serial needs a path: serial:/dev/ttyACM0".into()),
            ("sim", name) => {
                let name = name.unwrap_or("modeling-session");
                let scenario = pen_sim::scenarios::by_name(name)
                    .ok_or_else(|| format!("unknown scenario {name:?}; `pen-sim scenarios` lists them"))?;
                Ok(Source::Sim(SimOptions {
                    scenario,
                    seed: 1,
                    speed: 1.0,
                    plug: Default::default(),
                }))
            }
            _ => Err(format!(
                "unknown source {s:?}: hid, hid:PATH, serial:PATH, sim or sim:SCENARIO"
            )),
        }
    }
}
