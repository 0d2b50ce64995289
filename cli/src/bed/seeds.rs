//! `granbed-cli bed --seeds`: the scene poured and compressed once per
//! seed, each run into `DIR/seed_<S>/` (resumable alone with `--resume`),
//! and the run-to-run spread of the bed's figures in `DIR` (physics.md §8
//! P2: Kawakita a and 1/b with their spread over random beds):
//!
//! * `seeds.csv`: one row per seed, the columns of `--types`'
//!   `comparison.csv` ([`super::compare::COMPARISON_COLUMNS`]);
//! * `seeds_spread.csv`: per figure ([`SPREAD_FIGURES`]) the runs that have
//!   it (a fit the run's summary warns about left out) and those left out,
//!   its mean, sample standard deviation, smallest and largest value and
//!   their difference;
//! * `seeds.json`: both tables;
//! * `seeds_pressure.svg`, `seeds_density.svg`: one curve per seed.

use core::fmt;
use core::str::FromStr;

use anyhow::Context as _;
use granbed_kernel::Real;
use serde::Serialize;

use super::compare::{ComparisonRow, write_overlays, write_rows};
use super::series_report::{SeriesReport, write_series_report};
use super::{BedArgs, Scene, SeriesRun, outputs, run, series, series_failures};
use crate::csv::{CsvWriter, Field};
use crate::output::{Streams, create_file, finish_file, write_json};

/// File name of the per-seed table.
pub const SEEDS_CSV: &str = "seeds.csv";
/// File name of the spread table.
pub const SPREAD_CSV: &str = "seeds_spread.csv";
/// File name of both tables as JSON.
pub const SEEDS_JSON: &str = "seeds.json";
/// File names of the overlaid pressure and density plots.
pub const SEEDS_SVG: [&str; 3] = [
    "seeds_pressure.svg",
    "seeds_density.svg",
    "seeds_profile.svg",
];

/// The most seeds one command takes (each is a whole run).
pub const MAX_SEEDS: usize = 100;

/// The sub-directory of seed `seed`'s run.
pub fn seed_dir(seed: u64) -> String {
    format!("seed_{seed}")
}

/// `--seeds`: a comma list of distinct seeds, each a whole number
/// 0 ≤ S < 2^64, at most [`MAX_SEEDS`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SeedList(pub Vec<u64>);

impl FromStr for SeedList {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let seeds = crate::numbers::distinct_list(s, crate::numbers::whole::<u64>(0, u64::MAX))?;
        if seeds.len() > MAX_SEEDS {
            return Err(format!(
                "{} seeds: at most {MAX_SEEDS} (each is a whole run)",
                seeds.len()
            ));
        }
        Ok(Self(seeds))
    }
}

impl fmt::Display for SeedList {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let texts: Vec<String> = self.0.iter().map(u64::to_string).collect();
        f.write_str(&texts.join(","))
    }
}

/// A figure of a run's row whose spread over the seeds is reported.
pub type Figure = fn(&ComparisonRow) -> Option<Real>;

/// The figures of [`SPREAD_CSV`], by their `seeds.csv` column names. A fit
/// the run's summary warns about (Kawakita outside the law's regime, Heckel
/// with R² below [`super::outputs::FIT_MIN_R_SQUARED`]) is left out: its figures are not
/// material figures, and one such run (a 1/b ≤ 0, say) would move the mean.
pub const SPREAD_FIGURES: [(&str, Figure); 10] = [
    ("kawakita_a", |r| r.kawakita_a.filter(|_| r.kawakita_ok)),
    ("kawakita_inv_b_pa", |r| {
        r.kawakita_inv_b_pa.filter(|_| r.kawakita_ok)
    }),
    ("heckel_yield_pressure_pa", |r| {
        r.heckel_yield_pressure_pa.filter(|_| r.heckel_ok)
    }),
    ("initial_solid_fraction", |r| Some(r.initial_solid_fraction)),
    ("max_pressure_pa", |r| Some(r.max_pressure_pa)),
    ("final_pressure_pa", |r| Some(r.final_pressure_pa)),
    ("final_relative_density", |r| Some(r.final_relative_density)),
    ("final_coordination", |r| Some(r.final_coordination)),
    ("elastic_recovery", |r| r.elastic_recovery),
    ("plasticity_factor", |r| r.plasticity_factor),
];

