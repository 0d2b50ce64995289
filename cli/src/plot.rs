//! Line and scatter plots as SVG text (plotters' SVG backend, no system
//! fonts: text is written as SVG `<text>` and laid out by the viewer),
//! shared by the granule, bed and study plots.

use core::ops::Range;

use plotters::prelude::*;

/// Plot size, pixels.
const SIZE: (u32, u32) = (900, 600);

/// Curve colours: matplotlib's `tab10` (distinct on white, no pale
/// yellow), enough for the nine types of a `--types all` comparison;
/// reused cyclically.
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

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// A solid line.
    Line,
    /// Filled circles.
    Dots,
    /// Open circles.
    Rings,
    /// A dashed black line (a fit).
    Dashed,
    /// A dashed line in the series' colour: a second curve that may lie
    /// on the first (the lower punch's pressure on the upper's), both
    /// visible where they coincide.
    DashedLine,
}

/// One series of a plot.
pub struct Series {
    label: String,
    points: Vec<(f64, f64)>,
    mark: Mark,
}

impl Series {
    /// A series named `label` drawn as `mark`; non-finite points are left
    /// out.
    pub fn new(
        label: impl Into<String>,
        mark: Mark,
        points: impl Iterator<Item = (f64, f64)>,
    ) -> Self {
        Self {
            label: label.into(),
            // Non-finite values (a degenerate granule, an empty window)
            // are left out rather than breaking the axes.
            points: points
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect(),
            mark,
        }
    }

    /// The finite points, in order.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }
}

/// A padded axis range over `values`, 0 included when `from_zero`; a
/// degenerate range still gets a unit-width axis.
fn range(values: impl Iterator<Item = f64>, from_zero: bool) -> core::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
    let (lo, hi) = if from_zero {
        (lo.min(0.0), hi.max(0.0))
    } else {
        (lo, hi)
    };
    let span = hi - lo;
    if span > 0.0 {
        (lo - 0.03 * span)..(hi + 0.05 * span)
    } else {
        let pad = if lo.abs() > 0.0 { 0.05 * lo.abs() } else { 1.0 };
        (lo - pad)..(hi + pad)
    }
}

/// The tick labels of an axis over `r`: `None` (plain decimals,
/// [`plain_labels`]) when its largest magnitude lies in [0.01, 10⁵); otherwise
/// numbers with an exponent (`2.5e-5`, `1.8e7`), where plain decimals
/// would be rows of zeros or eight digits wide, with the significant
/// digits the span needs (trailing zeros dropped). Round-off beside zero
/// (below 10⁻⁹ of the span) prints as `0`.
fn exponent_labels(r: &Range<f64>) -> Option<impl Fn(&f64) -> String + use<>> {
    let largest = r.start.abs().max(r.end.abs());
    if (1.0e-2..1.0e5).contains(&largest) || largest == 0.0 || !largest.is_finite() {
        return None;
    }
    let span = (r.end - r.start).abs();
    let zero = 1.0e-9 * span;
    // One digit more than ticks a tenth of the span apart need to differ
    // (ticks at 2.5 steps included), more on an axis narrow for its
    // magnitude (100000 to 100010).
    let digits = if span > 0.0 {
        ((10.0 * largest / span).log10().ceil() as usize + 2).clamp(2, 15)
    } else {
        4
    };
    let precision = digits - 1;
    Some(move |v: &f64| {
        if v.abs() <= zero {
            return "0".to_owned();
        }
        let text = format!("{v:.precision$e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) if mantissa.contains('.') => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exponent}")
            }
            _ => text,
        }
    })
}

/// Tick labels a plot draws on an axis (plotters' default count).
const AXIS_TICKS: usize = 11;

/// The tick labels of an axis over `r` with plain decimals, all with the
/// same number of decimals — as many as the finest tick needs (`0.800`,
/// `0.805`, `0.810`, not `0.8`, `0.805`, `0.81`; `0`, `2`, `4`, not
/// `0.0`, `2.0`) — for the axes [`exponent_labels`] leaves plain. The
/// ticks are plotters' own for the axis ([`AXIS_TICKS`] of them at most).
fn plain_labels(r: &Range<f64>) -> impl Fn(&f64) -> String + use<> {
    use plotters::coord::ranged1d::{BoldPoints, Ranged};
    use plotters::coord::types::RangedCoordf64;
    let span = (r.end - r.start).abs();
    let close = 1.0e-9 * span.max(f64::MIN_POSITIVE);
    let needs = |v: f64| {
        (0..=12)
            .find(|&d| {
                let scale = 10f64.powi(d);
                ((v * scale).round() / scale - v).abs() <= close
            })
            .unwrap_or(12)
    };
    let ticks = RangedCoordf64::from(r.clone()).key_points(BoldPoints(AXIS_TICKS));
    let decimals = ticks.iter().map(|&v| needs(v)).max().unwrap_or(0) as usize;
    move |v: &f64| {
        // Round-off beside zero prints as 0, not -0.000.
        let v = if v.abs() <= close { 0.0 } else { *v };
        format!("{v:.decimals$}")
    }
}

