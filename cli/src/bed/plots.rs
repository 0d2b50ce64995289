//! The plots of a bed run as SVG (`plots/` in the output), drawn with
//! plotters' SVG backend like `granule`'s plots: no system fonts, text is
//! written as SVG `<text>` and laid out by the viewer.
//!
//! * `pressure_strain.svg`: upper- and lower-punch pressure against the
//!   axial strain C;
//! * `kawakita.svg`: P/C against P with the Kawakita fit line (points in
//!   the fit's strain window filled);
//! * `heckel.svg`: ln(1/(1 − D)) against P with the Heckel fit line;
//! * `coordination_strain.svg`: coordination number Z, without and with
//!   the walls;
//! * `relative_density_strain.svg`: mean granule relative density and
//!   Σsolid/ΣV;
//! * `heywood_strain.svg`: mean Heywood coefficient α_SV with d_V and with
//!   the nominal diameter;
//! * `solid_fraction_pressure.svg`: the compaction profile as the bed's
//!   solid fraction D (relative density of the bed) against the
//!   upper-punch pressure P;
//! * `coordination_density.svg`: Z, without and with the walls, against
//!   the granules' packing fraction (D without their inner pores);
//! * `energy_strain.svg`: where the punch's work went: the energy ledger
//!   (elastic, plastic, hourglass, contact losses, damping, kinetic)
//!   against C, in J, mJ or µJ (as the largest needs);
//! * `density_height.svg`: each granule's relative density where the run
//!   ended against its height in the compact, with the layer means;
//! * `die_wall_strain.svg`: the die wall's radial-to-axial stress ratio and
//!   its mobilised friction |F_z|/F_n against C, from where the punches
//!   carry load;
//! * `stress_height.svg`: the axial stress through the compact's height at
//!   each snapshot, with Janssen's curve;
//! * `density_map.svg`: the solid fraction and axial stress in the
//!   compact's radial × height section at the last snapshot
//!   ([`super::density_map::map_svg`]).
//!
//! The averaged quantities (pressures, Z, the die wall's forces) are drawn
//! at each output interval's mean strain, those taken at the rows
//! (densities, Heywood, energies) at the rows' strains ([`strain_of`]).

use std::path::Path;

use super::outputs::{
    DENSITY_LAYERS, DieWallSummary, HeckelSummary, KawakitaSummary, Summary, die_wall_summary,
    final_height_m, heckel_rows, kawakita_doubts, packing_fraction, upper_pressure,
};
use super::run::{BedRun, BedSample};
use crate::numbers::significant;
use crate::output::write_text;
use crate::plot::{Mark, Series, xy_svg, xy_svg_from};
use anyhow::Context as _;
use granbed_kernel::Real;

/// Sub-directory of the output directory holding the plots.
pub const PLOTS_DIR: &str = "plots";

/// The plot files, in the order [`write_plots`] writes them.
pub const PLOT_FILES: [&str; 13] = [
    "pressure_strain.svg",
    "kawakita.svg",
    "heckel.svg",
    "coordination_strain.svg",
    "relative_density_strain.svg",
    "heywood_strain.svg",
    "solid_fraction_pressure.svg",
    "coordination_density.svg",
    "energy_strain.svg",
    "density_height.svg",
    "die_wall_strain.svg",
    "stress_height.svg",
    "density_map.svg",
];

/// The energy ledger's terms drawn by `energy_strain.svg`, J, with their
/// legends: the punch's work first, then what it went into.
const ENERGY_TERMS: [(&str, Quantity); 7] = [
    ("punch work", |s| s.energies.punch_work),
    ("elastic Ψ", |s| s.energies.elastic),
    ("plastic dissipation", |s| s.energies.plastic),
    ("contact losses (friction, constraints)", |s| {
        s.energies.contact_loss()
    }),
    ("damping", |s| s.energies.damping),
    ("hourglass", |s| s.energies.hourglass),
    ("kinetic", |s| s.energies.kinetic),
];

