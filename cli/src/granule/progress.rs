//! Progress bars on the process's standard error (indicatif): strain, force,
//! steps per second and ETA per running granule. They are hidden when
//! stderr is not a terminal or with `--quiet`, and never touch the results.

use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenSample;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Bar positions per unit strain (the bar counts strain in steps of 1e-4).
const TICKS_PER_STRAIN: f64 = 1.0e4;

/// The bars of one command: drawn on stderr when it is a terminal, hidden
/// otherwise or when `quiet`.
pub fn bars(quiet: bool) -> MultiProgress {
    let target = if quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    };
    MultiProgress::with_draw_target(target)
}

/// The progress bar of one granule run.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar labelled `label` (the granule type) for a run to
    /// `final_strain`, added to `bars`.
    pub fn new(bars: &MultiProgress, label: &str, final_strain: Real) -> Self {
        let len = (final_strain * TICKS_PER_STRAIN).round() as u64;
        let style = ProgressStyle::with_template(
            "{prefix:>3} [{bar:30}] {msg} ({elapsed_precise}, ETA {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        let bar = bars.add(ProgressBar::new(len).with_style(style));
        bar.set_prefix(label.to_owned());
        Self { bar }
    }

    /// Shows sample `s`, taken `elapsed_s` seconds into the run.
    pub fn update(&self, s: &PlatenSample, elapsed_s: f64) {
        let rate = if elapsed_s > 0.0 {
            s.steps as f64 / elapsed_s
        } else {
            0.0
        };
        let len = self.bar.length().unwrap_or(0);
        self.bar
            .set_position(((s.strain * TICKS_PER_STRAIN).round() as u64).min(len));
        self.bar.set_message(format!(
            "strain {:.4}, F {:.3e} N, {:.0} steps/s",
            s.strain,
            s.mean_force(),
            rate
        ));
    }

    /// Removes the bar (the run's summary line replaces it).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
