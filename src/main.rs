//! The `subdyn` command-line tool: `subdyn <verb> INPUT [options] -o OUTPUT`.
//!
//! Run `subdyn --help` for the verbs; every verb is one file under `src/cli/`.

#![warn(missing_docs)]

mod cli;

/// An allocation the system refuses ends the run with one line (exit 1).
#[global_allocator]
static ALLOCATOR: subdyn::allocator::OneLineOutOfMemory = subdyn::allocator::OneLineOutOfMemory;

fn main() -> std::process::ExitCode {
    cli::run()
}