/// The energy plot: each of [`ENERGY_TERMS`] against the strain
/// ([`crate::plot::energy_svg`]).
fn energy_svg(samples: &[BedSample]) -> anyhow::Result<String> {
    let terms: Vec<(&str, Vec<(f64, f64)>)> = ENERGY_TERMS
        .iter()
        .map(|&(label, y)| (label, samples.iter().map(|s| (s.strain, y(s))).collect()))
        .collect();
    crate::plot::energy_svg(
        "Energy: where the punch's work went",
        "axial strain C = (H0 - H)/H0",
        &terms,
    )
}

/// The density profile where the run ended: each granule's relative
/// density against the height of its centre in the compact, z/H, and the
/// summary's layer means at the layers' mid-heights.
fn density_height_svg(run: &BedRun, summary: &Summary) -> anyhow::Result<String> {
    let height = final_height_m(run);
    let granules = run
        .final_granules
        .iter()
        .map(|g| (g.relative_density, g.centre_m[2] / height));
    let means = summary.final_density_by_height.iter().filter_map(|l| {
        l.mean_relative_density
            .map(|m| (m, 0.5 * (l.from_height + l.to_height)))
    });
    let series = [
        Series::new("granules", Mark::Dots, granules),
        Series::new(
            format!("mean of each of {DENSITY_LAYERS} layers"),
            Mark::Line,
            means,
        ),
    ];
    xy_svg_from(
        "Granule density by height where the run ended",
        (
            "granule relative density η0 V0/V",
            "height in the compact z/H",
        ),
        &series,
        (false, true),
    )
}

/// Points of Janssen's curve drawn for a profile: every twentieth of the
/// height.
const JANSSEN_POINTS: usize = 21;

/// The axial stress by height at each snapshot with a stress profile
/// (summary.json's `stress_by_height`), over the upper punch's pressure
/// in the same step, at the layers' mid-heights; and Janssen's curve
/// exp(−4μK (H − z)/D) for the last profile, from its own K and the
/// wall's μ (none without a material or a finite ratio).
fn stress_height_svg(summary: &Summary, die_radius_m: Real) -> anyhow::Result<String> {
    let profiles = &summary.stress_by_height;
    let mut series: Vec<Series> = profiles
        .iter()
        .map(|p| {
            let up = p.walls.upper_punch_pa;
            Series::new(
                format!("C = {:.3}", p.strain),
                Mark::Line,
                p.layers
                    .iter()
                    .map(move |l| (l.axial_stress_pa / up, 0.5 * (l.bottom + l.top))),
            )
        })
        .collect();
    let mu = summary.material.map(|m| m.friction);
    if let (Some(last), Some(mu)) = (profiles.last(), mu) {
        let (k, h) = (last.lateral_to_axial, last.walls.height_m);
        let janssen = (0..JANSSEN_POINTS).map(move |i| {
            let z = i as Real / (JANSSEN_POINTS - 1) as Real;
            let depth = (1.0 - z) * h;
            ((-4.0 * mu * k * depth / (2.0 * die_radius_m)).exp(), z)
        });
        if janssen.clone().all(|(x, _)| x.is_finite()) {
            series.push(Series::new(
                format!("Janssen at C = {:.3} (its K, μ)", last.strain),
                Mark::Dashed,
                janssen,
            ));
        }
    }
    xy_svg_from(
        "Axial stress through the compact",
        (
            "layer's mean axial stress −σzz / upper-punch pressure",
            "height in the compact z/H",
        ),
        &series,
        (false, true),
    )
}

/// The value of a sample a curve shows.
pub type Quantity = fn(&BedSample) -> Real;

