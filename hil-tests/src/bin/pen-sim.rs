//! `pen-sim`: the simulated pen and base station.
//!
//! Exit status: 0 on success, 1 on an error (reason on stderr), 2 on a usage error.

use std::io::{BufWriter, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use pen_hil::{accuracy, head, pty, qemu, trace};
use pen_sim::{Simulation, scenarios};

#[derive(Parser)]
#[command(
    name = "pen-sim",
    version,
    about = "The simulated 3D pen and base station",
    propagate_version = true,
    after_help = "Examples:\n  \
    pen-sim scenarios\n  \
    pen-sim serve --pty --scenario hold --link /tmp/pen   # then: pend --source serial:/tmp/pen\n  \
    pen-sim accuracy --json\n\
    The other tools play the same scenarios in process: --source sim:SCENARIO (docs/cli.md)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Serve the simulated pen on a pseudo-terminal until killed.
    ///
    /// Prints the device path (/dev/pts/N) on the first line of stdout, then streams the serial
    /// framing there in real time and answers requests, as the base station's serial link does.
    #[command(after_help = "Examples:\n  \
    pen-sim serve --pty\n  \
    pen-sim serve --pty --scenario hold --speed 0 --link /tmp/pen   # then: penctl monitor --source serial:/tmp/pen")]
    Serve {
        /// Create a pseudo-terminal (the only transport so far; required for clarity).
        #[arg(long, required = true)]
        pty: bool,
        /// The session to play, repeated.
        #[arg(long, default_value = "modeling-session")]
        scenario: String,
        /// Seed of the randomness.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Also create this symbolic link to the device.
        #[arg(long, value_name = "PATH")]
        link: Option<PathBuf>,
        /// Device seconds per real second (0: as fast as the host reads).
        #[arg(long, default_value_t = 1.0)]
        speed: f64,
    },
    /// Write a trace as JSON lines: a header, then one line per measurement cycle.
    #[command(after_help = "Example:\n  pen-sim trace --scenario hand-sweep --seconds 2 > sweep.jsonl")]
    Trace {
        /// The session.
        #[arg(long)]
        scenario: String,
        /// How long to run, device seconds.
        #[arg(long)]
        seconds: f64,
        /// Seed of the randomness.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Run the standard scenarios and print their accuracy figures.
    #[command(after_help = "Examples:\n  pen-sim accuracy\n  pen-sim accuracy --json --scenario echoes")]
    Accuracy {
        /// Print {"scenarios": [...]} as JSON.
        #[arg(long)]
        json: bool,
        /// Seed of the randomness.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Scenarios to run (default: static-grid, hand-sweep, echoes).
        #[arg(long = "scenario", value_name = "NAME")]
        scenarios: Vec<String>,
    },
    /// Measure the tracked head: the pen alone, then with a seated viewer's glasses multiplexed
    /// at each ratio; print the pen's and the head's fix rates and errors.
    #[command(
        after_help = "Examples:\n  pen-sim head\n  pen-sim head --ratio 2:1 --prediction-ms 30 --seconds 30 --json"
    )]
    Head {
        /// The pen's session (it loops for --seconds).
        #[arg(long, default_value = "hand-sweep")]
        scenario: String,
        /// Device seconds per run.
        #[arg(long, default_value_t = 20.0)]
        seconds: f64,
        /// Seed of the randomness.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Pen:head slot ratios to compare (default 1:1, 2:1, 5:2, 3:1).
        #[arg(long = "ratio", value_name = "PEN:HEAD")]
        ratios: Vec<String>,
        /// How far ahead the head's pose is predicted, ms (0…50).
        #[arg(long, default_value_t = 20)]
        prediction_ms: u8,
        /// Probability per receiver and burst of a room reflection arriving up to 1.5 ms after
        /// the direct sound, which the next slot can hear first (0…1; 0: none).
        #[arg(long, default_value_t = 0.0)]
        reverb: f64,
        /// The reflections' path beyond the direct one: up to this, mm (515: 1.5 ms).
        #[arg(long, default_value_t = 515.0)]
        reverb_tail_mm: f64,
        /// Print the runs as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// Replay a scenario's cycles through the core on QEMU's Cortex-M4F (mps2-an386), compare
    /// its reports with this host build's, and print the instructions a fix costs there.
    #[command(after_help = "Example (needs qemu-system-arm):\n  pen-sim qemu --scenario hand-sweep --seconds 2 --json")]
    Qemu {
        /// The session.
        #[arg(long, default_value = "hand-sweep")]
        scenario: String,
        /// How long to run, device seconds.
        #[arg(long, default_value_t = 5.0)]
        seconds: f64,
        /// Seed of the randomness.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The pen-qemu image to run [default: built from the repository's firmware/].
        #[arg(long, value_name = "FILE")]
        elf: Option<std::path::PathBuf>,
        /// Print the figures as one JSON object.
        #[arg(long)]
        json: bool,
    },
    /// List the scenarios.
    #[command(after_help = "Example:\n  pen-sim scenarios")]
    Scenarios,
}

