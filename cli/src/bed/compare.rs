//! The comparison of `granbed-cli bed --types`: several granule types
//! compressed from the same poured bed, one row per type in
//! `comparison.csv` and `comparison.json`, and the overlaid plots
//! `comparison_pressure.svg` (P against C), `comparison_density.svg`
//! (mean granule relative density against C) and `comparison_profile.svg`
//! (the compaction profile, the bed's solid fraction D against P), and the
//! series' `report.html` ([`super::series_report`]).

use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::Real;
use granbed_kernel::material::GranuleType;
use serde::Serialize;

use super::outputs::{KawakitaSummary, Summary, fit_linear, kawakita_doubts};
use super::outputs::{heckel_rows, upper_pressure};
use super::plots::profile_svg;
use super::plots::{overlay_svg, strain_of};
use super::run::{BedRun, BedSample};
use super::series_report::{SeriesReport, write_series_report};
use crate::csv::{CsvWriter, Field};
use crate::output::{create_file, finish_file, write_json, write_text};

/// File name of the comparison table.
pub const COMPARISON_CSV: &str = "comparison.csv";
/// File name of the comparison as JSON.
pub const COMPARISON_JSON: &str = "comparison.json";
/// File name of the overlaid pressure plot.
pub const PRESSURE_SVG: &str = "comparison_pressure.svg";
/// File name of the overlaid relative-density plot.
pub const DENSITY_SVG: &str = "comparison_density.svg";
/// File name of the overlaid compaction profiles (D against P).
pub const PROFILE_SVG: &str = "comparison_profile.svg";

/// Columns of [`COMPARISON_CSV`], in order (`NaN` where the summary has
/// `null`, e.g. no Kawakita fit for a run that ended before its window).
pub const COMPARISON_COLUMNS: [&str; 22] = [
    "type",
    "seed",
    "yield_stress_pa",
    "eta0",
    "kawakita_a",
    "kawakita_inv_b_pa",
    "kawakita_r_squared",
    "kawakita_points",
    "kawakita_ok",
    "heckel_yield_pressure_pa",
    "heckel_r_squared",
    "heckel_ok",
    "initial_solid_fraction",
    "max_pressure_pa",
    "final_strain",
    "final_pressure_pa",
    "final_relative_density",
    "final_coordination",
    "elastic_recovery",
    "plasticity_factor",
    "quasi_static_passed",
    "wall_time_s",
];

/// One type's row: the values of its `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ComparisonRow {
    /// Granule type.
    #[serde(rename = "type")]
    pub granule_type: &'static str,
    /// Seed of the run's pour and mesh rotations.
    pub seed: u64,
    /// Yield stress, Pa.
    pub yield_stress_pa: Real,
    /// Initial relative density η0.
    pub eta0: Real,
    /// Kawakita a.
    pub kawakita_a: Option<Real>,
    /// Kawakita 1/b, Pa.
    pub kawakita_inv_b_pa: Option<Real>,
    /// R² of the Kawakita fit.
    pub kawakita_r_squared: Option<Real>,
    /// Output rows in the fit (C ≥ the scene's `kawakita_min_strain`).
    pub kawakita_points: usize,
    /// The Kawakita fit exists and describes the bed (1 in the CSV): none
    /// of the summary's doubts ([`kawakita_doubts`]: a in (0, 1], 1/b > 0,
    /// R² at least [`super::outputs::FIT_MIN_R_SQUARED`]). A fit with 0 is no material
    /// figure; the summary's warning says why.
    pub kawakita_ok: bool,
    /// Heckel mean yield pressure, Pa.
    pub heckel_yield_pressure_pa: Option<Real>,
    /// R² of the Heckel fit.
    pub heckel_r_squared: Option<Real>,
    /// The Heckel fit exists with [`fit_linear`] R² (1 in
    /// the CSV; 0: no material figure, as the summary warns).
    pub heckel_ok: bool,
    /// The poured bed's solid fraction D0.
    pub initial_solid_fraction: Real,
    /// Largest upper-punch pressure, Pa.
    pub max_pressure_pa: Real,
    /// Strain reached.
    pub final_strain: Real,
    /// Upper-punch pressure at the end, Pa.
    pub final_pressure_pa: Real,
    /// Mean granule relative density at the end.
    pub final_relative_density: Real,
    /// Coordination number Z at the end.
    pub final_coordination: Real,
    /// In-die elastic recovery after the upper punch's withdrawal (summary
    /// `unloading.elastic_recovery`; `None` without one or its lift-off).
    pub elastic_recovery: Option<Real>,
    /// Plasticity factor net / punch work of the withdrawal (summary
    /// `unloading.plasticity_factor`).
    pub plasticity_factor: Option<Real>,
    /// The run's quasi-static certificate passed (1 in the CSV; a row
    /// that failed it describes a bed with inertia in it: its summary's
    /// warning says which figure failed).
    pub quasi_static_passed: bool,
    /// Wall time of the compression, s.
    pub wall_time_s: f64,
    /// The error that stopped the run early, if any.
    pub error: Option<String>,
}

