//! `subdyn finetune …`: fine tuning of subdivision surfaces (and curves, in
//! the curve half) by scaling derivatives.

/// The fine-tuning verbs.
#[derive(Debug, clap::Subcommand)]
pub enum FinetuneCommand {
    /// Fine-tune a Doo-Sabin (or Catmull-Clark) surface: control values on edges, spring energy (14).
    Surface(super::finetune_surface::SurfaceArgs),
}

/// Runs a fine-tuning verb.
pub fn run(cmd: &FinetuneCommand) -> anyhow::Result<()> {
    match cmd {
        FinetuneCommand::Surface(args) => super::finetune_surface::run(args),
    }
}
