//! The `subdyn` command line: verbs, error printing and exit codes.
//!
//! Exit codes: 0 success, 1 bad input or a failed run (one line on stderr,
//! `subdyn: error: …`), 2 bad usage (clap's own message).

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use super::{
    bench, common, compare, ffd, finetune, fit, info, lattice, limit, recover, render, sculpt,
    signals, subdivide, threads,
};

/// subdyn: Catmull-Clark subdivision surfaces — refinement as stencil tables,
/// exact limit evaluation, mesh inspection and benchmarks.
#[derive(Debug, Parser)]
#[command(name = "subdyn", version, propagate_version = true)]
#[command(
    after_help = "Output formats follow the extension: .obj, .ply, .off, .xyz (optionally .gz)."
)]
struct Cli {
    /// Worker threads (default: `RAYON_NUM_THREADS`, else one per core; at
    /// most 4 per core).
    #[arg(long, global = true, value_name = "N")]
    threads: Option<usize>,
    /// Memory budget: a size such as `2G`, `512M` or `1500000000` (bytes).
    /// Readers and verbs refuse, before allocating, anything estimated over
    /// it (default: half of the physical memory, or of `ulimit -v`).
    #[arg(long, global = true, value_name = "SIZE", value_parser = memory_size)]
    max_memory: Option<u64>,
    #[command(subcommand)]
    command: Command,
}

/// The verbs.
#[derive(Debug, Subcommand)]
enum Command {
    /// Fit a dynamic Catmull-Clark surface to a point cloud (the embedded demo scan when no SCAN is given).
    Fit(fit::FitArgs),
    /// Recover a closed shape from a volume (NIfTI, slice stack, TIFF, EXR, raw) with image forces.
    Recover(recover::RecoverArgs),
    /// Refine a mesh uniformly with Catmull-Clark (the embedded cube when no INPUT is given).
    Subdivide(subdivide::SubdivideArgs),
    /// Tessellate the limit surface: every quad face as a K×K grid of exact limit samples.
    Limit(limit::LimitArgs),
    /// Print counts, boundaries, components, genus, valences and the bounding box of a mesh or point file, or the grid, world map and value range of a volume.
    Info(info::InfoArgs),
    /// Distances from A to B (B the reference): mean, RMS, 95th percentile, Hausdorff, Chamfer.
    Compare(compare::CompareArgs),
    /// Draw a mesh and/or point cloud to a PNG (software rasteriser).
    Render(render::RenderArgs),
    /// Fine tuning by scaling derivatives: a new shape whose derivatives are the old ones scaled by α.
    #[command(subcommand)]
    Finetune(finetune::FinetuneCommand),
    /// Build a lattice around a model: bounding box (AABB or PCA-oriented), octree levels, empty cells culled.
    Lattice(lattice::LatticeArgs),
    /// Free-form deformation of a mesh with a Catmull-Clark volume lattice of any topology.
    Ffd(ffd::FfdArgs),
    /// Sculpt a dynamic subdivision solid with a scripted session (ropes, extrude, trim, fix, plastic), or the built-in --demo.
    Sculpt(sculpt::SculptArgs),
    /// Benchmarks (timings as a table, then one JSON line).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

/// `--max-memory`'s value in bytes.
fn memory_size(text: &str) -> Result<u64, String> {
    subdyn::memory::parse_memory_size(text).map_err(|e| e.to_string())
}

/// The command line, with negative numbers accepted as the values of every
/// option (`--tol -1` reaches the verb's own range check).
fn command() -> clap::Command {
    fn allow_negative(cmd: clap::Command) -> clap::Command {
        cmd.mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(allow_negative)
    }
    allow_negative(Cli::command())
}

/// Parses the command line, runs the verb and turns any error into one line
/// on stderr and exit code 1.
pub fn run() -> ExitCode {
    common::install_panic_hook();
    let cli = match Cli::from_arg_matches_mut(&mut command().get_matches()) {
        Ok(cli) => cli,
        Err(err) => err.exit(),
    };
    if let Some(bytes) = cli.max_memory {
        subdyn::memory::set_memory_budget(bytes);
    }
    if let Err(err) = threads::start_pool(cli.threads) {
        common::print_error(&err);
        return ExitCode::from(1);
    }
    signals::install();
    // Every file of the run is staged and renamed at the end, all or none.
    let batch = match subdyn::io::OutputBatch::begin() {
        Ok(batch) => batch,
        Err(err) => {
            common::print_error(&err.into());
            return ExitCode::from(1);
        }
    };
    let result = match cli.command {
        Command::Fit(args) => fit::run(&args),
        Command::Recover(args) => recover::run(&args),
        Command::Subdivide(args) => subdivide::run(&args),
        Command::Limit(args) => limit::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Finetune(cmd) => finetune::run(&cmd),
        Command::Ffd(args) => ffd::run(&args),
        Command::Lattice(args) => lattice::run(&args),
        Command::Sculpt(args) => sculpt::run(&args),
        Command::Bench(cmd) => bench::run(&cmd),
    };
    // The summaries and `wrote` lines are printed once the files are in place.
    let result = result
        .and_then(|()| Ok(batch.commit()?))
        .and_then(|()| common::print_pending());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            common::print_error(&err);
            ExitCode::from(1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_line_definition_is_consistent() {
        command().debug_assert();
    }
}
