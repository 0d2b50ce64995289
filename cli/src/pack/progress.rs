//! The progress line of a pour on the process's standard error (indicatif):
//! simulated time, kinetic energy, largest speed, bed height and steps per
//! second, updated at every rest check. The pour's length is not known in
//! advance (it ends when the spheres are at rest), so this is a spinner,
//! not a bar with an ETA. Hidden when stderr is not a terminal or with
//! `--quiet`; it never touches the results.

use granbed_kernel::dem::pour::PourStatus;
use indicatif::{ProgressBar, ProgressStyle};

use crate::progress::{draw_target, steps_per_second};

/// The progress line of one pour.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A spinner for a pour of `granules` with time limit `max_time_s`,
    /// drawn on stderr when it is a terminal (never when `quiet`).
    pub fn new(quiet: bool, granules: usize, max_time_s: f64) -> Self {
        let target = draw_target(quiet);
        let style =
            ProgressStyle::with_template("{spinner} pour {prefix} [{elapsed_precise}] {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner());
        let bar = ProgressBar::with_draw_target(None, target).with_style(style);
        bar.set_prefix(format!("{granules} granules"));
        bar.set_message(format!("starting (gives up at {max_time_s} s simulated)"));
        Self { bar }
    }

    /// Shows state `s`, reached `elapsed_s` seconds into the pour.
    pub fn update(&self, s: &PourStatus, elapsed_s: f64) {
        let rate = steps_per_second(s.steps, elapsed_s);
        self.bar.set_message(format!(
            "t {:.4} s, KE {:.2e} J, v_max {:.2e} m/s, H {:.3} mm, {:.0} steps/s",
            s.time,
            s.kinetic_energy,
            s.max_speed,
            s.height * 1e3,
            rate
        ));
        self.bar.tick();
    }

    /// Removes the line (the summary line replaces it).
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
