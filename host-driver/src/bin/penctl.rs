//! `penctl`: inspect, configure and calibrate the 3D pen from the command line.
//!
//! Exit status: 0 on success, 1 when the input, the device or a request fails (the reason on
//! stderr), 2 on a usage error, 3 when `penctl list` finds no base station attached.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use pen_host::calibration::procedure::{self as calibrate, Prompt};
use pen_host::calibration::run;
use pen_host::calibration::{self, Calibration, CalibrationError, DeviceId, FitKind, plot};
use pen_host::device::{Device, DeviceEvent};
use pen_host::hex;
use pen_host::source::{self, SimSwitch, Source};
use pen_host::transport::{Transport, hid, serial};
use pen_protocol::{
    Command as DeviceCommand, Config, ConfigChanges, FrameDecoder, Message, REPORT_DESCRIPTOR, ReportId, StatusCode,
};
use serde::Serialize;

use pen_host::outln;

#[derive(Parser)]
#[command(
    name = "penctl",
    version,
    about = "Inspect, configure and calibrate the 3D pen",
    propagate_version = true,
    after_help = "Which base station, for every command that talks to one: --source hid (the first found on USB; \
    the default), hid:PATH, serial:PATH, or the simulated pen: --source sim (here it plays `hold`, the pen held \
    still over the display), sim:SCENARIO, with --speed (device seconds per second, 0: as fast as read).\n\
    Examples:\n  \
    penctl list\n  \
    penctl info --source serial:/dev/ttyACM0\n  \
    penctl monitor --source sim --speed 0 --count 5\n  \
    penctl calibrate --targets 9 --plot residuals.png\n\
    docs/penctl.md and docs/cli.md (the flags every tool shares)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Which device: `--source hid|hid:PATH|serial:PATH|sim|sim:SCENARIO` and `--speed`; `--source sim`
/// plays `hold`.
type DeviceArgs = source::DeviceArgs<SimSwitch>;