/// Columns of [`SPREAD_CSV`], in order.
pub const SPREAD_COLUMNS: [&str; 8] = [
    "figure", "runs", "left_out", "mean", "std", "min", "max", "spread",
];

/// One figure's spread over the runs (the runs without it left out: a fit
/// the run's strain does not reach or its summary warns about, a NaN).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// The `seeds.csv` column.
    pub figure: &'static str,
    /// Runs with a finite value.
    pub runs: usize,
    /// Runs left out.
    pub left_out: usize,
    /// Their mean (none without runs).
    pub mean: Option<Real>,
    /// Their sample standard deviation, with n − 1 (none below 2 runs).
    pub std: Option<Real>,
    /// The smallest value.
    pub min: Option<Real>,
    /// The largest value.
    pub max: Option<Real>,
    /// max − min.
    pub spread: Option<Real>,
}

/// The spread of `figure` over `rows` (summed in row order).
pub fn spread(name: &'static str, figure: Figure, rows: &[ComparisonRow]) -> Spread {
    let values: Vec<Real> = rows
        .iter()
        .filter_map(figure)
        .filter(|v| v.is_finite())
        .collect();
    let n = values.len();
    let mean = (n > 0).then(|| values.iter().sum::<Real>() / n as Real);
    let std = mean
        .filter(|_| n > 1)
        .map(|m| (values.iter().map(|v| (v - m) * (v - m)).sum::<Real>() / (n - 1) as Real).sqrt());
    let min = values.iter().copied().reduce(Real::min);
    let max = values.iter().copied().reduce(Real::max);
    Spread {
        figure: name,
        runs: n,
        left_out: rows.len() - n,
        mean,
        std,
        min,
        max,
        spread: min.zip(max).map(|(lo, hi)| hi - lo),
    }
}

/// The fields of [`SEEDS_JSON`].
#[derive(Debug, Serialize)]
pub struct SeedComparison<'a> {
    /// granbed version.
    pub version: &'static str,
    /// One row per seed, in the order given.
    pub seeds: &'a [ComparisonRow],
    /// The spread of each of [`SPREAD_FIGURES`].
    pub spread: &'a [Spread],
}

/// Writes [`SEEDS_CSV`], [`SPREAD_CSV`], [`SEEDS_JSON`] and [`SEEDS_SVG`]
/// into `dir`; `rows` and `runs` per seed, in the same order.
pub fn write_seeds(
    dir: &std::path::Path,
    rows: &[ComparisonRow],
    runs: &[&run::BedRun],
) -> anyhow::Result<()> {
    write_rows(&dir.join(SEEDS_CSV), rows)?;
    let spreads: Vec<Spread> = SPREAD_FIGURES
        .iter()
        .map(|&(name, figure)| spread(name, figure, rows))
        .collect();
    let path = dir.join(SPREAD_CSV);
    let ctx = || format!("cannot write to `{}`", path.display());
    let mut csv = CsvWriter::new(create_file(&path)?, &SPREAD_COLUMNS).with_context(ctx)?;
    for s in &spreads {
        let opt = |x: Option<Real>| Field::Real(x.unwrap_or(Real::NAN));
        csv.write_row(&[
            Field::Text(s.figure),
            Field::Int(s.runs as u64),
            Field::Int(s.left_out as u64),
            opt(s.mean),
            opt(s.std),
            opt(s.min),
            opt(s.max),
            opt(s.spread),
        ])
        .with_context(ctx)?;
    }
    finish_file(csv.into_inner(), &path)?;
    write_json(
        &dir.join(SEEDS_JSON),
        &SeedComparison {
            version: env!("CARGO_PKG_VERSION"),
            seeds: rows,
            spread: &spreads,
        },
    )?;
    let labels: Vec<String> = rows
        .iter()
        .map(|r| r.curve_label(&format!("seed {}", r.seed)))
        .collect();
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    let suffix = rows.first().map_or(String::new(), |r| {
        format!("by seed ({} granules, one pour each)", r.granule_type)
    });
    let svgs = write_overlays(dir, SEEDS_SVG, &labels, runs, &suffix)?;
    let granule_type = rows.first().map_or("", |r| r.granule_type);
    write_series_report(
        dir,
        &SeriesReport {
            title: format!("granbed bed series: {} pours of {granule_type}", rows.len()),
            about: "Each seed pours its own bed and compresses it; the spread of a figure over \
                    the seeds is the run-to-run variation that the choice of a setting is \
                    judged against."
                .to_owned(),
            member_dirs: rows.iter().map(|r| seed_dir(r.seed)).collect(),
            rows,
            spreads: Some(&spreads),
            files: &[SEEDS_CSV, SPREAD_CSV, SEEDS_JSON],
            svgs: &svgs,
        },
    )
}

