//! The plots of a bed run as SVG (`plots/` in the output), drawn with
//! plotters' SVG backend like `granule`'s plots: no system fonts, text is
//! written as SVG `<text>` and laid out by the viewer.
//!
//! * `pressure_strain.svg`: upper- and lower-punch pressure against the
//!   axial strain C;
//! * `kawakita.svg`: P/C against P with the Kawakita fit line (points with
//!   C ≥ 0.25 are the fitted ones);
//! * `coordination_strain.svg`: coordination number Z, without and with
//!   the walls;
//! * `relative_density_strain.svg`: mean granule relative density and
//!   Σsolid/ΣV;
//! * `heywood_strain.svg`: mean Heywood coefficient α_SV with d_V and with
//!   the nominal diameter.

use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::analysis::bed::KAWAKITA_MIN_STRAIN;

use super::outputs::KawakitaSummary;
use super::run::BedSample;
use crate::output::write_text;
use crate::plot::{Mark, Series, xy_svg};

/// Sub-directory of the output directory holding the plots.
pub const PLOTS_DIR: &str = "plots";

/// The plot files, in the order [`write_plots`] writes them.
pub const PLOT_FILES: [&str; 5] = [
    "pressure_strain.svg",
    "kawakita.svg",
    "coordination_strain.svg",
    "relative_density_strain.svg",
    "heywood_strain.svg",
];

/// The value of a sample a curve shows.
pub type Quantity = fn(&BedSample) -> Real;

/// One line per (label, samples) of `y` against the strain, overlaid with
/// a legend (the `--types` comparison plots).
pub fn overlay_svg(
    title: &str,
    y_desc: &str,
    curves: &[(&str, &[BedSample])],
    y: Quantity,
    y_from_zero: bool,
) -> anyhow::Result<String> {
    let series: Vec<Series> = curves
        .iter()
        .map(|(label, samples)| {
            Series::new(*label, Mark::Line, samples.iter().map(|s| (s.strain, y(s))))
        })
        .collect();
    xy_svg(
        title,
        "axial strain C = (H0 - H)/H0",
        y_desc,
        &series,
        y_from_zero,
    )
}

/// Two curves (label, value) of the samples against the strain.
fn against_strain(samples: &[BedSample], curves: [(&str, Quantity); 2]) -> [Series; 2] {
    curves
        .map(|(label, y)| Series::new(label, Mark::Line, samples.iter().map(|s| (s.strain, y(s)))))
}

/// The Kawakita plot: P/C against P (kPa) of the samples with C > 0, the
/// fitted ones (C ≥ 0.25) filled, and the line P/C = P/a + (1/b)/a over the
/// fitted pressures.
pub fn kawakita_svg(samples: &[BedSample], fit: &KawakitaSummary) -> anyhow::Result<String> {
    let point = |s: &BedSample| {
        (
            s.upper_pressure_pa * 1e-3,
            s.upper_pressure_pa / s.strain * 1e-3,
        )
    };
    let used = |s: &&BedSample| s.strain >= KAWAKITA_MIN_STRAIN;
    let early = |s: &&BedSample| s.strain > 0.0 && s.strain < KAWAKITA_MIN_STRAIN;
    let mut series = vec![
        Series::new(
            format!("C < {KAWAKITA_MIN_STRAIN}"),
            Mark::Rings,
            samples.iter().filter(early).map(point),
        ),
        Series::new(
            format!("C ≥ {KAWAKITA_MIN_STRAIN} (fitted)"),
            Mark::Dots,
            samples.iter().filter(used).map(point),
        ),
    ];
    if let (Some(a), Some(inv_b)) = (fit.a, fit.inv_b_pa) {
        let (lo, hi) = series[1]
            .points()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.0), hi.max(p.0))
            });
        if lo <= hi {
            // In kPa: P/C = P/a + (1/b)/a.
            let line = |p: f64| (p, p / a + inv_b * 1e-3 / a);
            let r2 = fit.r_squared.map_or("n/a".into(), |r| format!("{r:.4}"));
            series.push(Series::new(
                format!("fit: a = {a:.4}, 1/b = {:.4} kPa, R² = {r2}", inv_b * 1e-3),
                Mark::Dashed,
                [line(lo), line(hi)].into_iter(),
            ));
        }
    }
    xy_svg(
        "Kawakita plot",
        "upper-punch pressure P, kPa",
        "P/C, kPa",
        &series,
        true,
    )
}