#[derive(Subcommand)]
enum Command {
    /// List the base stations attached (HID interfaces and serial links); exit status 3 when there is none.
    #[command(after_help = "Example:\n  penctl list || echo \"no base station\"")]
    List,
    /// Print the device's information and configuration.
    #[command(
        after_help = "Examples:\n  penctl info\n  penctl info --source serial:/dev/ttyACM0 --json\n  \
                            penctl info --source sim"
    )]
    Info {
        #[command(flatten)]
        device: DeviceArgs,
        /// One JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Print samples as they arrive: a header, then a row per sample (or one JSON object per sample).
    #[command(after_help = "Examples:\n  penctl monitor --count 10\n  \
                            penctl monitor --source sim --speed 0 --json --count 5")]
    Monitor {
        #[command(flatten)]
        device: DeviceArgs,
        /// One JSON object per sample.
        #[arg(long)]
        json: bool,
        /// Stop after N samples.
        #[arg(long, value_name = "N")]
        count: Option<u64>,
    },
    /// Read or change the device's configuration.
    #[command(
        after_help = "Examples:\n  penctl config get\n  penctl config set temperature_c=23.5\n  penctl config save"
    )]
    Config {
        #[command(subcommand)]
        action: ConfigAction,
    },
    /// Start or stop tracking the viewer's head (the glasses' emitter, protocol 2.1; kept across a power cycle once `penctl config save` saves it).
    #[command(
        after_help = "Examples:\n  penctl head on && penctl config save\n  penctl head off --source serial:/dev/ttyACM0"
    )]
    Head {
        /// `on` or `off`.
        #[arg(value_parser = ["on", "off"])]
        state: String,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Restart the device into its ROM USB DFU bootloader (docs/flashing.md).
    #[command(after_help = "Example:\n  penctl bootloader && sleep 2 && dfu-util -l")]
    Bootloader {
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Calibrate: touch targets on the display, fit the tracker → display transform.
    Calibrate(CalibrateArgs),
    /// Measure each receiver's transducer delay from the pen held at surveyed points, and write it to the device.
    Delays(pen_host::calibration::delays::cli::DelaysArgs),
    /// Print the USB HID report descriptor as one line of hex.
    #[command(after_help = "Example:\n  penctl descriptor")]
    Descriptor,
    /// Decode a report given in hex and print it as one JSON object.
    ///
    /// The bytes start with the report ID, as read from hidraw or a serial frame's payload.
    /// Spaces, ':' and '-' between digits and a leading 0x are accepted.
    #[command(after_help = "Example:\n  penctl decode 010dd204c9fd7a03341204030201050712")]
    Decode {
        /// The report's bytes in hex (several arguments are joined).
        #[arg(required = true, value_name = "HEX")]
        hex: Vec<String>,
        /// The bytes are one serial frame (COBS and CRC-32, delimiters optional), not a bare report.
        #[arg(long)]
        frame: bool,
    },
}

#[derive(Subcommand)]
enum ConfigAction {
    /// Print the configuration.
    #[command(after_help = "Examples:\n  penctl config get\n  penctl config get --json > config.json")]
    Get {
        #[command(flatten)]
        device: DeviceArgs,
        /// One JSON object (the form `config set --file` reads).
        #[arg(long)]
        json: bool,
    },
    /// Change settings: KEY=VALUE (VALUE in JSON), or a whole configuration from --file.
    #[command(after_help = "Examples:\n  penctl config set temperature_c=23.5 stream_tof=true\n  \
                            penctl config set 'filter={\"kind\":\"off\"}'\n  penctl config get --json > c.json; penctl config set --file c.json")]
    Set {
        #[command(flatten)]
        device: DeviceArgs,
        /// Settings to change.
        #[arg(value_name = "KEY=VALUE", required_unless_present = "file")]
        settings: Vec<String>,
        /// A JSON configuration (keys it lacks keep their values).
        #[arg(long, value_name = "FILE")]
        file: Option<PathBuf>,
    },
    /// Save the running configuration to the device's flash.
    #[command(after_help = "Example:\n  penctl config set temperature_c=23.5 && penctl config save")]
    Save {
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Replace the running configuration with the firmware's defaults (not saved).
    #[command(after_help = "Example:\n  penctl config defaults && penctl config save")]
    Defaults {
        #[command(flatten)]
        device: DeviceArgs,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Fit {
    Rigid,
    Similarity,
}

#[derive(Args)]
#[command(
    after_help = "With --source sim the simulated pen plays the touches itself (on a display placed a little \
    off, as by hand) and the calibration goes to calibration-sim.toml.\n\
    Examples:\n  \
    penctl calibrate --targets 9 --display-mm 600x340 --display-px 2560x1440 --plot residuals.png\n  \
    penctl calibrate --source serial:/dev/ttyACM0 --write-device\n  \
    penctl calibrate --source sim --speed 0 --calibration /tmp/sim.toml"
)]
struct CalibrateArgs {
    #[command(flatten)]
    device: DeviceArgs,
    #[command(flatten)]
    display: pen_host::calibration::args::DisplayArgs,
    /// The transform to fit.
    #[arg(long, value_enum, default_value_t = Fit::Similarity)]
    fit: Fit,
    /// Where to save the calibration [default: $XDG_CONFIG_HOME/penscape/calibration.toml;
    /// calibration-sim.toml for the simulated pen, so that it never replaces the real one's].
    /// The file pend reads with the same flag.
    #[arg(long = "calibration", alias = "out", value_name = "FILE")]
    out: Option<PathBuf>,
    /// Also draw the residuals into this PNG.
    #[arg(long, value_name = "PNG")]
    plot: Option<PathBuf>,
    /// Also write the calibration to the device, so that it reports display coordinates.
    #[arg(long)]
    write_device: bool,
    /// Seconds to wait for each touch.
    #[arg(long, default_value_t = 60.0)]
    patience: f64,
    /// Skip the pivot: after the targets, the pen's tip held on the display's centre while the
    /// pen tilts about it, its top circling; it measures where the tip is from the emitter, which
    /// the tracked glasses' positions need (docs/calibration.md, "The pivot").
    #[arg(long)]
    no_pivot: bool,
}

/// A usage error found after parsing (values that parse but do not go together or are out of
/// range): exit status 2, like clap's own.
#[derive(Debug, thiserror::Error)]
#[error("{0} (penctl --help)")]
struct UsageError(String);

/// Opens the device, waiting a moment for it to attach.
fn attach(args: &DeviceArgs) -> Result<Device> {
    let mut device = Device::new(args.source()?);
    calibrate::attach(&mut device, Duration::from_secs(2))?;
    Ok(device)
}

fn transport(device: &mut Device) -> Result<&mut (dyn Transport + 'static)> {
    device.transport().context("the device went away")
}

fn get_config(t: &mut dyn Transport) -> Result<Config> {
    match t.get_feature(ReportId::Config)? {
        Message::Config(c) => Ok(c),
        other => bail!("the device answered with a {} report", other.id()),
    }
}

/// Sends a configuration or command; fails unless the device accepted it.
fn request(t: &mut dyn Transport, m: &Message) -> Result<()> {
    let status = t.set_feature(m)?;
    if status.code != StatusCode::Ok {
        bail!("the device refused: {status}");
    }
    Ok(())
}

fn print_json(v: &impl Serialize) -> Result<()> {
    outln!("{}", serde_json::to_string(v)?);
    Ok(())
}

/// `penctl info --json`.
#[derive(Serialize)]
struct InfoJson<'a> {
    device: String,
    /// The device information report, tagged like `penctl decode` prints it.
    info: &'a Message,
    config: &'a Config,
    /// The reset record (protocol 2.2), tagged like `penctl decode` prints it: the panic, fault
    /// or watchdog reset that ended the device's previous run. Absent where the firmware does
    /// not answer it.
    #[serde(skip_serializing_if = "Option::is_none")]
    last_reset: Option<Message>,
    /// The calibration pend would apply to this device by default.
    calibration: CalibrationJson,
}

/// The default calibration file for a device and whether it is this device's.
#[derive(Serialize)]
struct CalibrationJson {
    /// The file, if there is one.
    path: Option<String>,
    /// The base station it records (hex), if it records one.
    device: Option<String>,
    /// Whether pend applies it to this device.
    applies: bool,
    /// What it means, in words.
    status: String,
}

/// Which calibration pend would apply to the device `info` describes by default, and whether
/// it may: the user sees whether calibrating is needed before starting pend.
fn calibration_status(simulated: bool, info: &pen_protocol::DeviceInfo) -> CalibrationJson {
    let id = DeviceId::of(info);
    let path = calibration::default_path_for(simulated || id.is_simulated());
    let Some(path) = path.filter(|p| p.exists()) else {
        return CalibrationJson {
            path: None,
            device: None,
            applies: false,
            status: "none: run `penctl calibrate`".into(),
        };
    };
    let (device, applies, status) = match Calibration::load(&path) {
        Err(e) => (None, false, format!("unreadable ({e}): run `penctl calibrate`")),
        Ok(c) => match c.check_device(Ok(info)) {
            Ok(()) if c.device.is_some() => (c.device, true, "this base station's".into()),
            Ok(()) => (
                None,
                true,
                "records no base station (version 1): run `penctl calibrate`".into(),
            ),
            Err(_) => (
                c.device,
                false,
                format!(
                    "base station {}'s, not this one's: run `penctl calibrate`",
                    c.device.map(|d| d.to_string()).unwrap_or_default()
                ),
            ),
        },
    };
    CalibrationJson {
        path: Some(path.display().to_string()),
        device: device.map(|d| d.to_hex()),
        applies,
        status,
    }
}

/// Reads configuration changes in JSON (the form `config get --json` prints); errors name the
/// key at fault.
fn config_changes(v: serde_json::Value) -> Result<ConfigChanges> {
    // serde would also read a struct from a list of its values: only an object is one here.
    anyhow::ensure!(v.is_object(), "`(top level)`: must be a JSON object");
    serde_path_to_error::deserialize(v).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        if path == "." {
            anyhow::anyhow!("{inner}")
        } else {
            anyhow::anyhow!("`{path}`: {inner}")
        }
    })
}