/// The corner of the plot for the legend: the one whose region (a third
/// of the width, up to 40 % of the height for `entries` lines) holds the
/// fewest points of `series` over the axes `x` and `y`; the upper left on
/// a tie.
fn legend_corner(
    series: &[Series],
    x: &Range<f64>,
    y: &Range<f64>,
    entries: usize,
) -> SeriesLabelPosition {
    let height = (0.08 * entries as f64 + 0.06).min(0.4);
    let (w, h) = (x.end - x.start, y.end - y.start);
    let inside = |(px, py): (f64, f64), left: bool, upper: bool| {
        let fx = (px - x.start) / w;
        let fy = (py - y.start) / h;
        (if left { fx <= 0.34 } else { fx >= 0.66 })
            && (if upper {
                fy >= 1.0 - height
            } else {
                fy <= height
            })
    };
    [
        (SeriesLabelPosition::UpperLeft, true, true),
        (SeriesLabelPosition::UpperRight, false, true),
        (SeriesLabelPosition::LowerRight, false, false),
        (SeriesLabelPosition::LowerLeft, true, false),
    ]
    .into_iter()
    .map(|(corner, left, upper)| {
        let count = series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|&&p| inside(p, left, upper))
            .count();
        (count, corner)
    })
    .min_by_key(|(count, _)| *count)
    .map_or(SeriesLabelPosition::UpperLeft, |(_, corner)| corner)
}

/// The unit of energies up to `largest` J: (name, J per unit), the
/// largest of J, mJ and µJ in which `largest` is at least 1 (µJ below).
pub fn energy_unit(largest: f64) -> (&'static str, f64) {
    [("J", 1.0), ("mJ", 1e-3)]
        .into_iter()
        .find(|&(_, unit)| largest.abs() >= unit)
        .unwrap_or(("µJ", 1e-6))
}

/// An energy ledger under `title`: each term (legend, its (x, energy in
/// J) points) against x (`x_desc`), all in the [`energy_unit`] of the
/// largest finite value, the energy axis from zero.
pub fn energy_svg(
    title: &str,
    x_desc: &str,
    terms: &[(&str, Vec<(f64, f64)>)],
) -> anyhow::Result<String> {
    let largest = terms
        .iter()
        .flat_map(|(_, points)| points.iter().map(|p| p.1.abs()))
        .filter(|e| e.is_finite())
        .fold(0.0, f64::max);
    let (unit, scale) = energy_unit(largest);
    let series: Vec<Series> = terms
        .iter()
        .map(|(label, points)| {
            Series::new(
                *label,
                Mark::Line,
                points.iter().map(|&(x, e)| (x, e / scale)),
            )
        })
        .collect();
    xy_svg(title, x_desc, &format!("energy, {unit}"), &series, true)
}

/// The SVG text of `series` under `title`, with axis labels; the x axis
/// from zero, the y axis from zero if `y_from_zero`.
pub fn xy_svg(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[Series],
    y_from_zero: bool,
) -> anyhow::Result<String> {
    xy_svg_from(title, (x_desc, y_desc), series, (true, y_from_zero))
}

