//! Progress on stderr: an indicatif spinner naming the current stage, or a
//! bar with the total and an ETA where the total is known; shown only when
//! stderr is a terminal and `--quiet` is not given.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// A spinner for a sequence of named stages (hidden when not wanted).
pub struct Progress {
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A spinner on stderr, or nothing when `quiet` or stderr is not a terminal.
    pub fn new(quiet: bool) -> Progress {
        if quiet || !std::io::stderr().is_terminal() {
            return Progress { bar: None };
        }
        let bar = ProgressBar::new_spinner();
        bar.set_style(spinner_style());
        bar.enable_steady_tick(Duration::from_millis(100));
        Progress { bar: Some(bar) }
    }

    /// Shows `message` as the current stage (a bar from [`Progress::counted`]
    /// becomes the spinner again).
    pub fn stage(&self, message: impl Into<String>) {
        if let Some(bar) = &self.bar {
            if bar.length().is_some() {
                bar.set_style(spinner_style());
                bar.unset_length();
            }
            bar.set_message(message.into());
        }
    }

    /// Shows `done` of `total` units as a bar with the count, an ETA from
    /// the rate so far and `message` (the spinner becomes a bar at the
    /// first call, or when the total changes).
    pub fn counted(&self, done: u64, total: u64, message: impl Into<String>) {
        let Some(bar) = &self.bar else { return };
        if bar.length() != Some(total) {
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed}] {bar:20} {pos}/{len} {msg} (ETA {eta})",
            ) {
                bar.set_style(style);
            }
            bar.set_length(total);
            bar.reset_eta();
        }
        bar.set_position(done.min(total));
        bar.set_message(message.into());
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// The spinner: elapsed time and the stage's name.
fn spinner_style() -> ProgressStyle {
    ProgressStyle::with_template("{spinner} [{elapsed}] {msg}")
        .unwrap_or_else(|_| ProgressStyle::default_spinner())
}