/// One line per (label, samples) of `y` against the strain `x`
/// ([`strain_of`]), overlaid with a legend (the `--types` comparison
/// plots).
pub fn overlay_svg(
    title: &str,
    y_desc: &str,
    curves: &[(&str, &[BedSample])],
    (x, y): (Quantity, Quantity),
    y_from_zero: bool,
) -> anyhow::Result<String> {
    let series: Vec<Series> = curves
        .iter()
        .map(|(label, samples)| {
            Series::new(*label, Mark::Line, samples.iter().map(|s| (x(s), y(s))))
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

/// The compaction profile of each run (label, its (P in kPa, D) points):
/// the bed's solid fraction D against the upper-punch pressure P, under
/// `title`.
pub fn profile_svg(title: &str, runs: &[(&str, Vec<(f64, f64)>)]) -> anyhow::Result<String> {
    let series: Vec<Series> = runs
        .iter()
        .map(|(label, points)| Series::new(*label, Mark::Line, points.iter().copied()))
        .collect();
    xy_svg(
        title,
        "upper-punch pressure P, kPa",
        "bed solid fraction D",
        &series,
        false,
    )
}

/// The strain a quantity of a row belongs to: [`BedSample::mean_strain`]
/// for the averages over the output interval (forces, pressures, Z),
/// [`BedSample::strain`] for what was taken at the row.
pub fn strain_of(averaged: bool) -> Quantity {
    if averaged {
        |s| s.mean_strain
    } else {
        |s| s.strain
    }
}

/// Two curves (label, value) of the samples against the strain `x`
/// ([`strain_of`]), the second dashed, so that both show where they lie on
/// each other (the two relative densities of a bed of one granule size
/// nearly do).
fn against_strain(
    samples: &[BedSample],
    x: Quantity,
    curves: [(&str, Quantity); 2],
) -> [Series; 2] {
    let [first, second] = curves;
    [(first, Mark::Line), (second, Mark::DashedLine)]
        .map(|((label, y), mark)| Series::new(label, mark, samples.iter().map(|s| (x(s), y(s)))))
}

/// A fit's plot: `rows` (x, y, C) before the strain window `min_strain`
/// as rings, those in it as dots, and the fitted `line` (its legend and
/// y(x)), if any, over the window's x range; the y axis from zero if
/// `y_from_zero`.
fn fit_svg(
    title: &str,
    (x_desc, y_desc): (&str, &str),
    rows: impl Iterator<Item = (f64, f64, f64)> + Clone,
    min_strain: f64,
    line: Option<(String, &dyn Fn(f64) -> f64)>,
    y_from_zero: bool,
) -> anyhow::Result<String> {
    let before = rows.clone().filter(|&(_, _, c)| c < min_strain);
    let within = rows.filter(|&(_, _, c)| c >= min_strain);
    let mut series = vec![
        Series::new(
            format!("C < {min_strain}"),
            Mark::Rings,
            before.map(|(x, y, _)| (x, y)),
        ),
        Series::new(
            format!("C ≥ {min_strain} (fitted)"),
            Mark::Dots,
            within.map(|(x, y, _)| (x, y)),
        ),
    ];
    if let Some((label, y)) = line {
        let (lo, hi) = series[1]
            .points()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.0), hi.max(p.0))
            });
        if lo <= hi {
            series.push(Series::new(
                label,
                Mark::Dashed,
                [(lo, y(lo)), (hi, y(hi))].into_iter(),
            ));
        }
    }
    xy_svg(title, x_desc, y_desc, &series, y_from_zero)
}

/// The legend of a fit line: `figures`, marked as rejected when the
/// summary warns that the fit is no material figure (`material` false).
fn fit_label(figures: String, material: bool) -> String {
    if material {
        format!("fit: {figures}")
    } else {
        format!("rejected fit (see the warnings): {figures}")
    }
}

/// The R² of a fit for a legend.
fn r2_text(r_squared: Option<Real>) -> String {
    r_squared.map_or("n/a".into(), |r| format!("{r:.4}"))
}