impl BedArgs {
    /// `--seeds`: pour and compress `base` with each seed into
    /// `DIR/seed_<S>/` in turn (each on all the -j threads), then write the
    /// spread into `DIR`. A run stopped by an error does not stop the
    /// others; an interrupt stops the whole command (the seeds not run
    /// named, the runs so far resumable).
    pub(super) fn run_seeds(
        &self,
        base: &Scene,
        seeds: &[u64],
        notes: &[String],
        pool: &rayon::ThreadPool,
        streams: &mut Streams<'_>,
    ) -> anyhow::Result<()> {
        let members: Vec<series::Member> = seeds
            .iter()
            .map(|&seed| series::Member::of_seed(&self.out, seed, base))
            .collect();
        let scenes: Vec<Scene> = members.iter().map(|m| m.scene.clone()).collect();
        for m in &members {
            self.keep_unfinished(&m.dir)?;
        }
        let dirs: Vec<std::path::PathBuf> = members.iter().map(|m| m.dir.clone()).collect();
        series::prepare_fresh(&self.out, &dirs, self.overwrite)?;
        crate::output::create_out_dir(&self.out)?;
        if !self.quiet {
            writeln!(
                streams.stderr,
                "bed: {} x {} granules ({} mesh) in a {} mm die to C = {}, {} pours (seeds {}), \
                 into `{}`",
                base.granules,
                base.granule_type,
                base.mesh,
                base.die_diameter_mm,
                base.final_strain,
                seeds.len(),
                SeedList(seeds.to_vec()),
                self.out.display()
            )?;
        }
        series::SeriesFile {
            format: series::FORMAT,
            kind: series::SeriesKind::Seeds,
            members: seeds.iter().map(u64::to_string).collect(),
            scene_toml: base.to_toml(),
            pour: None,
        }
        .write(&self.out)?;
        let mut series: Vec<SeriesRun> = members
            .iter()
            .zip(&scenes)
            .map(|(m, scene)| m.run(scene, None, None))
            .collect();
        let runs = self.compress_series(pool, &mut series, &self.out, "spread", notes, streams)?;
        write_seed_tables(&self.out, &scenes, &runs)?;
        series_failures(&series, runs)
    }
}

