//! `subdyn compare` (being written).

use clap::Args;

/// Arguments of `subdyn compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {}

/// Runs `subdyn compare`.
pub fn run(_args: &CompareArgs) -> anyhow::Result<()> {
    anyhow::bail!("subdyn compare is not implemented yet")
}
