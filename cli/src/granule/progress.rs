//! Progress bars on the process's standard error (indicatif): strain, force,
//! steps per second and ETA per running granule. They are hidden when
//! stderr is not a terminal or with `--quiet`, and never touch the results.

use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenSample;
use indicatif::{MultiProgress, ProgressBar};

use crate::progress::{StrainBar, draw_target, steps_per_second};

/// The bars of one command: drawn on stderr when it is a terminal, hidden
/// otherwise or when `quiet`.
pub fn bars(quiet: bool) -> MultiProgress {
    MultiProgress::with_draw_target(draw_target(quiet))
}

/// The progress bar of one granule run.
pub struct Progress {
    bar: StrainBar,
}

impl Progress {
    /// A bar labelled `label` (the granule type) for a run to
    /// `final_strain`, added to `bars`.
    pub fn new(bars: &MultiProgress, label: &str, final_strain: Real) -> Self {
        let bar = bars.add(ProgressBar::new(0));
        let template = "{prefix:>3} [{bar:30}] {msg} ({elapsed_precise}, ETA {eta})";
        Self {
            bar: StrainBar::new(bar, template, label, final_strain),
        }
    }

    /// Shows sample `s`, taken `elapsed_s` seconds into the run.
    pub fn update(&self, s: &PlatenSample, elapsed_s: f64) {
        self.bar.show(
            s.strain,
            format!(
                "strain {:.4}, F {:.3e} N, {:.0} steps/s",
                s.strain,
                s.mean_force(),
                steps_per_second(s.steps, elapsed_s)
            ),
        );
    }

    /// Removes the bar (the run's summary line replaces it).
    pub fn finish(&self) {
        self.bar.finish();
    }
}
