//! `subdyn finetune …`: fine tuning by scaling derivatives (curves; surfaces
//! are added beside `Curve`).

use clap::Subcommand;

use super::finetune_curve;

/// The kinds of fine tuning.
#[derive(Debug, Subcommand)]
pub enum FinetuneCommand {
    /// Fine-tune a quadratic or cubic B-spline subdivision curve: Q'(t) = α(t) P'(t), closed curves re-closed by a spring energy.
    Curve(super::finetune_curve::CurveArgs),
}

/// Runs `subdyn finetune <kind>`.
pub fn run(cmd: &FinetuneCommand) -> anyhow::Result<()> {
    match cmd {
        FinetuneCommand::Curve(args) => finetune_curve::run(args),
    }
}
