//! Force–displacement plots as SVG (plotters' SVG backend, no system
//! fonts: text is written as SVG `<text>` and laid out by the viewer).
//!
//! Axes: platen approach x in mm, mean platen force F in mN.

use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenSample;
use plotters::prelude::*;


/// Plot size, pixels.
const SIZE: (u32, u32) = (900, 600);

/// Curve colours (the ten of matplotlib's `tab10`: distinct on white, no
/// pale yellow), reused cyclically.
const COLOURS: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];

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

/// (approach in mm, mean force in mN) of every sample.
fn points(samples: &[PlatenSample]) -> Vec<(f64, f64)> {
    samples
        .iter()
        .map(|s| (s.approach_m * 1.0e3, s.mean_force() * 1.0e3))
        .collect()
}

/// The SVG text of `curves` (one colour each, with a legend) and an
/// optional dashed fit line, under `title`.
pub fn force_displacement_svg(
    title: &str,
    curves: &[Curve<'_>],
    fit: Option<&FitLine>,
) -> anyhow::Result<String> {
    let series: Vec<Vec<(f64, f64)>> = curves.iter().map(|c| points(c.samples)).collect();
    let all = series.iter().flatten();
    let finite = |v: f64| v.is_finite();
    let x_max = all
        .clone()
        .map(|p| p.0)
        .filter(|v| finite(*v))
        .fold(0.0, f64::max);
    let y_max = all
        .clone()
        .map(|p| p.1)
        .filter(|v| finite(*v))
        .fold(0.0, f64::max);
    let y_min = all.map(|p| p.1).filter(|v| finite(*v)).fold(0.0, f64::min);
    // A degenerate range (a run that stopped at once) still gets axes.
    let x_max = if x_max > 0.0 { x_max } else { 1.0e-3 };
    let y_span = if y_max - y_min > 0.0 {
        y_max - y_min
    } else {
        1.0e-3
    };
    let y_range = (y_min - 0.02 * y_span)..(y_max + 0.05 * y_span);

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..x_max, y_range)?;
        chart
            .configure_mesh()
            .x_desc("platen approach x, mm")
            .y_desc("platen force F, mN")
            .draw()?;
        for (i, (curve, pts)) in curves.iter().zip(&series).enumerate() {
            let style = COLOURS[i % COLOURS.len()].stroke_width(2);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), style))?
                .label(curve.label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        if let Some(fit) = fit {
            let line = fit
                .x_range_m
                .map(|x| (x * 1.0e3, (fit.slope_n_per_m * x + fit.intercept_n) * 1.0e3));
            let style = BLACK.stroke_width(1);
            chart
                .draw_series(DashedLineSeries::new(line, 6, 4, style))?
                .label(fit.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}