fn info(args: &DeviceArgs, as_json: bool) -> Result<()> {
    let mut device = attach(args)?;
    let t = transport(&mut device)?;
    let Message::DeviceInfo(info) = t.get_feature(ReportId::DeviceInfo)? else {
        bail!("no device information")
    };
    pen_protocol::check_version(info.protocol)?;
    let config = get_config(t)?;
    // Firmware before protocol 2.2 does not answer it: that is no error.
    let last_reset = match t.get_feature(ReportId::ResetRecord) {
        Ok(Message::ResetRecord(r)) => Some(r),
        _ => None,
    };
    let calibration = calibration_status(args.is_sim(), &info);
    if as_json {
        print_json(&InfoJson {
            device: t.describe(),
            info: &Message::DeviceInfo(info),
            config: &config,
            last_reset: last_reset.map(Message::ResetRecord),
            calibration,
        })?;
    } else {
        outln!("device       {}", t.describe());
        outln!("protocol     {}", info.protocol);
        outln!("firmware     {}", info.firmware);
        outln!("receivers    {} of {}", info.receiver_count, info.max_receivers);
        outln!("fix rate     {} Hz", info.fix_rate_hz);
        outln!("unique ID    {}", hex::to_hex(&info.unique_id));
        outln!("display pose {}", if config.display.is_some() { "set" } else { "none" });
        match last_reset {
            Some(r) => outln!("last reset   {r}"),
            None => outln!("last reset   not reported (firmware before protocol 2.2)"),
        }
        match &calibration.path {
            Some(p) => outln!("calibration  {p}: {}", calibration.status),
            None => outln!("calibration  {}", calibration.status),
        }
    }
    Ok(())
}