/// The SVG text of every plot, named as in [`PLOT_FILES`].
pub fn plots(
    samples: &[BedSample],
    fit: &KawakitaSummary,
) -> anyhow::Result<[(&'static str, String); 5]> {
    const C: &str = "axial strain C = (H0 - H)/H0";
    let pressure = against_strain(
        samples,
        [
            ("upper punch", |s| s.upper_pressure_pa * 1e-3),
            ("lower punch", |s| s.lower_pressure_pa * 1e-3),
        ],
    );
    let coordination = against_strain(
        samples,
        [
            ("granule pairs", |s| s.coordination),
            ("with walls", |s| s.coordination_with_walls),
        ],
    );
    let density = against_strain(
        samples,
        [
            ("mean of η0 V0/V", |s| s.relative_density_mean),
            ("Σ solid / Σ V", |s| s.relative_density_solid),
        ],
    );
    let heywood = against_strain(
        samples,
        [
            ("d_V S/V", |s| s.heywood_dv),
            ("d S/V (nominal d)", |s| s.heywood_d),
        ],
    );
    let [f0, f1, f2, f3, f4] = PLOT_FILES;
    Ok([
        (
            f0,
            xy_svg("Punch pressure", C, "pressure P, kPa", &pressure, true)?,
        ),
        (f1, kawakita_svg(samples, fit)?),
        (
            f2,
            xy_svg("Coordination number", C, "Z", &coordination, true)?,
        ),
        (
            f3,
            xy_svg(
                "Granule relative density",
                C,
                "relative density η",
                &density,
                false,
            )?,
        ),
        (
            f4,
            xy_svg(
                "Heywood coefficient (mean over granules)",
                C,
                "α_SV",
                &heywood,
                false,
            )?,
        ),
    ])
}

/// Writes the plots of `samples` into `dir`/[`PLOTS_DIR`] (created) and
/// returns them (file name, SVG text) for the report.
pub fn write_plots(
    dir: &Path,
    samples: &[BedSample],
    fit: &KawakitaSummary,
) -> anyhow::Result<[(&'static str, String); 5]> {
    let dir = dir.join(PLOTS_DIR);
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create directory `{}`", dir.display()))?;
    let svgs = plots(samples, fit)?;
    for (name, svg) in &svgs {
        write_text(&dir.join(name), svg)?;
    }
    Ok(svgs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kawakita_plot_has_the_fit_line() {
        // C = abP/(1 + bP) with a = 0.5, 1/b = 100 kPa.
        let samples: Vec<BedSample> = (0..40)
            .map(|i| {
                let p = 5e3 * f64::from(i);
                BedSample {
                    strain: 0.5 * p / (1e5 + p),
                    upper_pressure_pa: p,
                    ..BedSample::default()
                }
            })
            .collect();
        let points = samples.iter().map(|s| (s.upper_pressure_pa, s.strain));
        let fit = granbed_kernel::analysis::bed::kawakita_fit(points, 0.25).unwrap();
        let summary = KawakitaSummary {
            a: Some(fit.a),
            inv_b_pa: Some(fit.inv_b_pa),
            r_squared: Some(fit.r_squared),
            points: fit.points,
        };
        let svg = kawakita_svg(&samples, &summary).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        assert!(svg.contains("fit: a = 0.5000, 1/b = 100.0000 kPa"), "{svg}");
        assert!(svg.contains("C &lt; 0.25"));
    }
}
