//! `penmodel`: the terrain modeler from the command line.
//!
//! Without a subcommand it models terrain with the pen (the built-in demo when no pen is
//! attached); `penmodel open DOC.json` continues a saved document.
//!
//! Exit status: 0 on success, 1 when the input is not valid, a file cannot be read or written, or
//! the pen fails (the reason on stderr), 2 on a usage error.

mod analyze;
mod bench;
mod calibrate;
mod erode;
mod generate;
mod import;
mod live;
mod out;
mod render;
mod ridges;
mod river;
mod rocks;
mod trees;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "penmodel",
    version,
    about = "The 3D pen's terrain modeler",
    propagate_version = true,
    args_conflicts_with_subcommands = true,
    after_help = "Without a subcommand: model terrain with the pen (the built-in demo when no pen is attached).\n\
    Examples:\n  penmodel                              # the demo: a window, or files in ./out without a display\n  \
    penmodel --show headless --out run1   # the demo written to run1/\n  \
    penmodel --source daemon              # the pen from pend\n  \
    penmodel --source sim:hold --speed 0  # a pen-sim scenario, uncalibrated\n  \
    penmodel open out/document.json       # continue a document\n\
    Flags the tools share (--source, --speed, --vertical-scale, --head-mm, --out; --display-mm for render): docs/cli.md."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    live: live::LiveArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Continue modeling a saved document with the pen.
    #[command(
        after_help = "Without pend or --source, a window opens the document with the mouse as the pen \
    (docs/modeler.md, Mouse); headless it is refused.\n\
    Examples:\n  \
    penmodel open out/document.json                         # with pend's pen, or the mouse\n  \
    penmodel open out/document.json --source serial:/dev/ttyACM0\n  \
    penmodel open out/document.json --show headless --source daemon --out run2"
    )]
    Open {
        /// The document (JSON); its journal, if any, is replayed first.
        #[arg(value_name = "DOC.json")]
        document: std::path::PathBuf,
        /// Open a document whose journal has a bad line (a checksum or sequence number that does
        /// not match, an edit that does not apply) up to its last good line: the journal as it
        /// was is kept as DOC.json.journal.corrupt, and what was left out is said.
        #[arg(long)]
        recover: bool,
        #[command(flatten)]
        live: live::LiveArgs,
    },
    /// Calibrate the pen on the display itself: the targets drawn full screen one at a time, the residual plot at the end.
    Calibrate(calibrate::Args),
    /// Generate a document's terrain and export it.
    Generate(generate::Args),
    /// Make a document from a heightmap (16-bit PNG, float32 GeoTIFF, raw float32): the sketch is added on top.
    Import(import::Args),
    /// Render a document's terrain into a PNG.
    Render(render::Args),
    /// Measure the renderer's frame time and the terrain update while pulling.
    Bench(bench::Args),
    /// Scatter rocks of mixed sizes on a field (seed 001) and write them out.
    Rocks(rocks::Args),
    /// Maps of a document's terrain: rain pass counts, ridge and valley areas, sunlight, sky view (seed 002).
    Analyze(analyze::Args),
    /// A document's ridgeline trees' elevations, or ridgelines grown from them (seed 002).
    Ridges(ridges::Args),
    /// Shape one river of a document by erosion and deposition (seed 003) and write its masks.
    River(river::Args),
    /// Fractal trees (seed 004): counts per roughness Q, a tree or grove as a mesh, a fit to silhouettes.
    Trees(trees::Args),
    /// Erode a document's sketched land by running water and soil creep, with its drainage signatures.
    Erode(erode::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => live::run(&cli.live, None, false),
        Some(Command::Open {
            document,
            recover,
            live,
        }) => live::run(&live, Some(&document), recover),
        Some(Command::Calibrate(args)) => calibrate::run(&args),
        Some(Command::Generate(args)) => generate::run(&args),
        Some(Command::Import(args)) => import::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Rocks(args)) => rocks::run(&args),
        Some(Command::Analyze(args)) => analyze::run(&args),
        Some(Command::Ridges(args)) => ridges::run(&args),
        Some(Command::River(args)) => river::run(&args),
        Some(Command::Trees(args)) => trees::run(&args),
        Some(Command::Erode(args)) => erode::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader went away (`penmodel … | head`): not an error, as for any Unix tool.
        Err(e) if pen_host::help::broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("penmodel: {e:#}");
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
