//! `report.html` of `granbed-cli granule`: one page per run — its warnings
//! (the run's notes, a failed certificate, the kernel's error), the key
//! results with units, the force–displacement and energy plots inline, the
//! section pictures, `summary.json`'s fields with their meanings and a
//! glossary of `force_displacement.csv` — and, for `--types`, one page in
//! the series directory comparing the types, each row linked to its run's
//! page. Built from [`crate::html`]'s pieces, as `bed`'s report is.

use core::fmt::Write as _;
use std::path::Path;

use granbed_kernel::Real;
use granbed_kernel::scene::platens::PlatenSample;

use super::outputs::{FORCE_CSV, FORCE_SVG, SUMMARY_JSON, TYPES_CSV, TYPES_SVG};
use super::section::{DENSITY_SVG, SECTION_SVG};
use super::summary::Summary;
use crate::html::{
    figure, fit_cell, glossary, html_escape, key_table, kpa, num, page_head, picture, summary_rows,
    summary_table, warnings_section,
};
use crate::output::write_text;
use granbed_kernel::scene::platens::SAMPLE_COLUMNS;

/// File name of a report page (a run's, and a `--types` series').
pub const REPORT_FILE: &str = "report.html";

/// File name of the energy plot beside the force plot.
pub const ENERGY_SVG: &str = "energy_strain.svg";

/// The fields of `summary.json` shown first, with their meaning (any other
/// follows without one; a test checks that none does).
const FIELDS: [(&str, &str); 56] = [
    (
        "sigma_est_pa",
        "granule yield stress estimate σ_est = 4/(π d) dF/dx, Pa",
    ),
    (
        "sigma_est_strain_range",
        "the strains x/d the σ_est fit covered",
    ),
    ("fit_r_squared", "R² of the line F(x) fitted for σ_est"),
    ("fit_points", "samples in the σ_est fit"),
    ("slope_n_per_m", "its slope dF/dx, N/m"),
    ("intercept_n", "its intercept, N"),
    (
        "sigma_eff0_pa",
        "initial effective yield stress σ_y,eff0 = √a2(η0) σ_y, Pa",
    ),
    ("max_force_n", "largest mean platen force, N"),
    ("final_strain", "strain x/d reached"),
    (
        "quasi_static.passed",
        "quasi-static certificate passed (every figure below its limit)",
    ),
    (
        "quasi_static.max_kinetic_to_internal",
        "largest kinetic energy / internal work over the second half (limit 0.01)",
    ),
    (
        "quasi_static.force_imbalance_rel",
        "mean |upper − lower platen force| / upper force over the loaded samples of the second half (full symmetry only; limit 0.05)",
    ),
    (
        "quasi_static.rate_change_rel",
        "change of the force curve at half the platen speed (--rate-check; limit 0.05)",
    ),
    (
        "quasi_static.max_relative_kinetic_to_internal",
        "the kinetic ratio without the imposed motion (not judged)",
    ),
    ("granule_type", "granule type of the material preset"),
    ("youngs_modulus_pa", "Young's modulus E, Pa"),
    ("poisson_ratio", "Poisson's ratio ν"),
    ("yield_stress_pa", "yield stress σ_y, Pa"),
    ("eta0", "initial relative density η0"),
    ("cp", "yield-surface constant c_p"),
    ("eta_c", "critical relative density η_c"),
    ("true_density_kg_m3", "true (solid) density, kg/m³"),
    ("friction", "friction coefficient μ of the platen contact"),
    ("diameter_m", "granule diameter d, m"),
    ("mesh", "mesh level NxM of the full sphere"),
    ("symmetry", "octant (one eighth, mirrored) or full"),
    ("mesh_nodes", "nodes simulated"),
    ("mesh_hexes", "hexes simulated"),
    ("element", "element formulation"),
    ("hourglass_kappa", "hourglass coefficient κ"),
    ("target_strain", "requested final strain x/d"),
    ("approach_speed_m_s", "platen approach speed, m/s"),
    ("damping_ratio", "damping ratio ξ"),
    ("literal_return", "return map without the volume-drift fix"),
    (
        "yield_tolerance",
        "relative yield tolerance of the constitutive update",
    ),
    ("time_step_safety", "safety factor of the time step"),
    ("time_step_interval", "steps between time-step estimates"),
    ("time_step_method", "time-step estimate (global or element)"),
    ("output_strain_interval", "strain between samples"),
    ("gravity_m_s2", "gravity, m/s² (in −z)"),
    ("mass_scaling", "uniform mass scaling F (masses × F)"),
    (
        "energy_residual_rel",
        "energy-balance residual / contact work (round-off)",
    ),
    (
        "return_map_gap_rel",
        "internal work − (Ψ + plastic + hourglass) / contact work",
    ),
    ("hourglass_energy_rel", "hourglass energy / internal work"),
    ("damping_rel", "damping dissipation / contact work"),
    ("min_jacobian", "smallest element volume ratio J"),
    ("samples", "rows of force_displacement.csv"),
    ("steps", "time steps"),
    ("dt_s", "first time step, s"),
    ("final_dt_s", "time step at the last sample, s"),
    ("element_steps", "element evaluations"),
    ("wall_time_s", "wall time of the run, s"),
    (
        "ns_per_element_step",
        "wall time per element evaluation, ns",
    ),
    ("granbed_version", "granbed version"),
    ("error", "the kernel error that stopped the run"),
    // Shown above the table.
    ("notes", ""),
];

