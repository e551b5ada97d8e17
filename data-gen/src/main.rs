//! `data-gen`: deterministic synthetic data with exact ground truth for subdyn.
//!
//! Subcommands: `shape` (closed reference meshes), `scan` (simulated range
//! scans of a shape or a mesh file), `demo` (the data set embedded in subdyn),
//! `volume` (intensity volumes). Errors are one line on stderr and a non-zero
//! exit code.

mod demo;
mod measure;
mod rng;
mod scan;
mod shape_cmd;
mod shapes;
mod sidecar;
mod topology;
mod truth;
mod volume;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Deterministic synthetic data with exact ground truth for subdyn.
#[derive(Parser, Debug)]
#[command(
    name = "data-gen",
    version,
    about = "Deterministic synthetic data with exact ground truth for subdyn: shapes, range scans, volumes, the demo data set",
    long_about = None
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Write a closed reference mesh (sphere, ellipsoid, torus, genus2, bulb, anvil, or --from FILE) and its JSON sidecar.
    Shape(shape_cmd::ShapeArgs),
    /// Simulate a multi-view range scan of a shape or a mesh: binary PLY with per-point view ids, ground-truth mesh, JSON sidecar.
    Scan(scan::ScanArgs),
    /// Regenerate the demo data set embedded in subdyn (a multi-view scan of Spot).
    Demo(demo::DemoArgs),
    /// Rasterise a closed shape to an intensity volume.
    Volume(volume::VolumeArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion)
                || matches!(
                    e.kind(),
                    ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
                )
            {
                let _ = e.print();
                return if e.use_stderr() {
                    ExitCode::from(2)
                } else {
                    ExitCode::SUCCESS
                };
            }
            // One line: clap's message up to its usage hint, without "error: ".
            let text = e.to_string();
            let message = text
                .lines()
                .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .collect::<Vec<_>>()
                .join(" ");
            let message = message.strip_prefix("error: ").unwrap_or(&message);
            eprintln!("data-gen: {message} (see --help)");
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Shape(args) => shape_cmd::run(args),
        Command::Scan(args) => scan::run(args),
        Command::Demo(args) => demo::run(args),
        Command::Volume(args) => volume::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The chain of causes, skipping a cause its parent already quoted
            // (subdyn's `Io` error prints its source).
            let mut message = String::new();
            for cause in e.chain().map(|c| c.to_string()) {
                if !message.ends_with(&cause) {
                    if !message.is_empty() {
                        message.push_str(": ");
                    }
                    message.push_str(&cause);
                }
            }
            let message = message.replace('\n', " ");
            eprintln!("data-gen: error: {message}");
            ExitCode::FAILURE
        }
    }
}