/// `penctl monitor`'s column header (not in --json mode), aligned with its rows: sequence
/// number, device time, in range, position, switches, receivers used, fix residual, DOP, reports
/// lost just before.
fn monitor_header() -> String {
    format!(
        "{:>5}  {:>11}  {:5}  {:>8}  {:>8}  {:>8}  {:11}  {:>3}  {:>8}  {:>4}  {:>4}",
        "seq", "t s", "range", "x mm", "y mm", "z mm", "switches", "rx", "resid mm", "DOP", "lost"
    )
}

fn monitor(args: &DeviceArgs, as_json: bool, count: Option<u64>) -> Result<()> {
    let mut device = Device::new(args.source()?);
    let mut printed = 0u64;
    let mut out = std::io::stdout().lock();
    if !as_json {
        writeln!(out, "{}", monitor_header())?;
    }
    // Dropped input is said on stderr, at most once a second: a line of pure garbage (a wrong
    // port, baud rate or device) would otherwise show nothing at all.
    let (mut told_dropped, mut told_at) = (0u64, None::<std::time::Instant>);
    while count.is_none_or(|n| printed < n) {
        let dropped = device.dropped();
        // Counted afresh at each attach.
        told_dropped = told_dropped.min(dropped);
        if dropped > told_dropped && told_at.is_none_or(|t| t.elapsed() >= Duration::from_secs(1)) {
            eprintln!(
                "penctl: warning: {dropped} invalid reports or frames dropped since {} attached (garbage on the line: \
                 the wrong port or baud rate, or not a base station?)",
                device.awaited()
            );
            (told_dropped, told_at) = (dropped, Some(std::time::Instant::now()));
        }
        match device.next(Duration::from_millis(200)) {
            Some(DeviceEvent::Sample(s, lost)) => {
                if as_json {
                    writeln!(out, "{}", serde_json::to_string(&s.json(lost))?)?;
                } else {
                    let sw = |on: bool, name: &'static str| if on { name } else { "---" };
                    writeln!(
                        out,
                        "{:5}  {:11.6}  {:5}  {:8.1}  {:8.1}  {:8.1}  {} {} {}  {:3}  {:8.1}  {:4.1}  {:4}",
                        s.seq,
                        s.device_us as f64 * 1e-6,
                        if s.in_range { "in" } else { "out" },
                        s.position_mm.x,
                        s.position_mm.y,
                        s.position_mm.z,
                        sw(s.sw[0], "SW1"),
                        sw(s.sw[1], "SW2"),
                        sw(s.sw[2], "SW3"),
                        s.quality.receivers_used,
                        s.quality.residual_mm(),
                        s.quality.dop(),
                        lost,
                    )?;
                }
                printed += 1;
            }
            Some(DeviceEvent::Head(h)) => {
                if as_json {
                    writeln!(out, "{}", serde_json::to_string(&h.json())?)?;
                } else {
                    // The head's row: its own sequence, "head" for the range column, the pose
                    // predicted ahead, then "+N ms" and whether the report had a fix.
                    writeln!(
                        out,
                        "{:5}  {:11.6}  {:5}  {:8.1}  {:8.1}  {:8.1}  {:11}  {:3}  {:8.1}  {:4.1}  {}",
                        h.seq,
                        h.device_us as f64 * 1e-6,
                        "head",
                        h.position_mm.x,
                        h.position_mm.y,
                        h.position_mm.z,
                        format!("+{} ms", h.prediction_ms),
                        h.quality.receivers_used,
                        h.quality.residual_mm(),
                        h.quality.dop(),
                        if h.no_fix { "no fix: last pose kept" } else { "" },
                    )?;
                }
                printed += 1;
            }
            Some(DeviceEvent::Found(name)) => eprintln!("penctl: attached {name}"),
            Some(DeviceEvent::Lost(why)) => eprintln!("penctl: device lost ({why}); waiting for it"),
            Some(DeviceEvent::Waiting(notice)) => eprintln!("penctl: {notice}"),
            _ => {}
        }
    }
    Ok(())
}

