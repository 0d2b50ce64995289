//! Progress display on the process's standard error (indicatif), shared by
//! the commands: hidden with `--quiet` or when stderr is not a terminal,
//! and never touching the results.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Bar positions per unit strain (a strain bar moves in steps of 1e-4).
const TICKS_PER_STRAIN: f64 = 1.0e4;

/// Where bars are drawn: stderr, or nowhere when `quiet` (indicatif also
/// hides them when stderr is not a terminal).
pub fn draw_target(quiet: bool) -> ProgressDrawTarget {
    if quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    }
}

/// Steps per second of wall time (0 before any time has passed).
pub fn steps_per_second(steps: u64, elapsed_s: f64) -> f64 {
    if elapsed_s > 0.0 {
        steps as f64 / elapsed_s
    } else {
        0.0
    }
}

/// A bar whose position is the strain of a run to `final_strain`.
pub struct StrainBar {
    bar: ProgressBar,
}

impl StrainBar {
    /// Styles `bar` with the indicatif `template` (falling back to the
    /// default bar) and the prefix `label`, its length `final_strain`.
    pub fn new(bar: ProgressBar, template: &str, label: &str, final_strain: f64) -> Self {
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        bar.set_length((final_strain * TICKS_PER_STRAIN).round() as u64);
        bar.set_style(style);
        bar.set_prefix(label.to_owned());
        Self { bar }
    }

    /// Moves the bar to `strain` (clamped to its end) with `message`.
    pub fn show(&self, strain: f64, message: String) {
        let len = self.bar.length().unwrap_or(0);
        self.bar
            .set_position(((strain * TICKS_PER_STRAIN).round() as u64).min(len));
        self.bar.set_message(message);
    }

    /// Removes the bar (the run's summary line replaces it).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