/// [`xy_svg`] with the x axis too from zero only if `x_from_zero` (as
/// `from_zero` = (x, y)): an axis not from zero spans the data.
pub fn xy_svg_from(
    title: &str,
    (x_desc, y_desc): (&str, &str),
    series: &[Series],
    (x_from_zero, y_from_zero): (bool, bool),
) -> anyhow::Result<String> {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let x_range = range(all().map(|p| p.0), x_from_zero);
    let y_range = range(all().map(|p| p.1), y_from_zero);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 24))
            .margin(20)
            .x_label_area_size(58)
            .y_label_area_size(92)
            .build_cartesian_2d(x_range.clone(), y_range.clone())?;
        let x_labels = exponent_labels(&x_range);
        let y_labels = exponent_labels(&y_range);
        let (x_plain, y_plain) = (plain_labels(&x_range), plain_labels(&y_range));
        let mut mesh = chart.configure_mesh();
        // Text larger than plotters' default (about 10 px on the 900 × 600
        // canvas; 13 px, as it was, still read small in a report shown at
        // its width: the powder review of session 56), and the minor grid
        // lighter, for a printed page.
        mesh.x_desc(x_desc)
            .y_desc(y_desc)
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .light_line_style(BLACK.mix(0.05));
        match &x_labels {
            Some(f) => mesh.x_label_formatter(f),
            None => mesh.x_label_formatter(&x_plain),
        };
        match &y_labels {
            Some(f) => mesh.y_label_formatter(f),
            None => mesh.y_label_formatter(&y_plain),
        };
        mesh.draw()?;
        let mut colour = COLOURS.iter().cycle();
        for s in series {
            let pts = s.points.iter().copied();
            let label = s.label.as_str();
            match s.mark {
                Mark::Line => {
                    let style = colour.next().unwrap_or(&BLACK).stroke_width(2);
                    chart
                        .draw_series(LineSeries::new(pts, style))?
                        .label(label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                }
                Mark::Dots | Mark::Rings => {
                    let c = colour.next().unwrap_or(&BLACK);
                    let style = if s.mark == Mark::Dots {
                        c.filled()
                    } else {
                        c.stroke_width(1)
                    };
                    chart
                        .draw_series(pts.map(move |p| Circle::new(p, 3, style)))?
                        .label(label)
                        .legend(move |(x, y)| Circle::new((x + 10, y), 3, style));
                }
                Mark::Dashed | Mark::DashedLine => {
                    let style = if s.mark == Mark::Dashed {
                        BLACK.stroke_width(1)
                    } else {
                        colour.next().unwrap_or(&BLACK).stroke_width(2)
                    };
                    chart
                        .draw_series(DashedLineSeries::new(pts, 6, 4, style))?
                        .label(label)
                        // Dashed in the legend too: two dashes.
                        .legend(move |(x, y)| {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (6, 0)], style)
                                + PathElement::new(vec![(10, 0), (16, 0)], style)
                        });
                }
            }
        }
        // The legend, unless its only entry would be an empty label (a
        // single curve that the title and axes name). A single labelled
        // curve keeps it: a one-member series' "(failed)" is said there.
        if series.len() > 1 || series.iter().any(|s| !s.label.is_empty()) {
            let corner = legend_corner(series, &x_range, &y_range, series.len());
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 15))
                .position(corner)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()?;
        }
        root.present()?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legend goes to the emptiest corner: the upper left for a
    /// rising curve, elsewhere when the points crowd it.
    #[test]
    fn the_legend_avoids_the_points() {
        let (x, y) = (0.0..10.0, 0.0..10.0);
        let corner = |points: Vec<(f64, f64)>| {
            legend_corner(
                &[Series::new("s", Mark::Dots, points.into_iter())],
                &x,
                &y,
                3,
            )
        };
        let rising: Vec<(f64, f64)> = (0..=10).map(|i| (f64::from(i), f64::from(i))).collect();
        assert!(matches!(corner(rising), SeriesLabelPosition::UpperLeft));
        // Falling from the upper left, with a cluster in the upper right
        // (a Kawakita plot's early rows, say): the lower left is free.
        let mut crowded: Vec<(f64, f64)> = (0..=10)
            .map(|i| (f64::from(i), 10.0 - f64::from(i)))
            .collect();
        crowded.extend((0..5).map(|i| (9.0 + 0.1 * f64::from(i), 9.5)));
        crowded.extend((0..5).map(|i| (8.0 + 0.1 * f64::from(i), 0.5)));
        assert!(matches!(corner(crowded), SeriesLabelPosition::LowerLeft));
    }

    /// A single curve has a legend only if it is labelled: a one-member
    /// series' "(failed)" is said there.
    #[test]
    fn a_single_curve_has_a_legend_only_if_labelled() {
        let curve = |label: &str| {
            let points = (0..=4).map(|i| (f64::from(i), f64::from(i * i)));
            xy_svg(
                "t",
                "x",
                "y",
                &[Series::new(label, Mark::Line, points)],
                true,
            )
            .unwrap()
        };
        let (named, bare) = (curve("B2 (failed)"), curve(""));
        assert!(named.contains("B2 (failed)"));
        assert!(named.matches("<rect").count() > bare.matches("<rect").count());
    }

    /// Energies are drawn in the largest of J, mJ and µJ that the largest
    /// value fills.
    #[test]
    fn energies_take_the_unit_of_the_largest() {
        assert_eq!(energy_unit(2.5), ("J", 1.0));
        assert_eq!(energy_unit(9.7e-3), ("mJ", 1e-3));
        assert_eq!(energy_unit(9.7e-6), ("µJ", 1e-6));
        assert_eq!(energy_unit(0.0), ("µJ", 1e-6));
        assert_eq!(energy_unit(-2e-3), ("mJ", 1e-3));
    }

    /// An x axis not from zero spans the data; [`xy_svg`]'s starts at 0.
    #[test]
    fn an_x_axis_from_zero_or_over_the_data() {
        let points = || (0..=10).map(|i| (0.30 + 0.01 * f64::from(i), f64::from(i)));
        let svg = |from_zero| {
            xy_svg_from(
                "t",
                ("x", "y"),
                &[Series::new("", Mark::Line, points())],
                (from_zero, true),
            )
            .unwrap()
        };
        let tick = |svg: &str, label: &str| svg.contains(&format!("\n{label}\n</text>"));
        let (zero, data) = (svg(true), svg(false));
        assert!(tick(&zero, "0.00") && !tick(&zero, "0.31"), "{zero}");
        assert!(!tick(&data, "0.00") && tick(&data, "0.31"), "{data}");
    }

    /// Every tick of a plain axis has the decimals of the finest one.
    #[test]
    fn plain_ticks_share_their_decimals() {
        let density = plain_labels(&(0.799..0.826));
        assert_eq!(
            [density(&0.8), density(&0.805), density(&0.81)],
            ["0.800", "0.805", "0.810"]
        );
        let pressure = plain_labels(&(-0.5..18.9));
        assert_eq!([pressure(&0.0), pressure(&2.0)], ["0", "2"]);
        let strain = plain_labels(&(-0.01..0.315));
        assert_eq!(
            [strain(&0.0), strain(&0.05), strain(&0.1)],
            ["0.00", "0.05", "0.10"]
        );
        assert_eq!(strain(&-1e-17), "0.00");
        // In a plot: the labels of one axis all alike.
        let svg = xy_svg(
            "t",
            "x",
            "y",
            &[Series::new(
                "s",
                Mark::Line,
                (0..=10).map(|i| (0.03 * f64::from(i), 0.8 + 0.0025 * f64::from(i))),
            )],
            false,
        )
        .unwrap();
        let label = |text: &str| svg.lines().any(|l| l.trim() == text);
        assert!(label("0.810") && label("0.800") && !label("0.81"), "{svg}");
    }

    #[test]
    fn tiny_and_huge_axes_get_exponents() {
        assert!(exponent_labels(&(0.0..0.4)).is_none());
        assert!(exponent_labels(&(-0.03..18.0)).is_none());
        let tiny = exponent_labels(&(-3.0e-7..1.05e-5)).unwrap();
        assert_eq!(tiny(&2.5e-6), "2.5e-6");
        assert_eq!(tiny(&1.0e-5), "1e-5");
        assert_eq!(tiny(&-1.0e-22), "0");
        let huge = exponent_labels(&(0.0..1.8e7)).unwrap();
        assert_eq!(huge(&1.8e7), "1.8e7");
        assert_eq!(huge(&12_345_678.0), "1.23e7");
        // A narrow axis at a large magnitude keeps its ticks apart.
        let narrow = exponent_labels(&(100_000.0..100_010.0)).unwrap();
        assert_eq!(narrow(&100_001.0), "1.00001e5");
        assert_ne!(narrow(&100_002.0), narrow(&100_003.0));
        // In a plot: no row of zeros, no eight-digit labels.
        let points = |k: f64| (0..=10).map(move |i| (0.04 * f64::from(i), k * f64::from(i)));
        let small = xy_svg(
            "t",
            "x",
            "y",
            &[Series::new("s", Mark::Line, points(1e-6))],
            true,
        )
        .unwrap();
        let label = |svg: &str, text: &str| svg.lines().any(|l| l.trim() == text);
        assert!(
            label(&small, "1e-5") && !small.contains("0.00001"),
            "{small}"
        );
        let large = xy_svg(
            "t",
            "x",
            "y",
            &[Series::new("s", Mark::Line, points(2e6))],
            true,
        )
        .unwrap();
        assert!(
            label(&large, "2e7") && !large.contains("20000000"),
            "{large}"
        );
    }

    #[test]
    fn ranges_pad_and_survive_degenerate_data() {
        assert_eq!(range([].into_iter(), false), -0.03..1.05);
        let r = range([2.0, 2.0].into_iter(), false);
        assert!(r.start < 2.0 && r.end > 2.0);
        let r = range([1.0, 3.0].into_iter(), true);
        assert!(r.start < 0.0 && r.end > 3.0);
    }
}
