//! The `subdyn` command-line tool: `subdyn <verb> INPUT [options] -o OUTPUT`.
//!
//! Run `subdyn --help` for the verbs; every verb is one file under `src/cli/`.

#![warn(missing_docs)]

mod cli;

fn main() -> std::process::ExitCode {
    cli::run()
}
