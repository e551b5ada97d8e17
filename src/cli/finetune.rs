//! `subdyn finetune …`: fine tuning of subdivision curves and surfaces by
//! scaling derivatives.

use clap::Subcommand;

/// The kinds of fine tuning.
#[derive(Debug, Subcommand)]
pub enum FinetuneCommand {
    /// Fine-tune a quadratic or cubic B-spline subdivision curve: Q'(t) = α(t) P'(t), closed curves re-closed by a spring energy.
    Curve(super::finetune_curve::CurveArgs),
    /// Fine-tune a Doo-Sabin (or Catmull-Clark) surface: control values on edges, spring energy (14).
    Surface(super::finetune_surface::SurfaceArgs),
}

/// Runs `subdyn finetune <kind>`.
pub fn run(cmd: &FinetuneCommand) -> anyhow::Result<()> {
    match cmd {
        FinetuneCommand::Curve(args) => super::finetune_curve::run(args),
        FinetuneCommand::Surface(args) => super::finetune_surface::run(args),
    }
}
