//! `pend`: the pen daemon. Attaches to the base station (USB HID by default, `--source
//! serial:PATH`, or `--source sim` for the simulated pen), applies the calibration, and serves pen events to any number
//! of clients (a bounded number at once) on a Unix domain socket as JSON lines (docs/events.md). SIGTERM and SIGINT stop it:
//! the socket is removed and the exit status is 0. SIGHUP reloads the calibration.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{Context, Result};
use clap::Parser;
use pen_host::calibration::{Calibration, DisplaySize};
use pen_host::daemon::{self, DEFAULT_MAX_CLIENTS, DEFAULT_QUEUE, Hub, MAX_QUEUE};
use pen_host::pipeline::Pipeline;
use pen_host::source::{DeviceArgs, SimScenario, Source, SourceError};
use pen_host::virtual_tablet::{self, Extent, VirtualTablet};

/// `pend --help`'s end: what the defaults mean, and examples.
#[cfg(feature = "sim")]
const AFTER_HELP: &str = "The simulated pen (--source sim) plays `modeling-session` here: a session of modeling gestures, \
    the events a modeler sees, for each client from its start (with --virtual-tablet one session, from pend's start). While the base station is not there, pend says what it waits for and why every \
    5 s; access without root: host-driver/udev/70-penscape.rules.\n\
    Examples:\n  \
    pend                                     # the first base station on USB\n  \
    pend --source serial:/dev/ttyACM0        # its serial link\n  \
    pend --source sim                        # the simulated pen, in real time\n  \
    pend --source sim:hold --speed 0 --socket $XDG_RUNTIME_DIR/sim.sock\n  \
    pend --virtual-tablet                    # and a uinput pen for every program\n\
    docs/events.md (the socket's lines) and docs/cli.md (the flags every tool shares).";
/// `pend --help`'s end, in a build without the simulated pen.
#[cfg(not(feature = "sim"))]
const AFTER_HELP: &str = "While the base station is not there, pend says what it waits for and why every 5 s; access without \
root: host-driver/udev/70-penscape.rules.\n\
Examples:\n  \
pend                                     # the first base station on USB\n  \
pend --source serial:/dev/ttyACM0        # its serial link\n\
pend --virtual-tablet                    # and a uinput pen for every program\n\
docs/events.md (the socket's lines) and docs/cli.md (the flags every tool shares).";

#[derive(Parser)]
#[command(
    name = "pend",
    version,
    about = "The 3D pen's daemon: pen events for every program, on a Unix socket",
    after_help = AFTER_HELP
)]
struct Cli {
    /// The socket [default: $XDG_RUNTIME_DIR/penscape/pend.sock].
    #[arg(long, value_name = "PATH")]
    socket: Option<PathBuf>,
    #[command(flatten)]
    device: DeviceArgs<SimScenario>,
    /// The calibration file [default: $XDG_CONFIG_HOME/penscape/calibration.toml if it exists,
    /// calibration-sim.toml for --source sim; otherwise tracker coordinates are display coordinates].
    /// It is applied only to the base station it records.
    #[arg(long, value_name = "FILE")]
    calibration: Option<PathBuf>,
    /// Events a client may have waiting before it misses some (at most 16384; each queue holds
    /// at most N × 512 bytes of lines).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_QUEUE as u64,
          value_parser = clap::value_parser!(u64).range(1..=MAX_QUEUE as u64))]
    queue: u64,
    /// Clients served at once; one more is sent a `refused` line and closed.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_MAX_CLIENTS as u16,
          value_parser = clap::value_parser!(u16).range(1..))]
    max_clients: u16,
    /// Also move a uinput pen, "penscape pen", with the calibrated events, for programs that
    /// read the OS's pen (Krita, Blender, GIMP): needs write access to /dev/uinput
    /// (host-driver/udev/70-penscape.rules); docs/events.md.
    #[arg(long)]
    virtual_tablet: bool,
}

