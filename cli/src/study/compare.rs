//! `granbed-cli study compare A B`: how far one finished bed run lies from
//! another — the work-precision study's measures ([`curve_error`] of the
//! upper-punch pressure against strain, the relative errors of
//! Kawakita's a and 1/b) and what B cost against A (steps, wall time,
//! pair searches), read from the two runs' `compression.csv` and
//! `summary.json`. For checking that a change of the numerics keeps the
//! answer of a run that already exists, without running it again.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, bail};
use clap::Args;
use granbed_kernel::Real;
use serde_json::Value;

use super::work_precision::{curve_error, relative_error};
use crate::output::Streams;

/// Options of `granbed-cli study compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The reference run's output directory (of `granbed-cli bed`).
    #[arg(value_name = "REFERENCE")]
    pub reference: PathBuf,

    /// The run compared with it.
    #[arg(value_name = "RUN")]
    pub run: PathBuf,

    /// Strain window of the curve error, `FROM,TO` (0 ≤ FROM < TO < 1).
    #[arg(long, value_name = "FROM,TO", default_value = "0.02,0.3", value_parser = parse_window)]
    pub window: [Real; 2],
}

/// One run as the comparison reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// (strain, upper-punch pressure in Pa), in file order.
    pub curve: Vec<(Real, Real)>,
    /// The summary's fields, by name (`null` where it has none).
    summary: serde_json::Map<String, Value>,
}

impl RunRecord {
    /// Reads `dir/compression.csv` and `dir/summary.json`.
    pub fn read(dir: &Path) -> anyhow::Result<Self> {
        let csv_path = dir.join("compression.csv");
        let text = std::fs::read_to_string(&csv_path)
            .with_context(|| format!("reading {}", csv_path.display()))?;
        let curve = pressure_curve(&text).with_context(|| format!("in {}", csv_path.display()))?;
        let json_path = dir.join("summary.json");
        let json = std::fs::read_to_string(&json_path)
            .with_context(|| format!("reading {}", json_path.display()))?;
        let Value::Object(summary) = serde_json::from_str(&json)
            .with_context(|| format!("parsing {}", json_path.display()))?
        else {
            bail!("{}: not a JSON object", json_path.display());
        };
        // What every `granbed-cli bed` summary has; a directory without it
        // is not a bed run, and would compare as NaN.
        for key in ["steps", "wall_time_s"] {
            if !summary
                .get(key)
                .and_then(Value::as_f64)
                .is_some_and(|x| x >= 0.0)
            {
                bail!(
                    "{} is not the summary of a `granbed-cli bed` run: no number `{key}` >= 0",
                    json_path.display()
                );
            }
        }
        if curve.len() < 2 {
            bail!(
                "{} has {} rows: not the profile of a `granbed-cli bed` run",
                csv_path.display(),
                curve.len()
            );
        }
        Ok(Self { curve, summary })
    }

    /// The summary's number `key` (None if absent or null).
    pub fn number(&self, key: &str) -> Option<Real> {
        self.summary.get(key).and_then(Value::as_f64)
    }
}

/// The (strain, upper_pressure_pa) columns of a `compression.csv` text:
/// the averaged pressures at their rows' end strains, not at the
/// intervals' mean strains (`mean_strain`), so that the compared window
/// reaches the final strain. Two runs with the same output interval are
/// paired alike.
fn pressure_curve(text: &str) -> anyhow::Result<Vec<(Real, Real)>> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().context("empty file")?.split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .with_context(|| format!("no column '{name}'"))
    };
    let (c, p) = (column("strain")?, column("upper_pressure_pa")?);
    lines
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(i, l)| {
            let cells: Vec<&str> = l.split(',').collect();
            let cell = |k: usize| -> anyhow::Result<Real> {
                cells
                    .get(k)
                    .and_then(|s| s.parse().ok())
                    .with_context(|| format!("row {}: column {} is not a number", i + 2, k + 1))
            };
            Ok((cell(c)?, cell(p)?))
        })
        .collect()
}

/// Parses `FROM,TO` with 0 ≤ FROM < TO < 1.
fn parse_window(s: &str) -> Result<[Real; 2], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [from, to] = parts[..] else {
        return Err(format!("--window must be FROM,TO (got '{s}')"));
    };
    let num = |t: &str| {
        t.trim()
            .parse::<Real>()
            .map_err(|_| format!("--window: '{t}' is not a number"))
    };
    let (from, to) = (num(from)?, num(to)?);
    if !(0.0 <= from && from < to && to < 1.0) {
        return Err(format!(
            "--window must have 0 <= FROM < TO < 1 (got {from},{to})"
        ));
    }
    Ok([from, to])
}

/// What [`compare`] measures (NaN where a figure is missing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Relative L2 distance of the run's P(C) from the reference's.
    pub curve: Real,
    /// Relative error of Kawakita's a.
    pub kawakita_a: Real,
    /// Relative error of Kawakita's 1/b.
    pub kawakita_inv_b: Real,
    /// Steps of the run over the reference's.
    pub steps: Real,
    /// Compression wall time of the run over the reference's.
    pub wall_time: Real,
    /// Pair searches per step of the run over the reference's (a resumed
    /// run's summary counts its last segment only).
    pub pair_searches: Real,
}

/// Compares `run` with `reference` over the strain `window`.
pub fn compare(reference: &RunRecord, run: &RunRecord, window: [Real; 2]) -> Comparison {
    let rel = |key: &str| relative_error(run.number(key), reference.number(key));
    let ratio = |key: &str| match (run.number(key), reference.number(key)) {
        (Some(x), Some(r)) if r != 0.0 => x / r,
        _ => Real::NAN,
    };
    Comparison {
        curve: curve_error(&run.curve, &reference.curve, window).unwrap_or(Real::NAN),
        kawakita_a: rel("kawakita_a"),
        kawakita_inv_b: rel("kawakita_inv_b_pa"),
        steps: ratio("steps"),
        wall_time: ratio("wall_time_s"),
        pair_searches: ratio("pair_searches_per_step"),
    }
}

