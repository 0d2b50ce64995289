//! `report.html` of a series (`--types`, `--seeds`) in the series
//! directory: one page that puts the members side by side — the overlaid
//! plots, one table row per run (the figures of `comparison.csv` /
//! `seeds.csv`, rounded for reading, pressures in kPa, each run linked to
//! its own `report.html`), and for `--seeds` the spread of each figure.
//! A row whose figures are no material figures (a rejected fit, a failed
//! quasi-static certificate, an error) is marked, and the mark says why.

use core::fmt::Write as _;
use std::path::Path;

use super::compare::ComparisonRow;
use super::report::REPORT_FILE;
use super::seeds::Spread;
use crate::html::{TABLE_DIGITS, figure, fit_cell, html_escape, kpa, num, page_head};
use crate::output::write_text;

/// What a series' page shows.
pub struct SeriesReport<'a> {
    /// The page's title.
    pub title: String,
    /// One paragraph on what the series is (plain text).
    pub about: String,
    /// Per run, in the rows' order: its directory's name in the series
    /// directory (its report is `<name>/report.html`).
    pub member_dirs: Vec<String>,
    /// One row per run.
    pub rows: &'a [ComparisonRow],
    /// The spread of each figure over the runs (`--seeds`).
    pub spreads: Option<&'a [Spread]>,
    /// The series' tables, by file name, linked at the top.
    pub files: &'a [&'a str],
    /// The overlaid plots: file name in the series directory, SVG text.
    pub svgs: &'a [(&'a str, String)],
}

/// A plain number cell.
fn cell(text: &str) -> String {
    format!("<td class=\"num\">{}</td>", html_escape(text))
}

/// Why `row`'s figures are not all material figures, for its row's note;
/// empty if nothing is wrong.
fn doubts(row: &ComparisonRow) -> Vec<&'static str> {
    let mut out = Vec::new();
    // A failed run's certificate is not judged (as its summary does).
    if row.error.is_some() {
        out.push("the run failed (see its report)");
    } else if !row.quasi_static_passed {
        out.push("not quasi-static: inertia is in its pressures");
    }
    match (row.kawakita_a, row.kawakita_ok) {
        (None, _) => {
            out.push("no Kawakita fit (too few rows in its window, or no line through them)")
        }
        (Some(_), false) => out.push("Kawakita fit rejected"),
        (Some(_), true) => {}
    }
    match (row.heckel_yield_pressure_pa, row.heckel_ok) {
        (None, _) => {
            out.push("no Heckel fit (too few rows in its window, or no line through them)")
        }
        (Some(_), false) => out.push("Heckel fit rejected"),
        (Some(_), true) => {}
    }
    out
}

/// The names of the spread's figures on the page, with units; pressures
/// (`*_pa`) are shown in kPa.
fn spread_name(figure: &str) -> &'static str {
    match figure {
        "kawakita_a" => "Kawakita a",
        "kawakita_inv_b_pa" => "Kawakita 1/b, kPa",
        "heckel_yield_pressure_pa" => "Heckel P_y, kPa",
        "initial_solid_fraction" => "poured solid fraction D0",
        "max_pressure_pa" => "largest pressure, kPa",
        "final_pressure_pa" => "final pressure, kPa",
        "final_relative_density" => "final granule relative density",
        "final_coordination" => "final coordination number Z",
        "elastic_recovery" => "in-die elastic recovery",
        "plasticity_factor" => "plasticity factor",
        _ => "",
    }
}

