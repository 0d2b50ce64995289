//! The files `granbed-cli granule` writes: the force–displacement CSV, the
//! summary JSON, the per-type table of `--types`, and text files (SVG).
//! Every writer names the file in its error.

use crate::output::{create_file, finish_file};
use std::path::Path;

use anyhow::Context as _;
use granbed_kernel::material::GranuleType;
use granbed_kernel::scene::platens::{PlatenSample, SAMPLE_COLUMNS};

use super::summary::Summary;
use crate::csv::{CsvWriter, Field, write_table};

/// File name of the force–displacement table.
pub const FORCE_CSV: &str = "force_displacement.csv";
/// File name of the run summary.
pub const SUMMARY_JSON: &str = "summary.json";
/// File name of the force–displacement plot.
pub const FORCE_SVG: &str = "force_displacement.svg";
/// File name of the per-type table of `--types`.
pub const TYPES_CSV: &str = "types.csv";
/// File name of the overlaid plot of `--types`.
pub const TYPES_SVG: &str = "force_displacement_types.svg";

/// Header of [`TYPES_CSV`].
pub const TYPES_COLUMNS: [&str; 12] = [
    "type",
    "sigma_y_pa",
    "eta0",
    "sigma_eff0_pa",
    "sigma_est_pa",
    "slope_n_per_m",
    "fit_r_squared",
    "quasi_static_passed",
    "steps",
    "wall_time_s",
    "energy_residual_rel",
    "return_map_gap_rel",
];

/// The cells of one sample, in the order of [`SAMPLE_COLUMNS`] (the header
/// of [`FORCE_CSV`]).
pub fn force_row(s: &PlatenSample) -> [Field; SAMPLE_COLUMNS.len()] {
    let v = s.values();
    core::array::from_fn(|k| v.get(k).map_or(Field::Int(s.steps), |&x| Field::Real(x)))
}

/// Writes `samples` as [`FORCE_CSV`] rows to `path`.
pub fn write_force_csv(path: &Path, samples: &[PlatenSample]) -> anyhow::Result<()> {
    write_table(path, &SAMPLE_COLUMNS, samples.iter().map(force_row))
}

/// Writes `summary` as pretty-printed JSON to `path` (see
/// [`crate::output::write_json`]).
pub fn write_summary_json(path: &Path, summary: &Summary) -> anyhow::Result<()> {
    crate::output::write_json(path, summary)
}

pub use crate::output::write_text;

/// The [`TYPES_CSV`] row of one type's summary (`NaN` for a measure that
/// is `null` in its summary).
fn types_row(t: GranuleType, s: &Summary) -> [Field; TYPES_COLUMNS.len()] {
    let r = Field::Real;
    let opt = |x: Option<f64>| Field::Real(x.unwrap_or(f64::NAN));
    [
        Field::Text(t.name()),
        r(s.material.yield_stress_pa),
        r(s.material.eta0),
        r(s.sigma_eff0_pa),
        opt(s.sigma_est_pa),
        opt(s.slope_n_per_m),
        opt(s.fit_r_squared),
        Field::Int(u64::from(s.quasi_static.passed)),
        Field::Int(s.steps),
        r(s.wall_time_s),
        opt(s.energy_residual_rel),
        opt(s.return_map_gap_rel),
    ]
}

/// Writes one [`TYPES_CSV`] row per `(type, summary)`, in the given order.
pub fn write_types_csv(path: &Path, runs: &[(GranuleType, &Summary)]) -> anyhow::Result<()> {
    let ctx = || format!("cannot write to `{}`", path.display());
    let mut csv = CsvWriter::new(create_file(path)?, &TYPES_COLUMNS).with_context(ctx)?;
    for (t, s) in runs {
        csv.write_row(&types_row(*t, s)).with_context(ctx)?;
    }
    finish_file(csv.into_inner(), path)
}