/// The Kawakita plot: P/C against P (kPa) of the samples with C > 0, the
/// fitted ones (C ≥ the fit's window) filled, and the line
/// P/C = P/a + (1/b)/a over the fitted pressures.
pub fn kawakita_svg(samples: &[BedSample], fit: &KawakitaSummary) -> anyhow::Result<String> {
    let rows = samples.iter().filter(|s| s.mean_strain > 0.0).map(|s| {
        (
            s.upper_pressure_pa * 1e-3,
            s.upper_pressure_pa / s.mean_strain * 1e-3,
            s.mean_strain,
        )
    });
    // In kPa: P/C = P/a + (1/b)/a.
    let line = fit
        .a
        .zip(fit.inv_b_pa)
        .map(|(a, inv_b)| (a, inv_b, move |p: f64| p / a + inv_b * 1e-3 / a));
    let line = line.as_ref().map(|(a, inv_b, y)| {
        let label = fit_label(
            format!(
                "a = {a:.4}, 1/b = {} kPa, R² = {}",
                significant(inv_b * 1e-3, 4),
                r2_text(fit.r_squared)
            ),
            kawakita_doubts(fit).is_empty(),
        );
        (label, y as &dyn Fn(f64) -> f64)
    });
    fit_svg(
        "Kawakita plot",
        ("upper-punch pressure P, kPa", "P/C, kPa"),
        rows,
        fit.min_strain,
        line,
        true,
    )
}

/// The Heckel plot: ln(1/(1 − D)) against P (kPa) of the rows `(P [Pa], D,
/// C)` the fit can use (P finite, 0 < D < 1), the fitted ones (C ≥ the fit's window) filled, and
/// the line K·P + A over the fitted pressures.
pub fn heckel_svg(
    rows: impl Iterator<Item = (Real, Real, Real)> + Clone,
    fit: &HeckelSummary,
) -> anyhow::Result<String> {
    let rows = rows
        .filter(|&(p, d, _)| granbed_kernel::analysis::bed::heckel_usable(p, d))
        .map(|(p, d, c)| (p * 1e-3, -(-d).ln_1p(), c));
    // In kPa: K·P + A with K per kPa.
    let line = fit
        .k_per_pa
        .zip(fit.a)
        .map(|(k, a)| move |p: f64| k * 1e3 * p + a);
    let line = line.as_ref().map(|y| {
        let label = fit_label(
            format!(
                "P_y = {} kPa, A = {:.4}, R² = {}",
                significant(fit.yield_pressure_pa.unwrap_or(f64::NAN) * 1e-3, 4),
                fit.a.unwrap_or(f64::NAN),
                r2_text(fit.r_squared)
            ),
            fit.linear(),
        );
        (label, y as &dyn Fn(f64) -> f64)
    });
    fit_svg(
        "Heckel plot",
        (
            "upper-punch pressure P, kPa",
            "ln(1/(1 - D)), D the bed's solid fraction",
        ),
        rows,
        fit.min_strain,
        line,
        // ln(1/(1 - D)) of a bed starts near ln(1/(1 - D0)), far from 0.
        false,
    )
}