/// The page of `report`.
pub fn series_report_html(report: &SeriesReport<'_>) -> anyhow::Result<String> {
    let mut h = page_head(&report.title);
    writeln!(h, "<p>{}</p>", html_escape(&report.about))?;
    let files: Vec<String> = report
        .files
        .iter()
        .chain(report.svgs.iter().map(|(name, _)| name))
        .map(|f| format!("<a href=\"{0}\">{0}</a>", html_escape(f)))
        .collect();
    writeln!(
        h,
        "<p>Files: {}; each run's own outputs and report in its directory.</p>",
        files.join(", ")
    )?;
    let doubtful: Vec<(usize, Vec<&str>)> = report
        .rows
        .iter()
        .map(doubts)
        .enumerate()
        .filter(|(_, d)| !d.is_empty())
        .collect();
    if !doubtful.is_empty() {
        writeln!(
            h,
            "<h2>Warnings</h2>\n<p>Figures that are no material figures (each run's report and \
             summary.json say why in full):</p>\n<ul>"
        )?;
        for (i, d) in &doubtful {
            writeln!(
                h,
                "<li><a href=\"{}/{REPORT_FILE}\">{}</a>: {}</li>",
                html_escape(&report.member_dirs[*i]),
                html_escape(&report.member_dirs[*i]),
                html_escape(&d.join("; "))
            )?;
        }
        writeln!(h, "</ul>")?;
    }
    writeln!(h, "<h2>Plots</h2>")?;
    for (name, svg) in report.svgs {
        h.push_str(&figure(name, svg));
    }
    writeln!(
        h,
        "<h2>Runs</h2>\n<p>Values rounded to {TABLE_DIGITS} digits (the CSV and JSON files keep \
         them all); pressures in kPa; ✗ marks a fit the run's summary rejects (its R² on hover).</p>\n\
         <table>\n<tr><th>run</th><th>yield stress, kPa</th><th>η0</th><th>D0</th>\
         <th>Kawakita a</th><th>Kawakita 1/b, kPa</th><th>Heckel P_y, kPa</th>\
         <th>largest P, kPa</th><th>C reached</th><th>final η</th><th>final Z</th>\
         <th>elastic recovery</th><th>plasticity factor</th>\
         <th>quasi-static</th><th>wall time, s</th></tr>"
    )?;
    for (row, dir) in report.rows.iter().zip(&report.member_dirs) {
        let class = if doubts(row).is_empty() {
            ""
        } else {
            " class=\"doubt\""
        };
        let certificate = if row.error.is_some() {
            "failed"
        } else if row.quasi_static_passed {
            "passed"
        } else {
            "NOT passed"
        };
        writeln!(
            h,
            "<tr{class}><td><a href=\"{0}/{REPORT_FILE}\">{0}</a></td>{1}{2}{3}{4}{5}{6}{7}{8}{9}{10}\
             {11}{12}<td>{certificate}</td>{13}</tr>",
            html_escape(dir),
            cell(&kpa(Some(row.yield_stress_pa))),
            cell(&num(Some(row.eta0))),
            cell(&num(Some(row.initial_solid_fraction))),
            fit_cell(
                row.kawakita_a.map(|a| num(Some(a))),
                row.kawakita_r_squared,
                row.kawakita_ok
            ),
            fit_cell(
                row.kawakita_inv_b_pa.map(|b| kpa(Some(b))),
                row.kawakita_r_squared,
                row.kawakita_ok
            ),
            fit_cell(
                row.heckel_yield_pressure_pa.map(|p| kpa(Some(p))),
                row.heckel_r_squared,
                row.heckel_ok
            ),
            cell(&kpa(Some(row.max_pressure_pa))),
            cell(&num(Some(row.final_strain))),
            cell(&num(Some(row.final_relative_density))),
            cell(&num(Some(row.final_coordination))),
            cell(&num(row.elastic_recovery)),
            cell(&num(row.plasticity_factor)),
            cell(&format!("{:.1}", row.wall_time_s)),
        )?;
    }
    writeln!(h, "</table>")?;
    if let Some(spreads) = report.spreads {
        writeln!(
            h,
            "<h2>Spread over the runs</h2>\n<p>The run-to-run spread of each figure: a change of \
             setting that moves a figure by less than this cannot be told from the pour's \
             chance. A fit a run's summary rejects is left out.</p>\n<table>\n<tr><th>figure</th>\
             <th>runs</th><th>left out</th><th>mean</th><th>std</th><th>min</th><th>max</th>\
             <th>max − min</th></tr>"
        )?;
        for s in spreads {
            let scale = if s.figure.ends_with("_pa") { 1e-3 } else { 1.0 };
            let v = |x: Option<f64>| cell(&num(x.map(|x| x * scale)));
            writeln!(
                h,
                "<tr><td title=\"{}\">{}</td>{}{}{}{}{}{}{}</tr>",
                html_escape(s.figure),
                html_escape(spread_name(s.figure)),
                cell(&s.runs.to_string()),
                cell(&s.left_out.to_string()),
                v(s.mean),
                v(s.std),
                v(s.min),
                v(s.max),
                v(s.spread),
            )?;
        }
        writeln!(h, "</table>")?;
    }
    writeln!(h, "</body>\n</html>")?;
    Ok(h)
}