/// Fields of the file format, not of the run: left out of the table.
fn skipped(key: &str) -> bool {
    key == "format" || key == "format_version"
}

/// The ratio σ_est/σ_y,eff0 of a summary, if σ_est was fitted.
fn ratio(s: &Summary) -> Option<Real> {
    s.sigma_est_pa.map(|sigma| sigma / s.sigma_eff0_pa)
}

/// The run's warnings: why σ_est is missing or narrower (`notes`), a
/// failed certificate.
fn warnings(s: &Summary) -> Vec<String> {
    let mut w = s.notes.clone();
    if s.error.is_none() && !s.quasi_static.passed {
        w.push(s.not_quasi_static());
    }
    w
}

/// The key results of a run, with units.
fn key_results(s: &Summary) -> String {
    let range = s.sigma_est_strain_range.map_or_else(
        || "no fit".to_owned(),
        |[a, b]| format!("x/d from {} to {}", num(Some(a)), num(Some(b))),
    );
    let rows = [
        (
            "σ_est = 4/(π d) dF/dx, kPa (the granule's apparent yield stress)".to_owned(),
            kpa(s.sigma_est_pa),
        ),
        (
            "σ_est fit: strains, samples, R²".to_owned(),
            format!(
                "{range}, {} samples, {}",
                s.fit_points,
                num(s.fit_r_squared)
            ),
        ),
        (
            "σ_y,eff0 = √a2(η0) σ_y, kPa (the material's initial yield stress)".to_owned(),
            kpa(Some(s.sigma_eff0_pa)),
        ),
        ("σ_est / σ_y,eff0".to_owned(), num(ratio(s))),
        (
            "largest platen force, mN".to_owned(),
            num(Some(s.max_force_n * 1e3)),
        ),
        ("strain x/d reached".to_owned(), num(Some(s.final_strain))),
        (
            "quasi-static certificate".to_owned(),
            if s.quasi_static.passed {
                "passed"
            } else {
                "NOT passed"
            }
            .to_owned(),
        ),
    ];
    key_table("Key results", &rows)
}

/// The energy plot of `samples`: the platens' work and where it went,
/// against x/d.
pub fn energy_svg(title: &str, samples: &[PlatenSample]) -> anyhow::Result<String> {
    type Term = fn(&PlatenSample) -> Real;
    let terms: [(&str, Term); 7] = [
        ("platen work", |s| s.energy.platen_work),
        ("elastic Ψ", |s| s.energy.elastic),
        ("plastic dissipation", |s| s.energy.plastic),
        ("contact losses (friction, constraints)", |s| {
            s.energy.platen_work - s.energy.contact_work
        }),
        ("damping", |s| s.energy.damping),
        ("hourglass", |s| s.energy.hourglass),
        ("kinetic", |s| s.energy.kinetic),
    ];
    let terms: Vec<(&str, Vec<(f64, f64)>)> = terms
        .iter()
        .map(|&(label, e)| (label, samples.iter().map(|s| (s.strain, e(s))).collect()))
        .collect();
    crate::plot::energy_svg(title, "strain x/d (platen approach / diameter)", &terms)
}

/// What the plot `name` shows, for its caption.
fn plot_caption(name: &str) -> Option<&'static str> {
    Some(match name {
        FORCE_SVG => {
            "The mean platen force against the platens' approach x; dashed: the straight line \
             fitted over x/d from 0.1 to 0.4 (less when the run ended before 0.4), whose slope \
             gives σ_est = 4/(π d) dF/dx."
        }
        ENERGY_SVG => {
            "Where the platens' work went, totals so far against x/d: the elastic energy, the \
             plastic dissipation, the platen contacts' losses (friction and the kinematic \
             constraints: platen work − contact work), the damping, the hourglass energy (the \
             one-point element's spurious modes) and the kinetic energy (small when the run is \
             quasi-static). Gravity's work and the return map's energy gap are not drawn."
        }
        _ => return None,
    })
}