impl CompareArgs {
    /// Reads both runs and prints the comparison on stdout.
    pub fn run(&self, streams: &mut Streams<'_>) -> anyhow::Result<()> {
        let reference = RunRecord::read(&self.reference)?;
        let run = RunRecord::read(&self.run)?;
        let c = compare(&reference, &run, self.window);
        let [from, to] = self.window;
        let out = &mut streams.stdout;
        if c.curve.is_nan() {
            writeln!(
                out,
                "P(C) relative L2, C = {from}..{to}: NaN (a run does not cover the window)"
            )?;
        } else {
            writeln!(out, "P(C) relative L2, C = {from}..{to}: {:.4}", c.curve)?;
        }
        writeln!(out, "Kawakita a, relative error: {:.4}", c.kawakita_a)?;
        writeln!(out, "Kawakita 1/b, relative error: {:.4}", c.kawakita_inv_b)?;
        writeln!(out, "steps, run / reference: {:.4}", c.steps)?;
        writeln!(out, "wall time, run / reference: {:.4}", c.wall_time)?;
        writeln!(
            out,
            "pair searches per step, run / reference: {:.4}",
            c.pair_searches
        )?;
        if let Some(note) = interval_note(&reference, &run) {
            writeln!(streams.stderr, "note: {note}")?;
        }
        Ok(())
    }
}

/// What to say when the two runs' output intervals differ: the curves
/// pair each interval-averaged pressure with the row's end strain, which
/// then lies half an interval further on in one run than in the other,
/// and the curve distance includes that offset.
fn interval_note(reference: &RunRecord, run: &RunRecord) -> Option<String> {
    let interval = |r: &RunRecord| {
        r.summary
            .get("scene")
            .and_then(|s| s.get("output_strain_interval"))
            .and_then(Value::as_f64)
    };
    let (a, b) = (interval(reference)?, interval(run)?);
    (a != b).then(|| {
        format!(
            "the runs' output intervals differ ({a} and {b}): each pressure, an average over its \
             interval, is read at the interval's end, so the curves are offset by {} in strain, \
             which the P(C) distance includes",
            0.5 * (a - b).abs()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(curve: Vec<(Real, Real)>, summary: Value) -> RunRecord {
        let Value::Object(summary) = summary else {
            unreachable!()
        };
        RunRecord { curve, summary }
    }

    #[test]
    fn the_pressure_columns_are_found_by_name() {
        let text = "time_s,upper_pressure_pa,strain\n0,0,0\n1,5.5,0.1\n";
        assert_eq!(pressure_curve(text).unwrap(), vec![(0.0, 0.0), (0.1, 5.5)]);
        assert!(pressure_curve("time_s,strain\n0,0\n").is_err());
        let bad = pressure_curve("strain,upper_pressure_pa\n0,x\n").unwrap_err();
        assert!(format!("{bad:#}").contains("row 2"), "{bad:#}");
    }

    #[test]
    fn a_run_scaled_by_a_tenth_is_ten_percent_away() {
        let curve: Vec<(Real, Real)> = (0..=40).map(|i| (0.01 * i as Real, i as Real)).collect();
        let scaled: Vec<_> = curve.iter().map(|&(c, p)| (c, 1.1 * p)).collect();
        let reference = record(
            curve,
            serde_json::json!({"steps": 100, "kawakita_a": 0.5, "kawakita_inv_b_pa": null}),
        );
        let run = record(
            scaled,
            serde_json::json!({"steps": 150, "kawakita_a": 0.4, "kawakita_inv_b_pa": 2.0}),
        );
        let c = compare(&reference, &run, [0.02, 0.3]);
        assert!((c.curve - 0.1).abs() < 1e-12, "{}", c.curve);
        assert!((c.kawakita_a - 0.2).abs() < 1e-12);
        assert!(c.kawakita_inv_b.is_nan());
        assert_eq!(c.steps, 1.5);
        assert!(c.wall_time.is_nan());
        assert!(compare(&run, &run, [0.02, 0.3]).curve == 0.0);
    }

    #[test]
    fn the_window_must_be_ordered_inside_zero_to_one() {
        assert_eq!(parse_window("0.02,0.3").unwrap(), [0.02, 0.3]);
        for bad in ["0.3,0.02", "0.1", "a,0.2", "0.1,1.0", "-0.1,0.2"] {
            let e = parse_window(bad).unwrap_err();
            assert!(e.contains("--window"), "{bad}: {e}");
        }
    }

    /// Runs of one output interval compare without a note; runs of two
    /// get one, with the curves' offset, half the difference.
    #[test]
    fn different_output_intervals_are_noted() {
        let of = |interval: f64| {
            record(
                vec![(0.0, 0.0), (interval, 1.0)],
                serde_json::json!({"scene": {"output_strain_interval": interval}}),
            )
        };
        assert_eq!(interval_note(&of(0.005), &of(0.005)), None);
        let note = interval_note(&of(0.005), &of(0.01)).unwrap();
        assert!(
            note.contains("0.005 and 0.01") && note.contains("offset by 0.0025"),
            "{note}"
        );
        // A summary without the field (not a bed scene's): nothing to say.
        let bare = record(vec![(0.0, 0.0)], serde_json::json!({}));
        assert_eq!(interval_note(&bare, &of(0.01)), None);
    }
}