/// Writes [`REPORT_FILE`] of `report` into the series directory `dir`.
pub fn write_series_report(dir: &Path, report: &SeriesReport<'_>) -> anyhow::Result<()> {
    write_text(&dir.join(REPORT_FILE), &series_report_html(report)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bed::seeds::{SPREAD_FIGURES, spread};

    fn row(seed: u64, kawakita_a: f64, passed: bool) -> ComparisonRow {
        ComparisonRow {
            granule_type: "B2",
            seed,
            yield_stress_pa: 30e3,
            eta0: 0.8,
            kawakita_a: Some(kawakita_a),
            kawakita_inv_b_pa: Some(123_456.7),
            kawakita_r_squared: Some(0.991_23),
            kawakita_points: 20,
            kawakita_ok: false,
            heckel_yield_pressure_pa: Some(2.5e6),
            heckel_r_squared: Some(0.95),
            heckel_ok: false,
            initial_solid_fraction: 0.543_21,
            max_pressure_pa: 1.5e6,
            final_strain: 0.300_001_9,
            final_pressure_pa: 1.5e6,
            final_relative_density: 0.912_345,
            final_coordination: 6.789,
            elastic_recovery: Some(0.0567),
            plasticity_factor: Some(0.9),
            quasi_static_passed: passed,
            wall_time_s: 12.345,
            error: None,
        }
        .with_fit_flags()
    }

    /// Every run is a row linked to its own report, rounded, pressures in
    /// kPa; a rejected fit and a failed certificate are marked and listed,
    /// a sound run is not; the spread is a table of its own.
    #[test]
    fn a_row_per_run_with_its_doubts_marked() {
        let mut failed = row(3, 0.5, false);
        failed.error = Some("step 9: element 2 inverted".into());
        failed.kawakita_a = None;
        failed.kawakita_inv_b_pa = None;
        let failed = failed.with_fit_flags();
        let rows = [row(1, 0.41, true), row(2, 1.7, false), failed];
        assert!(rows[0].kawakita_ok && !rows[1].kawakita_ok, "{rows:?}");
        let spreads: Vec<Spread> = SPREAD_FIGURES
            .iter()
            .map(|&(name, f)| spread(name, f, &rows))
            .collect();
        let svgs = [("a.svg", "<svg>A</svg>".to_owned())];
        let report = SeriesReport {
            title: "series <B2>".into(),
            about: "two seeds".into(),
            member_dirs: vec!["seed_1".into(), "seed_2".into(), "seed_3".into()],
            rows: &rows,
            spreads: Some(&spreads),
            files: &["seeds.csv"],
            svgs: &svgs,
        };
        let html = series_report_html(&report).unwrap();
        assert!(html.contains("<title>series &lt;B2&gt;</title>"));
        assert!(html.contains("<svg>A</svg>") && html.contains("href=\"seeds.csv\""));
        for dir in ["seed_1", "seed_2"] {
            assert!(html.contains(&format!("<a href=\"{dir}/report.html\">{dir}</a></td>")));
        }
        // Rounded, in kPa: 1/b = 123 456.7 Pa, P_y = 2.5 MPa, P_max 1.5 MPa.
        for text in ["123.5", "2500", "1500", "0.5432", "0.3000", "6.789", "12.3"] {
            assert!(html.contains(&format!(">{text}<")), "no cell {text}");
        }
        assert!(html.contains(">0.4100</td>"), "seed 1's a is not marked");
        assert!(html.contains(">1.700 ✗</td>"), "seed 2's a is not marked");
        assert!(html.contains("title=\"R² = 0.9912\""));
        assert_eq!(html.matches("<tr class=\"doubt\">").count(), 2);
        // A failed run is not also called not quasi-static, and a fit its
        // run never reached is no rejected fit: n/a without a mark.
        assert!(html.contains(
            "seed_3</a>: the run failed (see its report); no Kawakita fit (too few rows in its \
             window, or no line through them)</li>"
        ));
        assert!(html.contains(&format!("title=\"{}\">n/a</td>", crate::html::NO_FIT)));
        assert!(!html.contains("n/a ✗"));
        assert!(html.contains(
            "seed_2</a>: not quasi-static: inertia is in its pressures; Kawakita fit rejected</li>"
        ));
        assert!(!html.contains("seed_1</a>: "), "a sound run is listed");
        // The spread leaves seed 2's rejected a and seed 3's missing one
        // out: one run, mean 0.41.
        assert!(html.contains(
            "<td title=\"kawakita_a\">Kawakita a</td><td class=\"num\">1</td>\
             <td class=\"num\">2</td><td class=\"num\">0.4100</td>"
        ));
        assert!(
            SPREAD_FIGURES
                .iter()
                .all(|(f, _)| !spread_name(f).is_empty()),
            "a spread figure without its name on the page"
        );
    }
}