/// The SVG text of every plot of `run`, named as in [`PLOT_FILES`], with
/// the fits of its `summary`.
pub fn plots(
    run: &BedRun,
    summary: &Summary,
) -> anyhow::Result<[(&'static str, String); PLOT_FILES.len()]> {
    let samples = &run.samples[..];
    const C: &str = "axial strain C = (H0 - H)/H0";
    let mut pressure = against_strain(
        samples,
        strain_of(true),
        [
            ("upper punch", |s| s.upper_pressure_pa * 1e-3),
            ("lower punch", |s| s.lower_pressure_pa * 1e-3),
        ],
    )
    .into_iter()
    .collect::<Vec<_>>();
    // The withdrawal after the final strain, from the turn on.
    if let Some(u) = &run.unloading {
        let turn = samples
            .last()
            .map(|s| (s.mean_strain, s.upper_pressure_pa * 1e-3));
        pressure.push(Series::new(
            "upper punch, withdrawing",
            Mark::Line,
            turn.into_iter().chain(
                u.samples
                    .iter()
                    .map(|s| (s.mean_strain, s.upper_pressure_pa * 1e-3)),
            ),
        ));
    }
    let mut coordination = against_strain(
        samples,
        strain_of(true),
        [
            ("granule pairs", |s| s.coordination),
            ("with walls", |s| s.coordination_with_walls),
        ],
    )
    .into_iter()
    .collect::<Vec<_>>();
    // At the snapshots, from their contact networks (the pairs that carried
    // a force in the step, any sweep): the whole bed's and the interior's.
    let interior: Vec<(f64, f64)> = summary
        .contact_network
        .iter()
        .map(|n| (n.strain, n.interior_coordination))
        .filter(|(_, z)| z.is_finite())
        .collect();
    if !interior.is_empty() {
        let granules = summary.scene.granules as f64;
        coordination.push(Series::new(
            "whole bed, pairs with a force in the snapshot's step",
            Mark::Rings,
            summary
                .contact_network
                .iter()
                .map(|n| (n.strain, 2.0 * n.pairs as f64 / granules)),
        ));
        coordination.push(Series::new(
            "interior granules (centres a diameter from every wall), the same",
            Mark::Dots,
            interior.into_iter(),
        ));
    }
    let density = against_strain(
        samples,
        strain_of(false),
        [
            ("mean of η0 V0/V", |s| s.relative_density_mean),
            ("Σ solid / Σ V", |s| s.relative_density_solid),
        ],
    );
    let heywood = against_strain(
        samples,
        strain_of(false),
        [
            ("d_V S/V", |s| s.heywood_dv),
            ("d S/V (nominal d)", |s| s.heywood_d),
        ],
    );
    // The die wall's two ratios at each row's mean strain, from the first
    // row whose upper-punch pressure reaches 5 % of its largest: before,
    // the bed's own weight and the settling's impulses are a large part of
    // the stresses (rows where a ratio is not defined are left out too).
    let loaded = 0.05 * summary.max_pressure_pa;
    let walls: Vec<(Real, DieWallSummary)> = samples
        .iter()
        .skip_while(|s| !(s.upper_pressure_pa >= loaded && loaded > 0.0))
        .map(|s| (s.mean_strain, die_wall_summary(run, s)))
        .collect();
    let wall_ratio = |of: fn(&DieWallSummary) -> Option<Real>| {
        walls
            .iter()
            .filter_map(move |(c, w)| of(w).map(|r| (*c, r)))
            .collect::<Vec<_>>()
    };
    let friction = wall_ratio(|w| w.friction_to_normal);
    // Coulomb's limit of the second ratio, over the same strains.
    let mu = summary.material.map_or(Real::NAN, |m| m.friction);
    let limit = friction
        .first()
        .zip(friction.last())
        .map(|(a, b)| [(a.0, mu), (b.0, mu)]);
    let mut die_wall = vec![
        Series::new(
            "K: die-wall pressure / mean punch pressure",
            Mark::Line,
            wall_ratio(|w| w.radial_to_axial).into_iter(),
        ),
        Series::new(
            "|die-wall friction| / die-wall normal force",
            Mark::DashedLine,
            friction.into_iter(),
        ),
    ];
    // No line (nor legend) without a known μ.
    if let Some(limit) = limit.filter(|_| mu.is_finite()) {
        die_wall.push(Series::new(
            "friction coefficient μ",
            Mark::Dashed,
            limit.into_iter(),
        ));
    }
    let [
        pressure_f,
        kawakita_f,
        heckel_f,
        coordination_f,
        density_f,
        heywood_f,
        profile_f,
        coordination_density_f,
        energy_f,
        density_height_f,
        die_wall_f,
        stress_height_f,
        density_map_f,
    ] = PLOT_FILES;
    // Unlabelled: the title and axes say what the one curve is (no legend).
    let profile = [(
        "",
        heckel_rows(run, upper_pressure)
            .map(|(p, d, _)| (p * 1e-3, d))
            .collect(),
    )];
    // Z is an interval average: its packing fraction is the one at the
    // interval's mean strain.
    let packing = |s: &BedSample| packing_fraction(run, s, s.mean_strain);
    let coordination_density: [(&str, Mark, Quantity); 2] = [
        ("granule pairs", Mark::Line, |s| s.coordination),
        ("with walls", Mark::DashedLine, |s| {
            s.coordination_with_walls
        }),
    ];
    let coordination_density = coordination_density.map(|(label, mark, z)| {
        Series::new(label, mark, samples.iter().map(|s| (packing(s), z(s))))
    });
    Ok([
        (
            pressure_f,
            xy_svg("Punch pressure", C, "pressure P, kPa", &pressure, true)?,
        ),
        (kawakita_f, kawakita_svg(samples, &summary.kawakita)?),
        (
            heckel_f,
            heckel_svg(heckel_rows(run, upper_pressure), &summary.heckel)?,
        ),
        (
            coordination_f,
            xy_svg("Coordination number", C, "Z", &coordination, true)?,
        ),
        (
            density_f,
            xy_svg(
                "Granule relative density",
                C,
                "relative density η",
                &density,
                false,
            )?,
        ),
        (
            heywood_f,
            xy_svg(
                "Heywood coefficient (mean over granules)",
                C,
                "α_SV",
                &heywood,
                false,
            )?,
        ),
        (
            profile_f,
            profile_svg("Compaction profile: the bed's solid fraction", &profile)?,
        ),
        (
            coordination_density_f,
            xy_svg_from(
                "Coordination number against the granules' packing fraction",
                (
                    "granules' packing fraction (envelope volume / die volume)",
                    "Z",
                ),
                &coordination_density,
                (false, true),
            )?,
        ),
        (energy_f, energy_svg(samples)?),
        (density_height_f, density_height_svg(run, summary)?),
        (
            die_wall_f,
            xy_svg(
                "The die wall: radial-to-axial stress and mobilised friction",
                C,
                "ratio",
                &die_wall,
                true,
            )?,
        ),
        (
            stress_height_f,
            stress_height_svg(summary, 0.5e-3 * summary.scene.die_diameter_mm)?,
        ),
        (
            density_map_f,
            super::density_map::map_svg(summary.final_density_map.as_ref()),
        ),
    ])
}

/// Writes the plots of `run` into `dir`/[`PLOTS_DIR`] (created) and
/// returns them (file name, SVG text) for the report.
pub fn write_plots(
    dir: &Path,
    run: &BedRun,
    summary: &Summary,
) -> anyhow::Result<[(&'static str, String); PLOT_FILES.len()]> {
    let dir = dir.join(PLOTS_DIR);
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("cannot create directory `{}`", dir.display()))?;
    let svgs = plots(run, summary)?;
    for (name, svg) in &svgs {
        write_text(&dir.join(name), svg)?;
    }
    Ok(svgs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every term of the ledger is drawn with its legend, in the unit of
    /// the largest value.
    #[test]
    fn the_energy_plot_has_every_term_in_its_unit() {
        let samples: Vec<BedSample> = (0..=10)
            .map(|i| {
                let c = 0.03 * f64::from(i);
                let mut s = BedSample {
                    strain: c,
                    ..BedSample::default()
                };
                s.energies.punch_work = 0.02 * c;
                s.energies.elastic = 0.01 * c;
                s
            })
            .collect();
        let svg = energy_svg(&samples).unwrap();
        assert!(svg.contains("energy, mJ"), "{svg}");
        for (label, _) in ENERGY_TERMS {
            let label = crate::output::escape_markup(label);
            assert!(
                svg.contains(&format!("\n{label}\n</text>")),
                "no legend {label}"
            );
        }
        // 6 mJ of punch work at C = 0.3: a tick at 6 (mJ), none at 0.006.
        assert!(svg.contains("\n6\n</text>") && !svg.contains("\n0.006\n</text>"));
    }

    #[test]
    fn the_kawakita_plot_has_the_fit_line() {
        // C = abP/(1 + bP) with a = 0.5, 1/b = 100 kPa.
        let samples: Vec<BedSample> = (0..40)
            .map(|i| {
                let p = 5e3 * f64::from(i);
                let c = 0.5 * p / (1e5 + p);
                BedSample {
                    strain: c,
                    mean_strain: c,
                    upper_pressure_pa: p,
                    ..BedSample::default()
                }
            })
            .collect();
        let points = samples.iter().map(|s| (s.upper_pressure_pa, s.mean_strain));
        let fit = granbed_kernel::analysis::bed::kawakita_fit(points, 0.25).unwrap();
        let summary = KawakitaSummary {
            a: Some(fit.a),
            inv_b_pa: Some(fit.inv_b_pa),
            r_squared: Some(fit.r_squared),
            points: fit.points,
            min_strain: 0.25,
        };
        let svg = kawakita_svg(&samples, &summary).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..100]);
        assert!(svg.contains("fit: a = 0.5000, 1/b = 100.0 kPa"), "{svg}");
        assert!(svg.contains("C &lt; 0.25"));
        // A fit outside the law's regime (a > 1) is drawn, marked rejected.
        let odd = KawakitaSummary {
            a: Some(3.5),
            ..summary
        };
        let svg = kawakita_svg(&samples, &odd).unwrap();
        assert!(
            svg.contains("rejected fit (see the warnings): a = 3.5000"),
            "{svg}"
        );
    }

    #[test]
    fn the_heckel_plot_has_the_fit_line_and_only_the_rows_of_the_law() {
        // ln(1/(1 − D)) = P/(80 kPa) + 0.5, and one row past D = 1.
        let mut rows: Vec<(Real, Real, Real)> = (0..30)
            .map(|i| {
                let p = 4e3 * f64::from(i);
                (p, 1.0 - (-(p / 80e3 + 0.5)).exp(), 0.01 * f64::from(i))
            })
            .collect();
        rows.push((2e5, 1.05, 0.3));
        let window = rows.iter().filter(|r| r.2 >= 0.2).map(|r| (r.0, r.1));
        let fit = granbed_kernel::analysis::bed::heckel_fit(window).unwrap();
        let summary = HeckelSummary {
            yield_pressure_pa: Some(fit.yield_pressure_pa),
            k_per_pa: Some(fit.k_per_pa),
            a: Some(fit.a),
            d_a: Some(fit.d_a),
            d_b: None,
            r_squared: Some(fit.r_squared),
            points: fit.points,
            min_strain: 0.2,
        };
        let svg = heckel_svg(rows.iter().copied(), &summary).unwrap();
        assert!(svg.contains("fit: P_y = 80.00 kPa, A = 0.5000"), "{svg}");
        let bent = HeckelSummary {
            r_squared: Some(0.5),
            ..summary
        };
        let svg_bent = heckel_svg(rows.iter().copied(), &bent).unwrap();
        assert!(svg_bent.contains("rejected fit (see the warnings): P_y = 80.00 kPa"));
        assert!(svg.contains("C &lt; 0.2") && svg.contains("(fitted)"));
        // Rows the law does not cover are not drawn: D = 0 would plot at
        // ln 1 = 0, D < 0 below it (D > 1 gives NaN, which no plot draws).
        let mut more = rows.clone();
        more.extend([(1.5e5, 0.0, 0.3), (1.6e5, -0.1, 0.3)]);
        let svg_more = heckel_svg(more.iter().copied(), &summary).unwrap();
        assert_eq!(
            svg_more.matches("<circle").count(),
            svg.matches("<circle").count()
        );
    }
}
