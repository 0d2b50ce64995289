//! Force–displacement plots as SVG (`crate::plot`).
//!
//! Axes: platen approach x in mm, mean platen force F in mN.

use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenSample;

use crate::plot::{Mark, Series, xy_svg};

/// One curve: a legend label and its samples.
#[derive(Clone, Copy, Debug)]
pub struct Curve<'a> {
    /// Legend text.
    pub label: &'a str,
    /// Samples in time order.
    pub samples: &'a [PlatenSample],
}

/// A fitted straight line F = slope·x + intercept drawn between two
/// approaches (the σ_est fit).
#[derive(Clone, Debug)]
pub struct FitLine {
    /// dF/dx, N/m.
    pub slope_n_per_m: Real,
    /// F at x = 0, N.
    pub intercept_n: Real,
    /// Approach range drawn, m.
    pub x_range_m: [Real; 2],
    /// Legend text.
    pub label: String,
}

/// The SVG text of `curves` (one colour each, with a legend) and an
/// optional dashed fit line, under `title`: approach x in mm, mean platen
/// force F in mN, both axes from zero.
pub fn force_displacement_svg(
    title: &str,
    curves: &[Curve<'_>],
    fit: Option<&FitLine>,
) -> anyhow::Result<String> {
    let mut series: Vec<Series> = curves
        .iter()
        .map(|c| {
            let points = c
                .samples
                .iter()
                .map(|s| (s.approach_m * 1.0e3, s.mean_force() * 1.0e3));
            Series::new(c.label, Mark::Line, points)
        })
        .collect();
    if let Some(fit) = fit {
        let line = fit
            .x_range_m
            .map(|x| (x * 1.0e3, (fit.slope_n_per_m * x + fit.intercept_n) * 1.0e3));
        series.push(Series::new(
            fit.label.as_str(),
            Mark::Dashed,
            line.into_iter(),
        ));
    }
    xy_svg(
        title,
        "platen approach x, mm",
        "platen force F, mN",
        &series,
        true,
    )
}