/// The report page of one run with `summary`, its plots `svgs` (file name
/// in the run's directory, SVG text) and the section pictures that exist
/// (`pictures`, file names).
pub fn report_html(
    summary: &Summary,
    svgs: &[(&str, &str)],
    pictures: &[&str],
) -> anyhow::Result<String> {
    let title = format!(
        "granbed granule: {}, mesh {} ({})",
        summary.granule_type, summary.mesh, summary.symmetry
    );
    let mut h = page_head(&title);
    h.push_str(&warnings_section(
        summary.error.as_deref(),
        &warnings(summary),
        "None: σ_est was fitted over the whole window and the run passed the quasi-static \
         certificate.",
    ));
    h.push_str(&key_results(summary));
    writeln!(
        h,
        "<p>Files: <a href=\"{FORCE_CSV}\">{FORCE_CSV}</a>, \
         <a href=\"{SUMMARY_JSON}\">{SUMMARY_JSON}</a>.</p>\n<h2>Plots</h2>"
    )?;
    for (name, svg) in svgs {
        h.push_str(&figure(name, svg));
        if let Some(caption) = plot_caption(name) {
            writeln!(h, "<p class=\"caption\">{}</p>", html_escape(caption))?;
        }
    }
    if !pictures.is_empty() {
        writeln!(
            h,
            "<h2>Sections through the centre</h2>\n<p>The granule at the end, cut by the plane \
             y = 0 between the platens: each cut hex coloured by its axial stress −σ<sub>zz</sub>, \
             and by its relative density η0/J.</p>"
        )?;
        for path in pictures {
            h.push_str(&picture(path, "section of the granule", &[]));
        }
    }
    h.push_str(&summary_table(&summary_rows(summary, &FIELDS, skipped)?));
    h.push_str("<h2>Columns of the table</h2>\n");
    h.push_str(&glossary(
        FORCE_CSV,
        "One row per sample: the unloaded state, then every output_strain_interval of \
         approach; energies are the totals so far. An octant run reports the whole granule's \
         forces and energies.",
        &SAMPLE_COLUMNS,
    ));
    h.push_str("</body>\n</html>\n");
    Ok(h)
}

/// Writes `report.html` of one run into `dir`, with its plots (file name,
/// SVG text) and the section pictures found there.
pub fn write_report(dir: &Path, summary: &Summary, svgs: &[(&str, &str)]) -> anyhow::Result<()> {
    let pictures: Vec<&str> = [SECTION_SVG, DENSITY_SVG]
        .into_iter()
        .filter(|f| dir.join(f).is_file())
        .collect();
    write_text(
        &dir.join(REPORT_FILE),
        &report_html(summary, svgs, &pictures)?,
    )
}

/// The page of a `--types` series: the overlaid force curves `overlay`
/// and one row per (directory name, summary), linked to its run's page.
pub fn types_report_html(overlay: &str, runs: &[(&str, &Summary)]) -> String {
    let mut h = page_head("granbed granule: types compared");
    let _ = writeln!(
        h,
        "<p>Each type compressed between the platens alone, on the same mesh and settings. \
         Values rounded to 4 digits; stresses in kPa; ✗ marks a σ_est whose run failed the \
         quasi-static certificate, ended before the fit's window closed or was stopped by the \
         kernel (R² on hover). \
         Files: <a href=\"{TYPES_CSV}\">{TYPES_CSV}</a>.</p>"
    );
    h.push_str(&figure(TYPES_SVG, overlay));
    h.push_str(
        "<h2>Types</h2>\n<table>\n<tr><th>type</th><th>σ_y, kPa</th><th>η0</th>\
         <th>σ_y,eff0, kPa</th><th>σ_est, kPa</th><th>σ_est / σ_y,eff0</th>\
         <th>strain reached</th><th>quasi-static</th><th>wall time, s</th></tr>\n",
    );
    for (dir, s) in runs {
        let ok = s.quasi_static.passed && s.notes.is_empty() && s.error.is_none();
        let link = html_escape(&format!("{dir}/{REPORT_FILE}"));
        let _ = writeln!(
            h,
            "<tr><td><a href=\"{link}\">{}</a></td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td></tr>",
            html_escape(&s.granule_type),
            kpa(Some(s.material.yield_stress_pa)),
            num(Some(s.material.eta0)),
            kpa(Some(s.sigma_eff0_pa)),
            fit_cell(s.sigma_est_pa.map(|x| kpa(Some(x))), s.fit_r_squared, ok),
            num(ratio(s)),
            num(Some(s.final_strain)),
            if s.error.is_some() {
                "failed"
            } else if s.quasi_static.passed {
                "passed"
            } else {
                "NOT passed"
            },
            num(Some(s.wall_time_s)),
        );
    }
    h.push_str("</table>\n</body>\n</html>\n");
    h
}
