//! `penctl`: inspect and control the 3D pen from the command line.
//!
//! Exit status: 0 on success, 1 when the input is not valid (bad hex, not a report), 2 on a
//! usage error.

use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use pen_host::{hex, json};
use pen_protocol::{FrameDecoder, Message, REPORT_DESCRIPTOR};

#[derive(Parser)]
#[command(
    name = "penctl",
    version,
    about = "Inspect and control the 3D pen",
    propagate_version = true
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the USB HID report descriptor as one line of hex.
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

fn decode(hex_args: &[String], frame: bool) -> Result<()> {
    let bytes = hex::parse_hex(&hex_args.join(" ")).context("not valid hex")?;
    let report = if frame { unframe(&bytes)? } else { bytes };
    let message = Message::decode(&report).context("not a valid report")?;
    println!("{}", json::message_json(&message));
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Descriptor => {
            println!("{}", hex::to_hex(&REPORT_DESCRIPTOR));
            Ok(())
        }
        Command::Decode { hex, frame } => decode(&hex, frame),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("penctl: {e:#}");
            ExitCode::FAILURE
        }
    }
}
