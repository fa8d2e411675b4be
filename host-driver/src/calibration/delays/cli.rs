//! `penctl delays`: the command around [`super`]'s procedure and fit — its flags, what it tells
//! the user, the table of delays and residuals, and the write to the device.

use std::io::Write;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::Args;
use glam::DVec3;

use super::{DelayFit, Prompt};
use crate::device::Device;
use crate::source::{DeviceArgs, SimSwitch};

/// Residuals above this suggest a point or a receiver surveyed wrongly, µs (1 mm of range).
const SUSPECT_RESIDUAL_US: f64 = 3.0;

/// `penctl delays`' flags.
#[derive(Args)]
#[command(after_help = "Example (emitter positions in the tracker frame, mm):\n  \
                        penctl delays --at 100,60,40 --at 500,60,120 --at 500,280,40 --at 100,280,200 --at 300,170,300")]
pub struct DelaysArgs {
    /// Which device.
    #[command(flatten)]
    pub device: DeviceArgs<SimSwitch>,
    /// A surveyed point where the pen's emitter will be held, X,Y,Z in mm (tracker frame);
    /// at least 3, given once each.
    #[arg(long = "at", value_name = "X,Y,Z", required = true, value_parser = parse_point)]
    pub points: Vec<DVec3>,
    /// Print the delays and residuals without writing them to the device.
    #[arg(long)]
    pub dry_run: bool,
    /// Seconds to wait for each hold.
    #[arg(long, default_value_t = 60.0)]
    pub patience: f64,
}

/// `X,Y,Z` in mm.
fn parse_point(s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("{s:?} is not X,Y,Z (three numbers in mm, separated by commas)"));
    };
    let num = |v: &str| {
        v.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{v:?} in {s:?} is not a finite number of mm"))
    };
    Ok(DVec3::new(num(x)?, num(y)?, num(z)?))
}

/// Runs `penctl delays`.
pub fn run(a: DelaysArgs) -> Result<()> {
    super::check_points(&a.points)?;
    let source = sim_or_device(&a)?;
    let mut device = Device::new(source);
    crate::calibration::procedure::attach(&mut device, Duration::from_secs(2))?;
    let config = super::read_config(&mut device)?;
    let receivers = super::receivers(&config);
    let air = match config.speed_of_sound_m_s {
        Some(c) => format!("speed of sound {c:.1} m/s"),
        None => format!("temperature_c {:.1} °C", config.temperature_c),
    };
    eprintln!(
        "penctl: {} receivers; the device's {air}: set the room's first if it is not (`penctl config set temperature_c=…`)",
        receivers.len()
    );
    let patience = Duration::from_secs_f64(a.patience.max(1.0));
    let held = super::collect(&mut device, &config, &a.points, patience, |p| match p {
        Prompt::Hold { index, count, point_mm } => eprintln!(
            "point {}/{count}: hold the pen's emitter at ({:.1}, {:.1}, {:.1}) mm, press SW1 and keep still",
            index + 1,
            point_mm.x,
            point_mm.y,
            point_mm.z
        ),
        Prompt::Lift => eprintln!("  release SW1 first"),
        Prompt::Again { cycles } => eprintln!("  too short ({cycles} cycles): press again and hold still a moment"),
        Prompt::Taken { cycles } => eprintln!("  taken ({cycles} cycles)"),
    })?;
    let fit = super::fit(&receivers, &held)?;
    print_fit(&config.transducer_delay_us, &held, &fit)?;
    if fit.max_abs_us() > SUSPECT_RESIDUAL_US {
        eprintln!(
            "penctl: residuals above {SUSPECT_RESIDUAL_US} µs (1 mm): check the points' survey, the receivers' positions (`penctl config get`) and that the pen was held still with its emitter on the point"
        );
    }
    if a.dry_run {
        println!("not written to the device (--dry-run)");
        return Ok(());
    }
    super::write_config(&mut device, &super::with_delays(&config, &fit)).context("writing the delays")?;
    println!("written to the device's transducer_delay_us (`penctl config save` keeps them)");
    Ok(())
}

fn print_fit(before_us: &[f32], held: &[super::Held], fit: &DelayFit) -> Result<()> {
    let mut out = std::io::stdout().lock();
    let speed = held.iter().map(|h| h.speed_m_s).sum::<f64>() / held.len().max(1) as f64;
    // µs of flight → mm of range.
    let mm = |us: f64| us * speed * 1e-3;
    writeln!(out, "receiver  delay µs  was µs  RMS residual µs (mm)")?;
    for (i, d) in fit.delays_us.iter().enumerate() {
        let rms = fit.rms_us(i);
        writeln!(
            out,
            "{i:8}  {d:8.2}  {:6.2}  {rms:6.2} ({:.2})",
            before_us.get(i).copied().unwrap_or(0.0),
            mm(rms)
        )?;
    }
    writeln!(
        out,
        "point  emitter mm               DOP  cycles  residual µs per receiver"
    )?;
    for (k, h) in held.iter().enumerate() {
        let residuals: Vec<String> = fit.residuals_us[k]
            .iter()
            .map(|r| r.map(|r| format!("{r:+6.2}")).unwrap_or_else(|| "     –".into()))
            .collect();
        writeln!(
            out,
            "{:5}  ({:6.1}, {:6.1}, {:6.1})  {:4.1}  {:6}  {}",
            k + 1,
            h.point_mm.x,
            h.point_mm.y,
            h.point_mm.z,
            fit.dop[k],
            h.cycles,
            residuals.join(" ")
        )?;
    }
    writeln!(out, "speed of sound {speed:.1} m/s (as the device solved)")?;
    let max = fit.max_abs_us();
    writeln!(out, "max residual {max:.2} µs ({:.2} mm)", mm(max))?;
    Ok(())
}

/// The simulated pen holds the points itself; any other device is held by the user.
#[cfg(feature = "sim")]
fn sim_or_device(a: &DelaysArgs) -> Result<crate::source::Source> {
    if a.device.is_sim() {
        return Ok(super::sim_source(&a.points, a.device.speed()));
    }
    Ok(a.device.source()?)
}

#[cfg(not(feature = "sim"))]
fn sim_or_device(a: &DelaysArgs) -> Result<crate::source::Source> {
    Ok(a.device.source()?)
}