/// The calibration file pend uses: the one given, or the default if it exists (looked for
/// again at each SIGHUP, so one made since is taken).
fn calibration_path(given: Option<&Path>, source: &Source) -> Option<PathBuf> {
    given
        .map(Path::to_path_buf)
        .or_else(|| pen_host::calibration::default_path_for_source(source).filter(|p| p.exists()))
}

/// Loads the calibration at `path`, or the identity without one; says which on stderr.
fn load_calibration(path: Option<&Path>) -> Result<(Calibration, String)> {
    match path {
        Some(path) => {
            let c = Calibration::load(path)?;
            let whose = c.device.map(|d| format!(", base station {d}")).unwrap_or_default();
            let fit = match c.residuals.len() {
                0 => "no fit targets".to_string(),
                _ => format!("RMS {:.2} mm", c.rms_mm()),
            };
            if let Some(warning) = c.unbound_warning(path) {
                eprintln!("pend: warning: {warning}");
            }
            Ok((c, format!("calibration {} ({fit}{whose})", path.display())))
        }
        None => Ok((
            Calibration::identity(DisplaySize::REFERENCE),
            "no calibration; tracker coordinates are display coordinates (penctl calibrate)".to_string(),
        )),
    }
}

fn run(cli: Cli) -> Result<()> {
    let source = cli.device.source()?;
    let (calibration, what) = load_calibration(calibration_path(cli.calibration.as_deref(), &source).as_deref())?;
    eprintln!("pend: {what}");
    // Made before anything is served, so that a refusal (no access to /dev/uinput) ends pend
    // at once with the reason.
    let mut tablet = match cli.virtual_tablet {
        true => {
            let extent = Extent {
                width_mm: calibration.display.width_mm,
                height_mm: calibration.display.height_mm,
            };
            let t = VirtualTablet::open(extent)?;
            eprintln!(
                "pend: virtual tablet \"{}\": {:.0} × {:.0} mm of the display, {} units per mm",
                virtual_tablet::NAME,
                extent.width_mm,
                extent.height_mm,
                virtual_tablet::UNITS_PER_MM
            );
            Some(t)
        }
        false => None,
    };
    let socket = cli.socket.clone().unwrap_or_else(daemon::default_socket);
    let listener = daemon::bind(&socket)?;
    eprintln!("pend: serving {source} on {}", socket.display());

    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        signal_hook::flag::register(signal, stop.clone()).context("installing signal handlers")?;
    }
    // The simulated pen plays a script: each client gets it from its start, in a session of its
    // own. The virtual tablet follows one pen from pend's start, so with it the session is shared.
    if cli.device.is_sim() && tablet.is_none() {
        return serve_sessions(source, calibration, what, &socket, listener, &cli, &stop);
    }
    // SIGHUP reloads the calibration, as daemons reread their configuration; by default it
    // would end pend and leave its socket behind.
    let reload = Arc::new(AtomicBool::new(false));
    signal_hook::flag::register(signal_hook::consts::SIGHUP, reload.clone()).context("installing signal handlers")?;
    let (reloads_tx, reloads) = std::sync::mpsc::channel();
    let given = cli.calibration.clone();
    let sources = source.clone();
    let hub = Arc::new(Hub::new(usize::from(cli.max_clients)));
    let (h, s) = (hub.clone(), stop.clone());
    // In range by the parser: at most MAX_QUEUE.
    let queue = usize::try_from(cli.queue).unwrap_or(MAX_QUEUE);
    std::thread::spawn(move || daemon::accept(listener, h, queue, s));
    let (h, s) = (hub.clone(), stop.clone());
    // The transport lives on the device thread: the simulated pen is not Send.
    std::thread::spawn(move || {
        let mut failed = false;
        daemon::run_device_reloading(
            Pipeline::new(source, calibration),
            h,
            s,
            |m| eprintln!("pend: {m}"),
            |e| {
                if let Some(t) = tablet.as_mut()
                    && let Err(err) = t.event(e)
                    && !failed
                {
                    // Said once; the socket's clients are served on.
                    eprintln!("pend: the virtual tablet failed: {err}");
                    failed = true;
                }
            },
            &reloads,
        )
    });

    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
        if reload.swap(false, Ordering::Relaxed) {
            let path = calibration_path(given.as_deref(), &sources);
            match load_calibration(path.as_deref()) {
                // The device thread applies it between polls and says whether it took it.
                Ok(loaded) => {
                    let _ = reloads_tx.send(loaded);
                }
                Err(e) => eprintln!("pend: SIGHUP: kept the calibration in use: {e:#}"),
            }
        }
    }
    let _ = std::fs::remove_file(&socket);
    let (delivered, missed) = hub.counts();
    let refused = hub.refused();
    eprintln!(
        "pend: stopped; {delivered} events delivered, {missed} missed by slow clients, {refused} clients refused (more than {} at once)",
        hub.max_clients()
    );
    Ok(())
}