fn config(action: ConfigAction) -> Result<()> {
    match action {
        ConfigAction::Get { device, json: as_json } => {
            let mut d = attach(&device)?;
            let c = get_config(transport(&mut d)?)?;
            if as_json {
                print_json(&c)?;
            } else if let serde_json::Value::Object(map) = serde_json::to_value(c)? {
                for (k, v) in map {
                    outln!("{k} = {v}");
                }
            }
            Ok(())
        }
        ConfigAction::Set { device, settings, file } => {
            let mut d = attach(&device)?;
            let t = transport(&mut d)?;
            let mut c = get_config(t)?;
            if let Some(path) = file {
                let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
                let v: serde_json::Value =
                    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
                c = config_changes(v).with_context(|| path.display().to_string())?.apply(&c);
            }
            let mut changes = serde_json::Map::new();
            for s in &settings {
                let (k, v) = s.split_once('=').with_context(|| format!("{s:?} is not KEY=VALUE"))?;
                let value = serde_json::from_str(v).with_context(|| format!("{k}: {v:?} is not a JSON value"))?;
                changes.insert(k.trim().to_string(), value);
            }
            c = config_changes(serde_json::Value::Object(changes))?.apply(&c);
            c.validate().context("not sent")?;
            request(t, &Message::Config(c))?;
            eprintln!("penctl: configuration applied (`penctl config save` keeps it across power cycles)");
            Ok(())
        }
        ConfigAction::Save { device } => {
            let mut d = attach(&device)?;
            request(transport(&mut d)?, &Message::Command(DeviceCommand::SaveConfig))
        }
        ConfigAction::Defaults { device } => {
            let mut d = attach(&device)?;
            request(transport(&mut d)?, &Message::Command(DeviceCommand::LoadDefaults))
        }
    }
}

/// The device to calibrate; the simulated user touches exactly the targets (and pivots on
/// `pivot`), on a display set up by hand a little off the tracker frame, as a real one would be.
#[cfg(feature = "sim")]
fn calibration_source(device: &DeviceArgs, targets: &[glam::DVec2], pivot: Option<glam::DVec2>) -> Result<Source> {
    if !device.is_sim() {
        return Ok(device.source()?);
    }
    Ok(run::sim_source(targets, pivot, device.speed()))
}

/// The device to calibrate.
#[cfg(not(feature = "sim"))]
fn calibration_source(device: &DeviceArgs, _targets: &[glam::DVec2], _pivot: Option<glam::DVec2>) -> Result<Source> {
    Ok(device.source()?)
}