fn scenario(name: &str) -> Result<pen_sim::Scenario> {
    match scenarios::by_name(name) {
        Some(s) => Ok(s),
        None => bail!("unknown scenario {name:?}; `pen-sim scenarios` lists them"),
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Serve {
            pty: _,
            scenario: name,
            seed,
            link,
            speed,
        } => {
            if !(speed >= 0.0 && speed.is_finite()) {
                bail!("--speed must be a finite number ≥ 0");
            }
            let options = pty::ServeOptions {
                scenario: scenario(&name)?,
                seed,
                link,
                speed,
            };
            pty::serve(
                &options,
                |path| {
                    println!("{}", path.display());
                    let _ = std::io::stdout().flush();
                },
                |c| {
                    eprintln!(
                        "pen-sim: {} frames sent, {} dropped (host not reading), {} requests, {} bad frames",
                        c.frames, c.dropped, c.requests, c.bad_frames
                    )
                },
            )?;
            Ok(())
        }
        Command::Trace {
            scenario: name,
            seconds,
            seed,
        } => {
            if !(seconds > 0.0 && seconds.is_finite()) {
                bail!("--seconds must be a positive number");
            }
            let s = scenario(&name)?;
            let mut sim = Simulation::new(&s, seed);
            let mut out = BufWriter::new(std::io::stdout().lock());
            writeln!(out, "{}", trace::header(&sim))?;
            let end = (seconds * 1e6) as u64;
            while sim.now_us() < end {
                let r = sim.step();
                writeln!(out, "{}", trace::line(&r, s.rig.receivers_mm.len()))?;
            }
            out.flush().context("writing the trace")?;
            Ok(())
        }
        Command::Accuracy {
            json,
            seed,
            scenarios: names,
        } => {
            let names = if names.is_empty() {
                vec!["static-grid".to_string(), "hand-sweep".into(), "echoes".into()]
            } else {
                names
            };
            let bar = if std::io::stderr().is_terminal() {
                ProgressBar::new(names.len() as u64)
            } else {
                ProgressBar::hidden()
            };
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}").unwrap_or(ProgressStyle::default_bar()),
            );
            let mut results = Vec::new();
            for name in &names {
                bar.set_message(name.clone());
                let s = scenario(name)?;
                let mut sim = Simulation::new(&s, seed);
                let records = sim.run_for(s.timeline.duration_s());
                results.push(accuracy::evaluate(&s, &records));
                bar.inc(1);
            }
            bar.finish_and_clear();
            if json {
                println!("{}", serde_json::json!({ "scenarios": results }));
            } else {
                println!(
                    "{:<18} {:>8} {:>8} {:>6} {:>7} {:>7} {:>7} {:>9} {:>6} {:>6}",
                    "scenario",
                    "rmse_mm",
                    "crlb_mm",
                    "ratio",
                    "p50_mm",
                    "p99_mm",
                    "max_mm",
                    "fixes/s",
                    "false",
                    "missed"
                );
                for m in &results {
                    println!(
                        "{:<18} {:>8.3} {:>8.3} {:>6.3} {:>7.3} {:>7.3} {:>7.3} {:>9.1} {:>6} {:>6}",
                        m.name,
                        m.rmse_mm,
                        m.crlb_mm,
                        m.rmse_mm / m.crlb_mm,
                        m.p50_mm,
                        m.p99_mm,
                        m.max_mm,
                        m.fix_rate_hz,
                        m.false_switch_events,
                        m.missed_switch_events
                    );
                }
            }
            Ok(())
        }
        Command::Head {
            scenario: name,
            seconds,
            seed,
            ratios,
            prediction_ms,
            reverb,
            reverb_tail_mm,
            json,
        } => {
            if !(0.0..=1.0).contains(&reverb) {
                bail!("--reverb must be a probability, 0…1");
            }
            if !(reverb_tail_mm > 0.0 && reverb_tail_mm <= 10_000.0) {
                bail!("--reverb-tail-mm must be 0…10000 mm");
            }
            if !(seconds > 0.0 && seconds.is_finite()) {
                bail!("--seconds must be a positive number");
            }
            if prediction_ms > pen_protocol::MAX_PREDICTION_MS {
                bail!("--prediction-ms must be 0…{}", pen_protocol::MAX_PREDICTION_MS);
            }
            let ratios = if ratios.is_empty() {
                vec!["1:1".to_string(), "2:1".into(), "5:2".into(), "3:1".into()]
            } else {
                ratios
            };
            let schedules = ratios
                .iter()
                .map(|r| head::parse_ratio(r).map_err(|e| anyhow::anyhow!("--ratio: {e}")))
                .collect::<Result<Vec<_>>>()?;
            let mut pen_only = scenario(&name)?;
            pen_only.acoustics.reverb_rate = reverb;
            pen_only.acoustics.reverb_tail_mm = reverb_tail_mm;
            let mut runs = vec![("pen alone".to_string(), head::run(&pen_only, seed, seconds))];
            for (label, schedule) in ratios.iter().zip(schedules) {
                let s = pen_only.clone().with_head(pen_core::HeadSettings {
                    schedule,
                    prediction_ms,
                });
                runs.push((label.clone(), head::run(&s, seed, seconds)));
            }
            if json {
                let runs: Vec<_> = runs
                    .iter()
                    .map(|(ratio, r)| serde_json::json!({ "ratio": ratio, "pen": r.pen, "head": r.head }))
                    .collect();
                println!(
                    "{}",
                    serde_json::json!({ "scenario": name, "seconds": seconds, "runs": runs })
                );
            } else {
                println!(
                    "{:<10} {:>9} {:>8} {:>8} {:>9} {:>8} {:>9} {:>8} {:>8}",
                    "ratio",
                    "pen fix/s",
                    "pen rmse",
                    "pen p99",
                    "head fix/s",
                    "head raw",
                    "head pred",
                    "held",
                    "shadowed"
                );
                let base = &runs[0].1.pen;
                for (ratio, r) in &runs {
                    let (rate, raw, pred, held, shadow) = r.head.as_ref().map_or(
                        (
                            "-".to_string(),
                            "-".to_string(),
                            "-".to_string(),
                            "-".to_string(),
                            "-".to_string(),
                        ),
                        |h| {
                            (
                                format!("{:.1}", h.fix_rate_hz),
                                format!("{:.2}", h.raw_rmse_mm),
                                format!("{:.2}", h.predicted_rmse_mm),
                                format!("{:.2}", h.held_rmse_mm),
                                format!("{:.0} %", h.shadowed_fraction * 100.0),
                            )
                        },
                    );
                    println!(
                        "{:<10} {:>9.1} {:>8.3} {:>8.3} {:>9} {:>8} {:>9} {:>8} {:>8}",
                        ratio, r.pen.fix_rate_hz, r.pen.rmse_mm, r.pen.p99_mm, rate, raw, pred, held, shadow
                    );
                    let _ = base;
                }
                println!(
                    "errors in mm; head pred: the reported pose (predicted {prediction_ms} ms ahead) against the head then; held: the raw fix held as long"
                );
            }
            Ok(())
        }
        Command::Qemu {
            scenario: name,
            seconds,
            seed,
            elf,
            json,
        } => {
            let s = scenario(&name)?;
            let mut sim = Simulation::new(&s, seed);
            let records = sim.run_for(seconds);
            let host: Vec<pen_sim::Sent> = records.iter().flat_map(|r| r.sent.clone()).collect();
            let elf = match elf {
                Some(e) => e,
                None => qemu::build_pen_qemu()?,
            };
            let run = qemu::run(
                &elf,
                &qemu::replay(&s.config, s.head, &records),
                std::time::Duration::from_secs(600),
            )?;
            let identical = run.reports == host;
            let first_difference = host.iter().zip(&run.reports).position(|(a, b)| a != b);
            if json {
                println!(
                    "{}",
                    serde_json::json!({
                        "scenario": name, "cycles": run.cycles, "reports": run.reports.len(),
                        "identical": identical, "first_difference": first_difference,
                        "instructions_per_fix_mean": run.mean_instructions(),
                        "instructions_per_fix_max": run.worst_instructions(),
                    })
                );
            } else {
                println!(
                    "{} cycles, {} reports from the emulated core, {} from the host build",
                    run.cycles,
                    run.reports.len(),
                    host.len()
                );
                println!("reports bit-identical: {identical}");
                println!(
                    "fusion per cycle on the Cortex-M4F: {:.0} instructions on average, {:.0} at most ({:.2} per SysTick count)",
                    run.mean_instructions(),
                    run.worst_instructions(),
                    run.instructions_per_count()
                );
            }
            if !identical {
                bail!("the emulated core's reports differ from the host's (first at report {first_difference:?})");
            }
            Ok(())
        }
        Command::Scenarios => {
            for (name, about) in scenarios::NAMES {
                println!("{name:<18} {about}");
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("pen-sim: {e:#}");
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