/// `pend --source sim`: each client a session of its own from the scenario's start, until
/// SIGTERM or SIGINT; SIGHUP's calibration goes to the running sessions and the next ones.
fn serve_sessions(
    source: Source,
    calibration: Calibration,
    what: String,
    socket: &Path,
    listener: pen_host::socket::Bound,
    cli: &Cli,
    stop: &Arc<AtomicBool>,
) -> Result<()> {
    let reload = Arc::new(AtomicBool::new(false));
    signal_hook::flag::register(signal_hook::consts::SIGHUP, reload.clone()).context("installing signal handlers")?;
    // Said once before any client: the device attaches, or why it is refused.
    let (probed, c) = (source.clone(), calibration.clone());
    let probe = std::thread::spawn(move || {
        daemon::probe(Pipeline::new(probed, c), Duration::from_secs(10), |m| {
            eprintln!("pend: {m}")
        })
    });
    let _ = probe.join();
    eprintln!("pend: each client gets a session of its own, from the scenario's start");
    let current = Arc::new(daemon::CurrentCalibration::new(calibration, what));
    let sessions = Arc::new(daemon::Sessions::new(usize::from(cli.max_clients)));
    // In range by the parser: at most MAX_QUEUE.
    let queue = usize::try_from(cli.queue).unwrap_or(MAX_QUEUE);
    let sources = source.clone();
    let (sn, s, cur) = (sessions.clone(), stop.clone(), current.clone());
    std::thread::spawn(move || {
        daemon::accept_sessions(listener, sn, queue, s.clone(), |hub, n| {
            let (source, stop, current) = (source.clone(), s.clone(), cur.clone());
            // The transport lives on the session's thread: the simulated pen is not Send.
            let spawned = std::thread::Builder::new()
                .name(format!("pend-session-{n}"))
                .spawn(move || {
                    let (taken, calibration, _) = current.get();
                    daemon::run_session(Pipeline::new(source, calibration), hub, stop, &current, taken, |m| {
                        eprintln!("pend: client {n}: {m}")
                    })
                });
            if spawned.is_err() {
                eprintln!("pend: client {n}: no thread for its session");
            }
        })
    });
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(50));
        if reload.swap(false, Ordering::Relaxed) {
            let path = calibration_path(cli.calibration.as_deref(), &sources);
            match load_calibration(path.as_deref()) {
                Ok((c, what)) => {
                    eprintln!("pend: SIGHUP: reloaded: {what} (the sessions running and the next ones)");
                    current.set(c, what);
                }
                Err(e) => eprintln!("pend: SIGHUP: kept the calibration in use: {e:#}"),
            }
        }
    }
    let _ = std::fs::remove_file(socket);
    let (delivered, missed) = sessions.counts();
    eprintln!(
        "pend: stopped; {} sessions, {delivered} events delivered, {missed} missed by slow clients, {} clients \
         refused (more than {} at once)",
        sessions.started(),
        sessions.refused(),
        sessions.max_clients()
    );
    Ok(())
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        // Flags that parse but do not go together (--speed without the simulated pen): a usage
        // error.
        Err(e) if e.downcast_ref::<SourceError>().is_some() => {
            eprintln!("pend: {e:#} (pend --help)");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("pend: {e:#}");
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