impl ComparisonRow {
    /// The row of type `t` from its run's summary.
    pub fn new(t: GranuleType, s: &Summary<'_>) -> Self {
        Self {
            granule_type: t.name(),
            seed: s.scene.seed,
            yield_stress_pa: s.yield_stress_pa,
            eta0: s.eta0,
            kawakita_a: s.kawakita.a,
            kawakita_inv_b_pa: s.kawakita.inv_b_pa,
            kawakita_r_squared: s.kawakita.r_squared,
            kawakita_points: s.kawakita.points,
            kawakita_ok: false,
            heckel_yield_pressure_pa: s.heckel.yield_pressure_pa,
            heckel_r_squared: s.heckel.r_squared,
            heckel_ok: false,
            initial_solid_fraction: s.initial_solid_fraction,
            max_pressure_pa: s.max_pressure_pa,
            final_strain: s.final_strain,
            final_pressure_pa: s.final_pressure_pa,
            final_relative_density: s.final_relative_density,
            final_coordination: s.final_coordination,
            elastic_recovery: s.unloading.and_then(|u| u.elastic_recovery),
            plasticity_factor: s.unloading.and_then(|u| u.plasticity_factor),
            quasi_static_passed: s.quasi_static.passed,
            wall_time_s: s.wall_time_s,
            error: s.error.clone(),
        }
        .with_fit_flags()
    }

    /// The row with `kawakita_ok` and `heckel_ok` set from its own fit
    /// values by the summary's rules ([`kawakita_doubts`],
    /// [`fit_linear`]).
    pub fn with_fit_flags(mut self) -> Self {
        let kawakita = KawakitaSummary {
            a: self.kawakita_a,
            inv_b_pa: self.kawakita_inv_b_pa,
            r_squared: self.kawakita_r_squared,
            points: self.kawakita_points,
            min_strain: Real::NAN,
        };
        self.kawakita_ok = self.kawakita_a.is_some() && kawakita_doubts(&kawakita).is_empty();
        self.heckel_ok = self.heckel_yield_pressure_pa.is_some()
            && self.heckel_r_squared.is_some_and(fit_linear);
        self
    }

    /// The legend of this run's curve in the overlaid plots: `name`, and
    /// what the table's columns would otherwise have to tell, that the run
    /// failed or did not pass its quasi-static certificate.
    pub fn curve_label(&self, name: &str) -> String {
        if self.error.is_some() {
            format!("{name} (failed)")
        } else if !self.quasi_static_passed {
            format!("{name} (not quasi-static)")
        } else {
            name.to_owned()
        }
    }

    fn fields(&self) -> [Field; COMPARISON_COLUMNS.len()] {
        let opt = |x: Option<Real>| Field::Real(x.unwrap_or(Real::NAN));
        [
            Field::Text(self.granule_type),
            Field::Int(self.seed),
            self.yield_stress_pa.into(),
            self.eta0.into(),
            opt(self.kawakita_a),
            opt(self.kawakita_inv_b_pa),
            opt(self.kawakita_r_squared),
            Field::Int(self.kawakita_points as u64),
            Field::Int(u64::from(self.kawakita_ok)),
            opt(self.heckel_yield_pressure_pa),
            opt(self.heckel_r_squared),
            Field::Int(u64::from(self.heckel_ok)),
            self.initial_solid_fraction.into(),
            self.max_pressure_pa.into(),
            self.final_strain.into(),
            self.final_pressure_pa.into(),
            self.final_relative_density.into(),
            self.final_coordination.into(),
            opt(self.elastic_recovery),
            opt(self.plasticity_factor),
            Field::Int(u64::from(self.quasi_static_passed)),
            self.wall_time_s.into(),
        ]
    }
}