/// The spread of a `--seeds` series in `dir` ([`write_seeds`]): `scenes`
/// and `runs` per seed, in order.
pub(super) fn write_seed_tables(
    dir: &std::path::Path,
    scenes: &[Scene],
    runs: &[run::BedRun],
) -> anyhow::Result<()> {
    let rows: Vec<ComparisonRow> = scenes
        .iter()
        .zip(runs)
        .map(|(scene, r)| {
            let t = scene.granule_type()?;
            Ok(ComparisonRow::new(t, &outputs::summary(scene, r)))
        })
        .collect::<anyhow::Result<_>>()?;
    let run_refs: Vec<&run::BedRun> = runs.iter().collect();
    write_seeds(dir, &rows, &run_refs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_lists_parse_and_name_what_is_wrong() {
        assert_eq!("1, 2,3".parse::<SeedList>(), Ok(SeedList(vec![1, 2, 3])));
        assert_eq!(
            "18446744073709551615".parse::<SeedList>(),
            Ok(SeedList(vec![u64::MAX]))
        );
        assert!("1,1".parse::<SeedList>().unwrap_err().contains("twice"));
        assert!("1,-2".parse::<SeedList>().unwrap_err().contains("`-2`"));
        assert!("1,x".parse::<SeedList>().unwrap_err().contains("`x`"));
        let many: Vec<String> = (0..=MAX_SEEDS as u64).map(|s| s.to_string()).collect();
        assert!(
            many.join(",")
                .parse::<SeedList>()
                .unwrap_err()
                .contains("at most")
        );
        assert_eq!(SeedList(vec![4, 7]).to_string(), "4,7");
    }

    /// Mean, sample standard deviation (n − 1), min, max and spread of the
    /// runs that have the figure; none of them without runs, no standard
    /// deviation for one.
    #[test]
    fn the_spread_leaves_out_the_runs_without_the_figure() {
        let row = |a: Option<Real>| {
            ComparisonRow {
                granule_type: "B2",
                seed: 1,
                yield_stress_pa: 30e3,
                eta0: 0.8,
                kawakita_a: a,
                kawakita_inv_b_pa: Some(8e3),
                kawakita_r_squared: Some(0.99),
                kawakita_points: 0,
                kawakita_ok: false,
                heckel_yield_pressure_pa: None,
                heckel_r_squared: None,
                heckel_ok: false,
                initial_solid_fraction: 0.5,
                max_pressure_pa: 0.0,
                final_strain: 0.3,
                final_pressure_pa: 0.0,
                final_relative_density: 0.8,
                final_coordination: 0.0,
                elastic_recovery: None,
                plasticity_factor: None,
                quasi_static_passed: true,
                wall_time_s: 0.0,
                error: None,
            }
            .with_fit_flags()
        };
        let a: Figure = |r| r.kawakita_a;
        let rows = [
            row(Some(0.3)),
            row(None),
            row(Some(0.5)),
            row(Some(Real::NAN)),
            row(Some(0.4)),
        ];
        let s = spread("kawakita_a", a, &rows);
        assert_eq!(s.runs, 3);
        assert!((s.mean.unwrap() - 0.4).abs() < 1e-15);
        assert!((s.std.unwrap() - 0.1).abs() < 1e-15);
        assert_eq!((s.min, s.max), (Some(0.3), Some(0.5)));
        assert!((s.spread.unwrap() - 0.2).abs() < 1e-15);
        let one = spread("kawakita_a", a, &rows[..2]);
        assert_eq!((one.runs, one.std, one.spread), (1, None, Some(0.0)));
        let none = spread("kawakita_a", a, &rows[1..2]);
        assert_eq!((none.runs, none.mean, none.min), (0, None, None));
        assert_eq!((s.left_out, none.left_out), (2, 1));

        // The overlaid plots' legends say what the table's columns say of
        // a run: failed, or not quasi-static.
        let mut labels = [row(Some(0.3)), row(Some(0.3)), row(Some(0.3))];
        labels[1].quasi_static_passed = false;
        labels[2].error = Some("stopped".into());
        let labels = labels.map(|r| r.curve_label("seed 1"));
        assert_eq!(
            labels,
            ["seed 1", "seed 1 (not quasi-static)", "seed 1 (failed)"]
        );

        // The reported figures leave out the fits the summary warns about:
        // a Kawakita a outside (0, 1] or with 1/b <= 0 (both its figures),
        // a Heckel fit with R^2 < 0.9.
        let mut odd = row(Some(3.5));
        let mut negative = row(Some(0.45));
        negative.kawakita_inv_b_pa = Some(-2.0);
        odd.heckel_yield_pressure_pa = Some(1e4);
        odd.heckel_r_squared = Some(0.5);
        let mut good = row(Some(0.4));
        good.heckel_yield_pressure_pa = Some(3e4);
        good.heckel_r_squared = Some(0.99);
        let rows = [odd, negative, good].map(ComparisonRow::with_fit_flags);
        let figure = |name: &str| {
            let (n, f) = SPREAD_FIGURES.iter().find(|(n, _)| *n == name).unwrap();
            spread(n, *f, &rows)
        };
        for name in [
            "kawakita_a",
            "kawakita_inv_b_pa",
            "heckel_yield_pressure_pa",
        ] {
            let s = figure(name);
            assert_eq!((s.runs, s.left_out), (1, 2), "{name}");
        }
        assert_eq!(figure("kawakita_a").mean, Some(0.4));
        assert_eq!(figure("heckel_yield_pressure_pa").mean, Some(3e4));
        assert_eq!(figure("final_relative_density").runs, 3);
    }
}
