//! `subdyn render` (being written).

use clap::Args;

/// Arguments of `subdyn render`.
#[derive(Debug, Args)]
pub struct RenderArgs {}

/// Runs `subdyn render`.
pub fn run(_args: &RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("subdyn render is not implemented yet")
}
