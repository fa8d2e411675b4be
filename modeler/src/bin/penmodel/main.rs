//! `penmodel`: the terrain modeler from the command line.
//!
//! Exit status: 0 on success, 1 when the input is not valid or a file cannot be read or written
//! (the reason on stderr), 2 on a usage error.

mod bench;
mod generate;
mod render;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "penmodel",
    version,
    about = "The 3D pen's terrain modeler",
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate a document's terrain and export it.
    Generate(generate::Args),
    /// Render a document's terrain into a PNG.
    Render(render::Args),
    /// Measure the renderer's frame time and the terrain update while pulling.
    Bench(bench::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Generate(args) => generate::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Bench(args) => bench::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("penmodel: {e:#}");
            ExitCode::FAILURE
        }
    }
}