/// The fields of [`COMPARISON_JSON`].
#[derive(Debug, Serialize)]
pub struct Comparison<'a> {
    /// granbed version.
    pub version: &'static str,
    /// The type whose sphere density the one shared pour used.
    pub pour_granule_type: &'static str,
    /// Wall time of the shared pour, s.
    pub pour_wall_time_s: f64,
    /// One row per type, in the order given.
    pub types: &'a [ComparisonRow],
}

/// Writes [`COMPARISON_CSV`], [`COMPARISON_JSON`], [`PRESSURE_SVG`],
/// [`DENSITY_SVG`] and [`PROFILE_SVG`] into `dir`: the rows and `runs`
/// are per type, in the same order.
pub fn write_comparison(
    dir: &Path,
    comparison: &Comparison<'_>,
    runs: &[&BedRun],
) -> anyhow::Result<()> {
    write_rows(&dir.join(COMPARISON_CSV), comparison.types)?;
    write_json(&dir.join(COMPARISON_JSON), comparison)?;
    let labels: Vec<String> = comparison
        .types
        .iter()
        .map(|r| r.curve_label(r.granule_type))
        .collect();
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    let suffix = format!(
        "by granule type (one pour, sphere density of {})",
        comparison.pour_granule_type
    );
    let svgs = write_overlays(
        dir,
        [PRESSURE_SVG, DENSITY_SVG, PROFILE_SVG],
        &labels,
        runs,
        &suffix,
    )?;
    let names: Vec<&str> = comparison.types.iter().map(|r| r.granule_type).collect();
    write_series_report(
        dir,
        &SeriesReport {
            title: format!("granbed bed series: granule types {}", names.join(", ")),
            about: format!(
                "Each granule type compressed from the same poured bed (the pour used the \
                 sphere density of {}, and took {:.1} s), so the rows differ by the material \
                 alone.",
                comparison.pour_granule_type, comparison.pour_wall_time_s
            ),
            member_dirs: names.iter().map(|&n| n.to_owned()).collect(),
            rows: comparison.types,
            spreads: None,
            files: &[COMPARISON_CSV, COMPARISON_JSON],
            svgs: &svgs,
        },
    )
}

/// Writes `rows` as a table of [`COMPARISON_COLUMNS`] to `path`.
pub fn write_rows(path: &Path, rows: &[ComparisonRow]) -> anyhow::Result<()> {
    let ctx = || format!("cannot write to `{}`", path.display());
    let mut csv = CsvWriter::new(create_file(path)?, &COMPARISON_COLUMNS).with_context(ctx)?;
    for row in rows {
        csv.write_row(&row.fields()).with_context(ctx)?;
    }
    finish_file(csv.into_inner(), path)
}

/// Writes the overlaid plots `[pressure, density, profile]` (file names
/// in `dir`) of the `runs`, one curve per run named by `labels`, the
/// titles ending with `suffix`; returns them as (file name, SVG text). The
/// profile, D against P, is what tells the runs apart: against the strain
/// every bed's D is D0/(1 − C).
pub fn write_overlays<'a>(
    dir: &Path,
    [pressure_file, density_file, profile_file]: [&'a str; 3],
    labels: &[&str],
    runs: &[&BedRun],
    suffix: &str,
) -> anyhow::Result<[(&'a str, String); 3]> {
    let curves: Vec<(&str, &[BedSample])> = labels
        .iter()
        .copied()
        .zip(runs.iter().map(|r| r.samples.as_slice()))
        .collect();
    let pressure = overlay_svg(
        &format!("Upper-punch pressure {suffix}"),
        "pressure P, kPa",
        &curves,
        (strain_of(true), |s| s.upper_pressure_pa * 1e-3),
        true,
    )?;
    let density = overlay_svg(
        &format!("Granule relative density {suffix}"),
        "mean relative density η0 V0/V",
        &curves,
        (strain_of(false), |s| s.relative_density_mean),
        false,
    )?;
    let profiles: Vec<(&str, Vec<(f64, f64)>)> = labels
        .iter()
        .copied()
        .zip(runs)
        .map(|(label, run)| {
            let points = heckel_rows(run, upper_pressure)
                .map(|(p, d, _)| (p * 1e-3, d))
                .collect();
            (label, points)
        })
        .collect();
    let profile = profile_svg(&format!("Compaction profile {suffix}"), &profiles)?;
    let svgs = [
        (pressure_file, pressure),
        (density_file, density),
        (profile_file, profile),
    ];
    for (name, svg) in &svgs {
        write_text(&dir.join(name), svg)?;
    }
    Ok(svgs)
}