fn calibrate_cmd(a: CalibrateArgs) -> Result<()> {
    let display = a.display.display();
    // Checked before the touches, not after the user has made them all.
    if let Err(e) = display.check() {
        let flag = match &e {
            CalibrationError::Display { key, .. } if key.ends_with("_px") => "--display-px",
            _ => "--display-mm",
        };
        return Err(UsageError(format!("{flag}: {e}")).into());
    }
    let targets = display.targets(a.display.targets as usize);
    let kind = match a.fit {
        Fit::Rigid => FitKind::Rigid,
        Fit::Similarity => FitKind::Similarity,
    };
    let pivot_at = (!a.no_pivot).then(|| display.pivot_target());
    let source = calibration_source(&a.device, &targets, pivot_at)?;
    let mut device = Device::new(source);
    calibrate::attach(&mut device, Duration::from_secs(2))?;
    let id = run::device_id(&mut device)?;
    // Chosen before the touches, so that a missing home is said at once.
    let out = match a.out {
        Some(p) => p,
        None => calibration::default_path_for(a.device.is_sim() || id.is_simulated())
            .context("neither XDG_CONFIG_HOME nor HOME is set; give --out")?,
    };
    let plan = run::Plan {
        display,
        targets,
        kind,
        pivot_at,
        patience: Duration::from_secs_f64(a.patience.max(1.0)),
        write_device: a.write_device,
    };
    let tty = std::io::stderr().is_terminal();
    let tell = |step: &Prompt| {
        // "taken" only where a person watches; a log has the targets and the table.
        let quiet = matches!(step, Prompt::Taken { .. } | Prompt::Pivoted { .. }) && !tty;
        if let Some(line) = step.says().filter(|_| !quiet) {
            eprintln!("{line}");
        }
    };
    let run::Outcome {
        calibration: cal,
        pivot,
    } = run::calibrate(&mut device, &plan, tell)?;
    if let (Some(p), Some(offset)) = (pivot, cal.tip_offset_mm) {
        outln!(
            "pivot: the emitter is {:.1} mm from the tip ({:.0}° of tilt, {:.2} mm RMS off the sphere); the pen's \
             emitter-to-tip vector ({:.1}, {:.1}, {:.1}) mm is taken out of the glasses' positions",
            p.radius_mm,
            p.tilt_deg,
            p.rms_mm,
            offset.x,
            offset.y,
            offset.z
        );
    }
    outln!("target (u, v) mm     residual mm");
    for r in &cal.residuals {
        outln!(
            "({:6.1}, {:6.1})        {:.3}",
            r.target_mm.x,
            r.target_mm.y,
            r.residual_mm
        );
    }
    outln!(
        "RMS {:.3} mm, max {:.3} mm, scale {:.5}",
        cal.rms_mm(),
        cal.max_mm(),
        cal.transform.scale
    );
    if (cal.transform.scale - 1.0).abs() > 0.005 {
        eprintln!(
            "penctl: the scale is {:.4}: check the configured temperature or speed of sound",
            cal.transform.scale
        );
    }
    // Replacing another base station's calibration is what the user asked for, but say so.
    if let Ok(old) = Calibration::load(&out)
        && let Some(other) = old.device.filter(|d| *d != id)
    {
        eprintln!(
            "penctl: {} was base station {other}'s; it is now this one's ({id})",
            out.display()
        );
    }
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    cal.save(&out).with_context(|| format!("saving {}", out.display()))?;
    outln!("saved {} (base station {id})", out.display());
    if let Some(png) = &a.plot {
        plot::write_residual_plot(&cal, png, 900).with_context(|| format!("writing {}", png.display()))?;
        outln!("plot {}", png.display());
    }
    if a.write_device {
        outln!("written to the device: it now reports display coordinates (`penctl config save` keeps them)");
    }
    Ok(())
}

fn decode(hex_args: &[String], frame: bool) -> Result<()> {
    let bytes = hex::parse_hex(&hex_args.join(" ")).context("not valid hex")?;
    let report = if frame { unframe(&bytes)? } else { bytes };
    let message = Message::decode(&report).context("not a valid report")?;
    print_json(&message)?;
    Ok(())
}

/// The payload of the one frame in `bytes`.
fn unframe(bytes: &[u8]) -> Result<Vec<u8>> {
    let mut dec = FrameDecoder::new();
    let mut payload = None;
    // A trailing delimiter ends the frame whether or not the input had one.
    for &b in bytes.iter().chain(std::iter::once(&0)) {
        if let Some(result) = dec.push(b) {
            anyhow::ensure!(payload.is_none(), "more than one frame in the input");
            payload = Some(result.context("not a valid frame")?.to_vec());
        }
    }
    payload.context("no frame in the input")
}

/// `penctl list` found no base station: not a failure of anything, but not success either, so a
/// script can tell it from both (exit status 3).
#[derive(Debug)]
struct NothingAttached;

impl std::fmt::Display for NothingAttached {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("no base station attached")
    }
}

impl std::error::Error for NothingAttached {}

/// The exit status of `penctl list` with nothing attached.
const EXIT_NOTHING_ATTACHED: u8 = 3;

fn list() -> Result<()> {
    let hids = hid::list()?;
    let serials = serial::list();
    if hids.is_empty() && serials.is_empty() {
        let hint = if cfg!(feature = "sim") {
            "; the simulated pen: --source sim"
        } else {
            ""
        };
        eprintln!("penctl: no base station attached (udev rules: docs/flashing.md{hint})");
        return Err(NothingAttached.into());
    }
    for h in hids {
        outln!(
            "hid     {}  {}{}",
            h.path,
            h.product,
            h.serial.map(|s| format!(" ({s})")).unwrap_or_default()
        );
    }
    for s in serials {
        outln!("serial  {s}");
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::List => list(),
        Command::Info { device, json } => info(&device, json),
        Command::Monitor { device, json, count } => monitor(&device, json, count),
        Command::Config { action } => config(action),
        Command::Head { state, device } => {
            let mut d = attach(&device)?;
            let (command, said) = if state == "on" {
                (
                    DeviceCommand::HeadOn,
                    "head tracking on: head reports follow (`penctl monitor`)",
                )
            } else {
                (DeviceCommand::HeadOff, "head tracking off: the pen has every cycle")
            };
            let status = transport(&mut d)?.set_feature(&Message::Command(command))?;
            match status.code {
                StatusCode::Ok => {}
                // The firmware knows the command; the base station has no glasses' emitter.
                StatusCode::Unsupported => {
                    bail!("this base station has no emitter for the glasses (the device answered: {status})")
                }
                _ => bail!("the device refused: {status}"),
            }
            eprintln!("penctl: {said}");
            Ok(())
        }
        Command::Bootloader { device } => {
            let mut d = attach(&device)?;
            request(transport(&mut d)?, &Message::Command(DeviceCommand::EnterBootloader))?;
            eprintln!("penctl: the device restarts into its DFU bootloader (dfu-util -l)");
            Ok(())
        }
        Command::Calibrate(a) => calibrate_cmd(a),
        Command::Delays(a) => pen_host::calibration::delays::cli::run(a),
        Command::Descriptor => {
            outln!("{}", hex::to_hex(&REPORT_DESCRIPTOR));
            Ok(())
        }
        Command::Decode { hex, frame } => decode(&hex, frame),
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader went away (`penctl monitor | head`): not an error, as for any Unix tool.
        Err(e) if pen_host::help::broken_pipe(&e) => ExitCode::SUCCESS,
        // Said on stderr already, with the hint.
        Err(e) if e.downcast_ref::<NothingAttached>().is_some() => ExitCode::from(EXIT_NOTHING_ATTACHED),
        // Flags that parse but do not go together: a usage error.
        Err(e) if e.downcast_ref::<UsageError>().is_some() || e.downcast_ref::<source::SourceError>().is_some() => {
            eprintln!("penctl: {e:#}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("penctl: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    #[test]
    fn the_command_line_is_well_formed_with_examples_in_every_help() {
        pen_host::help::check(super::Cli::command());
    }
}
